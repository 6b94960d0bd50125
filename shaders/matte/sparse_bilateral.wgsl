// The sparse cross-bilateral filter of stages (4) and (7): `dn.taps` taps in a disk, weighted by
// plane distance and normals. Reads `filter_in`, the caller's input.
fn sparse_bilateral(p: vec2i, radius: f32) -> vec3f {
    let c = textureLoad(filter_in, p, 0).rgb;
    if radius < 0.5 || !has_surface(p) {
        return c;
    }
    let xc = position_at(p);
    let nc = oct_decode(textureLoad(gb_normal, p, 0).xy);
    let fc = footprint(xc);
    var sum = c;
    var wsum = 1.0;
    for (var i = 0u; i < dn.taps; i++) {
        let q = p + vec2i(round(spiral_tap(i, dn.taps, radius, p)));
        if !in_bounds(q) || !has_surface(q) {
            continue;
        }
        let w = bilateral_weight(xc, nc, fc, position_at(q), oct_decode(textureLoad(gb_normal, q, 0).xy));
        sum += textureLoad(filter_in, q, 0).rgb * w;
        wsum += w;
    }
    return sum / wsum;
}
