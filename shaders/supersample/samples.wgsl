// The extra samples of supersampling (common.wgsl): per pixel, the guide's features (the raster's
// hit, re-derived as trace.wgsl does) and frame.samples - 1 samples at uniformly random positions
// in the pixel, each a traced primary ray shaded as the guide is (trace.wgsl: shade), on random
// sequences of their own.

@compute @workgroup_size(8, 8)
fn samples(@builtin(global_invocation_id) gid: vec3u) {
    let px = gid.xy;
    if px.x >= frame.size.x || px.y >= frame.size.y {
        return;
    }
    let pixel = px.y * frame.size.x + px.x;
    let ro = frame.cam_pos.xyz;
    let ids = textureLoad(gb_ids, px, 0).xy;
    var guide = vec4u(bitcast<u32>(-1.0), 0u, NO_GUIDE, 0u);
    if ids.y != NO_HIT {
        let rd = camera_ray(px);
        let hit = raster_hit(ro, rd, ids);
        let s = surface_at(hit, rd);
        guide = vec4u(bitcast<u32>(view_depth(rd, hit.t)), pack2x16snorm(oct_encode(s.ns)), s.material, 0u);
    }
    ss_guides[pixel] = guide;
    let extra = extra_samples();
    for (var j = 0u; j < extra; j++) {
        var rng = rng_init(pixel, frame.index, params.seed ^ ((j + 1u) * 0x9e3779b9u));
        let pos = rand2(&rng);
        let rd = camera_ray_at(vec2f(px) + pos);
        let hit = traverse(ro, rd, INF, false);
        var r: SampleRecord;
        r.pos = pack2x16unorm(pos);
        r.guide = NO_GUIDE;
        if hit.tri == NO_HIT {
            r.matte = pack_light(vec3f(0.0));
            r.glossy = pack_light(vec3f(0.0));
            r.direct = pack_light(env_radiance(rd));
            r.depth = -1.0;
            r.normal = 0u;
            r.material = NO_GUIDE;
        } else {
            let sh = shade(rd, hit, frame.paths, px, params.seed ^ 0x73747261u ^ ((j + 1u) * 0x85ebca6bu), &rng);
            r.matte = pack_light(sh.matte);
            r.glossy = pack_light(sh.glossy);
            r.direct = pack_light(sh.direct);
            r.depth = view_depth(rd, hit.t);
            r.normal = pack2x16snorm(oct_encode(sh.n));
            r.material = surface_at(hit, rd).material;
        }
        ss_samples[pixel * extra + j] = r;
    }
}
