// The sparse cross-bilateral filter of stages (4) and (7): `dn.taps` taps in a disk, weighted by
// plane distance and normals, and with edge_k > 0 also by luminance (stage 7's edge-stop, see
// matte/bilateral.wgsl). Reads `filter_in`, the caller's input, and for the edge-stop
// `reason_in`, the history length.

// Standard deviation of the n-frame mean at p: the raw input's spread over 16 taps on p's
// surface within 3 pixels, over sqrt(n).
fn history_noise(p: vec2i, xc: vec3f, nc: vec3f, fc: f32) -> f32 {
    let own = moments_add(Moments(vec4f(0.0), vec4f(0.0), 0.0), half_safe(matte_input(p)));
    let m = surface_moments(own, p, xc, nc, fc, 16u, 3.0);
    let m1 = m.m1.w / m.count;
    let n = max(f32(textureLoad(reason_in, p, 0).x >> 8u), 1.0);
    return sqrt(max(m.m2.w / m.count - m1 * m1, 0.0) / n);
}

fn sparse_bilateral(p: vec2i, radius: f32, edge_k: f32) -> vec3f {
    let c = textureLoad(filter_in, p, 0).rgb;
    if radius < 0.5 || !has_surface(p) {
        return c;
    }
    let xc = position_at(p);
    let nc = oct_decode(textureLoad(gb_normal, p, 0).xy);
    let fc = footprint(xc);
    var sigma_l = 0.0;
    if edge_k > 0.0 {
        sigma_l = edge_k * history_noise(p, xc, nc, fc) + 1e-6;
    }
    let lc = luminance(c);
    var sum = c;
    var wsum = 1.0;
    for (var i = 0u; i < dn.taps; i++) {
        let q = p + vec2i(round(spiral_tap(i, dn.taps, radius, p)));
        if !in_bounds(q) || !has_surface(q) {
            continue;
        }
        let t = textureLoad(filter_in, q, 0).rgb;
        var w = bilateral_weight(xc, nc, fc, position_at(q), oct_decode(textureLoad(gb_normal, q, 0).xy));
        if sigma_l > 0.0 {
            w *= exp(-abs(luminance(t) - lc) / sigma_l);
        }
        sum += t * w;
        wsum += w;
    }
    return sum / wsum;
}
