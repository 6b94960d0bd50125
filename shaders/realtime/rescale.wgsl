// Histories carried across a change of the frame's size (engine/src/passes/rescale.rs). A texel
// of the new size reads the old texture where the same view ray fell: the same texture
// coordinate, so the previous camera's projection still finds the last frame's pixels in it. A
// float history is read bilinearly from those of its four old texels that lie on the surface of
// the nearest one (their last-frame depths within 2%: a silhouette does not mix foreground and
// background into one history); an integer texel (flags, ids, counters) is the nearest one's.

// The last frame's depth at the old size (reversed Z: 0 is the sky); a 1x1 texel where the
// frame kept none, and then every tap counts.
var old_depth: texture_depth_2d;

struct RescaleTaps {
    texel: array<vec2i, 4>,
    w: vec4f,
    nearest: vec2i,
}

// Relative depth difference above which an old tap is another surface than the nearest one.
const RESCALE_DEPTH_TOLERANCE: f32 = 0.02;

fn rescale_taps(p: vec2i, old_size: vec2u, new_size: vec2u) -> RescaleTaps {
    // The new texel's centre in the old texture's pixel coordinates (centres at +0.5).
    let at = (vec2f(p) + 0.5) * vec2f(old_size) / vec2f(new_size);
    let b = bilinear_taps(at);
    let hi = vec2i(old_size) - 1;
    var t: RescaleTaps;
    for (var k = 0; k < 4; k++) {
        t.texel[k] = clamp(bilinear_tap(b, k), vec2i(0), hi);
    }
    t.w = b.w;
    t.nearest = clamp(vec2i(floor(at)), vec2i(0), hi);
    if all(textureDimensions(old_depth) == old_size) {
        let ref_depth = textureLoad(old_depth, t.nearest, 0);
        for (var i = 0; i < 4; i++) {
            let d = textureLoad(old_depth, t.texel[i], 0);
            if abs(d - ref_depth) > RESCALE_DEPTH_TOLERANCE * max(d, ref_depth) {
                t.w[i] = 0.0;
            }
        }
    }
    // The nearest texel is one of the four with the largest bilinear weight (at least 1/4), and
    // always passes, so the sum is positive.
    t.w /= max(t.w.x + t.w.y + t.w.z + t.w.w, 1e-6);
    return t;
}
