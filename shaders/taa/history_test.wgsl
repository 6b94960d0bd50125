// The test of a moving pixel's history shared by TAA and the upscaler (taa/upscale.wgsl): does
// the surface the pixel shows now appear at one of its history's bilinear taps in the previous
// depth buffer (eq. (11) of Mara et al., as the denoisers' temporal stages test theirs)?

var prev_depth: texture_depth_2d;

// Whether one of p's four neighbours lies off its surface (no surface, or a linear depth more
// than 10% away): p is on a silhouette.
fn on_silhouette(p: vec2i, z: f32) -> bool {
    for (var k = 0; k < 4; k++) {
        let d = depth_at(p + select(vec2i(2 * (k & 1) - 1, 0), vec2i(0, 2 * (k & 1) - 1), k >= 2));
        if d < 0.0 || abs(d - z) > 0.1 * z {
            return true;
        }
    }
    return false;
}

// The bilinear read of the history at `prev` for the pixel p; no weight where the pixel moved
// and none of the taps showed its surface, unless it lies on a silhouette. A pixel that did not
// move on screen reads its own texel untested (what an object uncovers as it moves off a still
// background is left to the clamp). On a moving silhouette the jittered sample of one frame
// often hits the other surface than last frame's texels did, and the edge's history is the
// blend TAA exists to keep, so every tap is read there (docs/decisions.md: "Uncovered
// surfaces").
fn history_taps(p: vec2i, prev: vec2f, still: bool) -> BilinearTaps {
    var b = bilinear_taps(prev);
    if still || !has_surface(p) {
        return b;
    }
    let x = position_at(p);
    let expected = previous_surface(textureLoad(gb_object, p, 0).xy, x);
    let s = surface_frame(p, x);
    // Depth alone (the previous normals would be a 17th sampled texture where the vertices
    // move, over WebGPU's default limit of 16 per stage).
    var shown = false;
    for (var k = 0; k < 4; k++) {
        let d = previous_plane_distance(prev_depth, bilinear_tap(b, k), expected, s);
        shown = shown || (b.w[k] > 0.0 && d >= 0.0 && d <= frame.d1_px);
    }
    if !shown && !on_silhouette(p, linear_depth(x)) {
        b.w = vec4f(0.0);
    }
    return b;
}
