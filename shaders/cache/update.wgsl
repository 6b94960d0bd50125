// The radiance cache's per-frame update and lookup (engine/src/passes/cache.rs), with the
// trace's scene program:
// - `gather`, one thread per pixel: for a pixel the last frame did not see, its prior (its
//   cell's mean as the previous frames left it, so the pixel's own sample is not in it, where
//   the cell's centroid is in sight) for the denoisers' temporal stages; then the pixel's own
//   matte sample added to its cell (where the pixel was traced this frame).
// - `secondary`, one thread per update_tile x update_tile tile: from one pixel's surface, a
//   cosine-sampled ray to the surface it sees, and there one estimate of the matte light that
//   surface would have as a primary hit (the trace's area-light sample and matte path), added
//   to that surface's cell. This fills cells of surfaces the camera does not see (behind a
//   pillar, around a corner) before a move uncovers them.
// `seen_last_frame` (realtime/seen.wgsl) decides which pixels the last frame did not see.

var gb_ids: texture_2d<u32>;
var tr_matte: texture_2d<f32>;
// rgb: the cell's mean; a: the frames' worth of samples it stands for (0: no cell).
var out_prior: texture_storage_2d<rgba16float, write>;
// The prior's mean squared luminance (0: no prior).
var out_prior_m2: texture_storage_2d<r32float, write>;
// The pixel's cell slot (CACHE_NONE: none; where the pixel was traced this frame, the slot its
// sample went to), for the tests.
var out_cell: texture_storage_2d<r32uint, write>;

// A primary or secondary surface the cache takes samples of: one with a matte lobe, seen from
// its front (or double-sided), not glass.
struct CacheSurface {
    ok: bool,
    s: Surface,
}

fn cache_surface(hit: Hit, rd: vec3f) -> CacheSurface {
    let s = surface_at(hit, rd);
    let m = material(s.material);
    var ok = s.front || (m.flags & MAT_DOUBLE_SIDED) != 0u;
    if ok {
        let ms = material_at(m, s.tc);
        let bsdf = with_glass(material_bsdf(m, ms), m, ms, s.front);
        ok = max3(bsdf.albedo) > 0.0 && bsdf.transmission <= 0.0;
    }
    return CacheSurface(ok, s);
}

fn cell_of(s: Surface) -> CellKey {
    return cell_key(s.p, s.ns, frame.cam_pos.xyz, pixel_spread());
}

@compute @workgroup_size(8, 8)
fn gather(@builtin(global_invocation_id) gid: vec3u) {
    let px = gid.xy;
    if px.x >= frame.size.x || px.y >= frame.size.y {
        return;
    }
    let ids = textureLoad(gb_ids, px, 0).xy;
    var prior = vec4f(0.0);
    var m2 = 0.0;
    var slot = CACHE_NONE;
    if ids.y != NO_HIT {
        let ray = primary_ray(px, 0u);
        let cs = cache_surface(raster_hit(ray.ro, ray.rd, ids), ray.rd);
        if cs.ok {
            let key = cell_of(cs.s);
            slot = cache_find(key);
            if slot != CACHE_NONE && !seen_last_frame(cs.s.p) && centroid_in_sight(key, slot, cs.s) {
                let c = cache_cells[slot];
                prior = vec4f(c.rgb, min(c.a, cache.prior_frames));
                m2 = cache_centroids[slot].w;
            }
            if traced_this_frame(px) {
                var rng = rng_init(px.y * frame.size.x + px.x, frame.index, params.seed ^ 0x63616368u);
                let u = vec3f(rand(&rng), rand(&rng), rand(&rng));
                slot = cache_claim(key);
                cache_add(slot, key, cs.s.p, textureLoad(tr_matte, px, 0).rgb, u);
            }
        }
    }
    let finite = is_finite3(prior.rgb) && is_finite3(vec3f(m2));
    textureStore(out_prior, px, select(vec4f(0.0), prior, finite));
    textureStore(out_prior_m2, px, vec4f(select(0.0, m2, finite), 0.0, 0.0, 0.0));
    textureStore(out_cell, px, vec4u(slot, 0u, 0u, 0u));
}

// One estimate of the matte light at surface s seen along rd, as realtime/trace.wgsl's `shade`
// computes it at a primary hit: an area-light sample and a cosine-sampled path, each weighed by
// the power heuristic against the other.
fn matte_light_at(s: Surface, rd: vec3f, cone_width: f32, rng: ptr<function, u32>) -> vec3f {
    let eps = params.cam_pos.w;
    let basis = onb(s.ns);
    let origin = offset_ray(s.p, s.ng, eps);
    var matte = vec3f(0.0);
    if !depth_ok(2) || dot(-rd, s.ns) <= 0.0 {
        return matte;
    }
    let groups = area_groups();
    let nee_select = 1.0 / f32(max(groups, 1u));
    if groups > 0u {
        let ls = sample_area_light(s.p, s.ng, rng);
        let wi = to_local(basis, ls.wi);
        if max3(ls.li) > 0.0 && wi.z > 0.0 && dot(ls.wi, s.ng) > 0.0 {
            let leg = shadow_leg(origin, s.p, ls.wi, ls.dist, eps);
            if traverse(origin, leg.dir, leg.tmax, true).tri == NO_HIT {
                matte += ls.li * (wi.z * INV_PI) * power_heuristic(ls.pdf, wi.z * INV_PI);
            }
        }
    }
    return matte + matte_path(basis, s.p, origin, s.ng, cone_width, nee_select, rand2(rng), rng);
}

@compute @workgroup_size(8, 8)
fn secondary(@builtin(global_invocation_id) gid: vec3u) {
    let tile = max(cache.update_tile, 1u);
    let h = pcg_hash((gid.x * 0x8da6b343u) ^ (gid.y * 0xd8163841u) ^ (frame.index * 0x9e3779b9u));
    let px = gid.xy * tile + vec2u(h % tile, (h / tile) % tile);
    if cache.update_tile == 0u || px.x >= frame.size.x || px.y >= frame.size.y {
        return;
    }
    let ids = textureLoad(gb_ids, px, 0).xy;
    if ids.y == NO_HIT {
        return;
    }
    let ray = primary_ray(px, 0u);
    let hit0 = raster_hit(ray.ro, ray.rd, ids);
    let s0 = surface_at(hit0, ray.rd);
    var rng = rng_init(px.y * frame.size.x + px.x, frame.index, params.seed ^ 0x73656364u);
    let wi = onb(s0.ns) * cosine_hemisphere(rand2(&rng));
    if dot(wi, s0.ng) <= 0.0 {
        return;
    }
    let rd = normalize(wi);
    let hit = traverse(offset_ray(s0.p, s0.ng, params.cam_pos.w), rd, INF, false);
    if hit.tri == NO_HIT {
        return;
    }
    let cs = cache_surface(hit, rd);
    if !cs.ok {
        return;
    }
    let width = pixel_spread() * (hit0.t + hit.t);
    let matte = matte_light_at(cs.s, rd, width, &rng);
    let u = vec3f(rand(&rng), rand(&rng), rand(&rng));
    let key = cell_of(cs.s);
    cache_add(cache_claim(key), key, cs.s.p, matte, u);
}
