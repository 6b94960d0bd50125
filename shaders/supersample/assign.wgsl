// Voorhuis §5: each extra sample finds its most similar guide among the four pixel centres
// nearest to it (the 2x2 block around its position), by depth and normal: the relative depth
// difference plus one minus the normals' cosine, a sample of the environment only with a guide
// of the environment; ties go to the nearer centre. Beyond the paper, a guide of the sample's
// own material wins over any other: the resolve gives the sample its guide's composited
// radiance, and a ceiling sample given an emitter's (same plane, same normal) came out tens of
// times too bright along every light's edge. A sample with no similar guide keeps its pixel's.

fn guide_score(r: SampleRecord, x: vec2f, g: vec2i) -> f32 {
    if any(g < vec2i(0)) || any(g >= vec2i(frame.size)) {
        return INF;
    }
    let f = ss_guides[u32(g.y) * frame.size.x + u32(g.x)];
    let z = bitcast<f32>(f.x);
    let d = x - (vec2f(g) + 0.5);
    let near = 1e-3 * dot(d, d);
    if r.depth < 0.0 || z < 0.0 {
        return select(INF, near, r.depth < 0.0 && z < 0.0);
    }
    let n = dot(oct_decode(unpack2x16snorm(r.normal)), oct_decode(unpack2x16snorm(f.y)));
    let other = select(0.0, 1e3, r.material != f.z);
    return abs(r.depth - z) / max(r.depth, 1e-6) + (1.0 - n) + near + other;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let px = gid.xy;
    if px.x >= frame.size.x || px.y >= frame.size.y {
        return;
    }
    let pixel = px.y * frame.size.x + px.x;
    let extra = extra_samples();
    for (var j = 0u; j < extra; j++) {
        let i = pixel * extra + j;
        let r = ss_samples[i];
        let x = vec2f(px) + unpack2x16unorm(r.pos);
        let base = vec2i(floor(x - 0.5));
        var best = pixel;
        var best_score = INF;
        for (var c = 0; c < 4; c++) {
            let g = base + vec2i(c & 1, c >> 1u);
            let s = guide_score(r, x, g);
            if s < best_score {
                best_score = s;
                best = u32(g.y) * frame.size.x + u32(g.x);
            }
        }
        ss_samples[i].guide = best;
    }
}
