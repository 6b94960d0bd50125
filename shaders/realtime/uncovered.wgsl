// Paths the trace shoots at a pixel (engine/src/passes/trace.rs): frame.uncovered_paths where
// its surface was not on screen last frame (a move uncovered it), frame.paths elsewhere. The
// pixel's matte light carries the count in its alpha, and a temporal stage whose history
// restarts there counts the sample as that many frames (FrameSettings::uncovered_paths).

// The last frame's depth buffer, interpolated where p projects into it, holds p's depth within
// 2%. Reversed infinite Z is affine in screen space on a plane, so on a surface the last frame
// saw the bilinear depth is exact wherever its four texels show that plane; at a silhouette
// the four mix two surfaces and no point matches. This passes what seen_last_frame's 3x3 test
// (nearest texels only) fails on a grazing floor under TAA's jitter, whose depth changes by
// more than 2% from row to row.
fn seen_on_a_plane(p: vec3f) -> bool {
    let clip = frame.prev_view_proj * vec4f(p, 1.0);
    if clip.w <= 0.0 {
        return false;
    }
    // Texel t's depth is the surface at pixel position t + the last frame's jitter.
    let u = to_pixels(clip) - vec2f(frame.prev_jitter_x, frame.prev_jitter_y);
    let t = vec2i(floor(u));
    if any(t < vec2i(0)) || any(t + 1 >= vec2i(frame.size)) {
        return false;
    }
    let f = u - vec2f(t);
    let d00 = textureLoad(prev_depth, t, 0);
    let d10 = textureLoad(prev_depth, t + vec2i(1, 0), 0);
    let d01 = textureLoad(prev_depth, t + vec2i(0, 1), 0);
    let d11 = textureLoad(prev_depth, t + vec2i(1, 1), 0);
    if min(min(d00, d10), min(d01, d11)) <= 0.0 {
        return false;
    }
    let d = mix(mix(d00, d10, f.x), mix(d01, d11, f.x), f.y);
    let expected = clip.z / clip.w;
    return abs(d - expected) <= 0.02 * expected;
}

fn pixel_paths(p: vec3f) -> u32 {
    if frame.uncovered_paths > frame.paths && !seen_last_frame(p) && !seen_on_a_plane(p) {
        return frame.uncovered_paths;
    }
    return frame.paths;
}
