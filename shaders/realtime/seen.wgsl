// Whether the last frame saw a surface point: the test of what a move uncovered that the
// radiance cache's gather (cache/update.wgsl) and the trace's uncovered paths
// (realtime/uncovered.wgsl) share, and that `hush-cli quality` scores uncovered pixels by.

var prev_depth: texture_depth_2d;

// The last frame saw p: its depth buffer holds p's depth (within 2%) at one of the 3x3 texels
// where p projects into it (both frames' depths were drawn with a sub-pixel jitter, which on a
// grazing floor moves a texel's depth by more than 2%). Reversed infinite Z: depth = near / view
// depth = clip z / clip w.
fn seen_last_frame(p: vec3f) -> bool {
    let clip = frame.prev_view_proj * vec4f(p, 1.0);
    if clip.w <= 0.0 {
        return false;
    }
    let t = vec2i(floor(to_pixels(clip)));
    if any(t < vec2i(0)) || any(t >= vec2i(frame.size)) {
        return false;
    }
    let expected = clip.z / clip.w;
    for (var k = 0; k < 9; k++) {
        let q = clamp(t + vec2i(k % 3 - 1, k / 3 - 1), vec2i(0), vec2i(frame.size) - 1);
        if abs(textureLoad(prev_depth, q, 0) - expected) <= 0.02 * expected {
            return true;
        }
    }
    return false;
}
