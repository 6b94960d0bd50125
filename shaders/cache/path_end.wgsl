// Paths that end in the radiance cache (engine/src/passes/cache.rs; SHaRC's main use): at a
// vertex where common/path.wgsl allows it (from the matte path's first on,
// realtime/area_light.wgsl), the rest of the path is the light the vertex's cell holds, where
// the cell has gathered `path_end_samples` samples, its mean is known to within
// `path_end_error` and its centroid is in sight of the vertex (the leak test of the pixels'
// prior). The cells' light is that of every bounce: the matte light of the pixels and
// secondary samples fills them, and those end their own paths in the cache, so the bounces add
// up over frames. Hence only where the path length is unlimited (max_depth < 0): under a limit
// the cells would carry light from past it (a white room lit from its ceiling, 64x48, frames
// 8-31: +9% over paths that stop at 6 segments; tests/radiance_cache.rs).

// The ray from surface s0 to cell k's centroid (slot s), each end lifted off the surface along
// its normal by a quarter cell, so that neither grazes the surface they share (a floor) nor cuts
// a curved one's chord (tmax 0: the two are too close to need one).
fn centroid_ray(k: CellKey, slot: u32, s0: Surface) -> ShadowRay {
    let lift = s0.ns * (0.25 * k.size);
    let a = s0.p + lift;
    let b = (vec3f(k.corner) + cache_centroids[slot].xyz) * k.size + lift;
    let d = b - a;
    let len = length(d);
    if len <= 1e-6 * k.size {
        return ShadowRay(a, vec3f(0.0, 0.0, 1.0), 0.0, vec3f(0.0));
    }
    return ShadowRay(a, d / len, len, vec3f(0.0));
}

// Cell k's centroid (slot s) is in sight of surface s0.
fn centroid_in_sight(k: CellKey, slot: u32, s0: Surface) -> bool {
    let r = centroid_ray(k, slot, s0);
    return r.tmax <= 0.0 || traverse(r.o, r.d, r.tmax, true).tri == NO_HIT;
}

// Whether cell c's mean is known to within `path_end_error` (relative standard error): its
// samples' variance, from their mean squared luminance m2, over their count. A firefly among a
// cell's first samples raises its mean for every path that ends there, a blob the denoisers
// cannot average away since it is the same in every frame; it raises m2 more, so the cell waits.
fn known_well(c: vec4f, m2: f32) -> bool {
    let l = luminance(c.rgb);
    let spread = max(m2 - l * l, 0.0);
    let e = cache.path_end_error;
    return spread <= e * e * l * l * c.a;
}

// Where a path may end: the light of the rest of the path but the punctual lights', and the
// ray that must be clear for it to count.
struct PathEnd {
    ok: bool,
    light: vec3f,
    sight: ShadowRay,
}

// Where the path may end at surface s (towards wo, local to its shading frame; may_end: the
// path allows it at this vertex; reach: the length of the segment that arrived here): the light
// leaving it from the cache, and the ray to its cell's centroid that must be clear. None where
// the path must go on: a delta or transmitting lobe, a glossy lobe that outweighs the matte one
// (the cell's light is a cosine-weighted mean, a sharp lobe would reflect its blocks), a segment
// no longer than the cell's diagonal, no cell, too few samples, or a mean not yet known well.
//
// The segment test is SHaRC's (its samples query a voxel only past sqrt(3) voxel edges): a short
// segment reaches into a corner, under a step or a table, where the light changes within a
// cell, and the cell's mean carries the open surface's light in there; a long one sees the cell
// from afar, where its blur is smaller than the bounce's own.
fn path_end(s: Surface, b: Bsdf, wo: vec3f, may_end: bool, reach: f32) -> PathEnd {
    var end = PathEnd(false, vec3f(0.0), ShadowRay(s.p, wo, 0.0, vec3f(0.0)));
    if !may_end || params.max_depth >= 0 || cache.path_end_samples <= 0.0 || b.delta || b.transmission > 0.0 {
        return end;
    }
    let f = fresnel(b, wo.z);
    let matte = matte_weight(b, wo.z);
    if max3(matte) <= max3(f) {
        return end;
    }
    let key = cell_key(s.p, s.ns, frame.cam_pos.xyz, pixel_spread());
    if !(reach > 1.7320508 * key.size) {
        return end;
    }
    let slot = cache_find(key);
    if slot == CACHE_NONE {
        return end;
    }
    let c = cache_cells[slot];
    if !(c.a >= cache.path_end_samples) || !is_finite3(c.rgb) || !known_well(c, cache_centroids[slot].w) {
        return end;
    }
    // The cell's matte light is the incoming light of the area lights, the environment and the
    // bounces, cos / pi weighted (eq. (9) without the material): the matte lobe reflects it by
    // its weight, and the glossy lobe, in light that varies little across it, by about F.
    end.ok = true;
    end.light = c.rgb * (matte + f);
    end.sight = centroid_ray(key, slot, s);
    return end;
}

// A path vertex's light (common/path.wgsl's `vertex_light`): where the path may end here
// (may_end: from the matte path's first vertex on; reach: the length of the segment that
// arrived) and `path_end` allows it, the cell's light
// plus the punctual lights', which the cells do not hold (the trace keeps them in `direct`),
// where the sight ray to the cell's centroid is clear; otherwise next_event's light sample.
// All of these rays go through one call of traverse: the GPU's compiler inlines each call, and
// lanes of a group at different calls take turns (H200, living room, 1280x720, unlimited
// length: trace 21.8 ms with path ends, 20.6 without; docs/decisions.md).
fn vertex_light(s: Surface, b: Bsdf, wo: vec3f, basis: mat3x3f, origin: vec3f, beta: vec3f, may_end: bool, reach: f32, rng: ptr<function, u32>) -> VertexLight {
    let end = path_end(s, b, wo, may_end, reach);
    var ending = end.ok;
    var light_sample = light_groups() > 0u && (max3(b.albedo) > 0.0 || !b.delta);
    // The next of the end's rays: 0 the sight ray, k > 0 punctual light k - 1.
    var k = 0u;
    var light = select(vec3f(0.0), end.light, ending);
    loop {
        var r: ShadowRay;
        let sight = ending && k == 0u;
        if ending {
            if k > params.num_lights {
                break;
            }
            if sight {
                r = end.sight;
            } else {
                r = punctual_ray(k - 1u, s, b, wo, basis, origin);
            }
            k++;
        } else if light_sample {
            light_sample = false;
            r = light_sample_ray(s, b, wo, basis, origin, rng);
        } else {
            break;
        }
        if !sight && max3(r.light) <= 0.0 {
            continue;
        }
        if r.tmax > 0.0 && traverse(r.o, r.d, r.tmax, true).tri != NO_HIT {
            if sight {
                // A hidden centroid: the cell may hold light from behind a wall; the path goes on.
                ending = false;
                light = vec3f(0.0);
            }
        } else {
            light += r.light;
        }
    }
    return VertexLight(beta * light, ending);
}
