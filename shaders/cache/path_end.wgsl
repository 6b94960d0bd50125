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

// The light leaving surface s towards wo (local to `basis`) from the cache and the punctual
// lights (a: 1), or nothing (a: 0) where the path must go on: a delta or transmitting lobe, a
// glossy lobe that outweighs the matte one (the cell's light is a cosine-weighted mean, a
// sharp lobe would reflect its blocks), no cell, too few samples, or a cell behind a wall.
fn path_end(s: Surface, b: Bsdf, wo: vec3f, basis: mat3x3f, origin: vec3f) -> vec4f {
    if params.max_depth >= 0 || cache.path_end_samples <= 0.0 || b.delta || b.transmission > 0.0 {
        return vec4f(0.0);
    }
    let f = fresnel(b, wo.z);
    let matte = matte_weight(b, wo.z);
    if max3(matte) <= max3(f) {
        return vec4f(0.0);
    }
    let key = cell_key(s.p, s.ns, frame.cam_pos.xyz, pixel_spread());
    let slot = cache_find(key);
    if slot == CACHE_NONE {
        return vec4f(0.0);
    }
    let c = cache_cells[slot];
    if !(c.a >= cache.path_end_samples) || !is_finite3(c.rgb) || !known_well(c, cache_centroids[slot].w) {
        return vec4f(0.0);
    }
    // The cell's matte light is the incoming light of the area lights, the environment and the
    // bounces, cos / pi weighted (eq. (9) without the material): the matte lobe reflects it by
    // its weight, and the glossy lobe, in light that varies little across it, by about F.
    var l = c.rgb * (matte + f);
    // Ray 0 tests the centroid's sight (centroid_in_sight); the others are the punctual lights'
    // shadow rays (punctual_light), which are not in the cells (the trace keeps them in
    // `direct`). One call of traverse for all: the GPU's compiler inlines each call, and the
    // path's loop already holds two; with these as two more calls the living room's real-time
    // trace took 2.8x as long on an H200 (640x360, 16.7 against 5.9 ms), with one more 1.15x.
    for (var i = 0u; i <= params.num_lights; i++) {
        var r: ShadowRay;
        if i == 0u {
            r = centroid_ray(key, slot, s);
        } else {
            r = punctual_ray(i - 1u, s, b, wo, basis, origin);
            if max3(r.light) <= 0.0 {
                continue;
            }
        }
        let blocked = r.tmax > 0.0 && traverse(r.o, r.d, r.tmax, true).tri != NO_HIT;
        if !blocked {
            l += r.light;
        } else if i == 0u {
            return vec4f(0.0);
        }
    }
    return vec4f(l, 1.0);
}
