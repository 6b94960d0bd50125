// Dundr §4.2 and §5: accumulation with r = max(a, 1 / age), where age counts the samples this
// surface accumulated; a pixel not traced this frame keeps its light, age and moments as they
// were (reprojected; in a still view its own where none reprojects; the sky's from the nearest
// texel that showed the sky), and a pixel with neither a sample nor a history is missing (age 0).
// The matte signal's pass also writes the features (linear depth and its gradient).
// Outputs: integrated (rgb), moments (m1, m2, age, frames): frames counts the frames since the
// pixel's history last restarted, traced or not (TAA compares it with its own history's length
// before it follows this light: taa/matte_moments.wgsl).

var prev_depth: texture_depth_2d;
var prev_normal: texture_2d<f32>;
var history: texture_2d<f32>;
var moments: texture_2d<f32>;
var out_integrated: texture_storage_2d<rgba32float, write>;
var out_moments: texture_storage_2d<rgba32float, write>;

// The texel of p's 3x3 that showed the sky last frame with light in its history, p's own
// first, then the edge neighbours before the corners; (-1, -1) where none did.
fn sky_texel(p: vec2i) -> vec2i {
    let order = array<vec2i, 9>(vec2i(0, 0), vec2i(1, 0), vec2i(-1, 0), vec2i(0, 1), vec2i(0, -1), vec2i(1, 1), vec2i(-1, 1), vec2i(1, -1), vec2i(-1, -1));
    for (var k = 0; k < 9; k++) {
        let q = p + order[k];
        if in_bounds(q) && textureLoad(prev_object, q, 0).y == NO_SURFACE && textureLoad(moments, q, 0).z >= 1.0 {
            return q;
        }
    }
    return vec2i(-1);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let sampled = traced_this_frame(vec2u(p));
    let current = half_safe(signal_input(p));
    var hist = vec3f(0.0);
    var mom = vec4f(0.0);
    var found = false;
    if pp.temporal != 0u && frame.history_valid != 0u {
        if has_surface(p) {
            let x = position_at(p);
            let prev = vec2f(p) + 0.5 + textureLoad(gb_motion, p, 0).xy;
            let expected = previous_surface(textureLoad(gb_object, p, 0).xy, x);
            let r = reproject(prev_depth, prev_normal, prev, expected, surface_frame(p, x), pp.normal_min_cos);
            if r.distance >= 0.0 && r.distance <= frame.d1_px && same_object(p, r.texel) {
                hist = half_safe(textureLoad(history, r.texel, 0).rgb);
                mom = textureLoad(moments, r.texel, 0);
                found = mom.z >= 1.0;
            }
        } else {
            // The sky stays where it was on screen. Where this texel showed a surface last
            // frame (a silhouette under the jitter) the nearest texel that showed the sky
            // holds the same light to within a pixel's change of direction.
            let q = sky_texel(p);
            if q.x >= 0 {
                hist = half_safe(textureLoad(history, q, 0).rgb);
                mom = textureLoad(moments, q, 0);
                found = mom.z >= 1.0;
            }
        }
        // In a still view a pixel keeps its own history where the reprojection found none: on
        // a depth edge the jittered sample lands on either surface, and no previous texel of
        // the 3x3 may pass for the one it hit this frame. Dropped, the history's samples would
        // be lost, and an untraced pixel missing until its next sample.
        if !found && frame.static_view != 0u && has_surface(p) {
            let own = textureLoad(moments, p, 0);
            if own.z >= 1.0 {
                hist = half_safe(textureLoad(history, p, 0).rgb);
                mom = own;
                found = true;
            }
        }
        // After a change of size the history was resampled (realtime/rescale.wgsl).
        mom.z = rescaled_length(mom.z);
        mom.w = rescaled_length(mom.w);
    }
    // 2^24: counts stay whole numbers in f32.
    let frames = select(1.0, min(mom.w + 1.0, 16777216.0), found);
    var light = hist;
    if sampled {
        let l = luma(current);
        // 2^24: sample counts stay whole numbers in f32.
        let age = select(1.0, min(mom.z + 1.0, 16777216.0), found);
        var a = pp.alpha;
        if frame.static_view != 0u && pp.still_samples > 0.0 {
            a = min(a, 1.0 / pp.still_samples);
        }
        let r = max(a, 1.0 / age);
        light = select(current, mix(hist, current, r), found);
        let m = select(vec2f(l, l * l), mix(mom.xy, vec2f(l, l * l), r), found);
        mom = vec4f(m, age, frames);
    } else if found {
        mom.w = frames;
    } else {
        mom = vec4f(0.0);
    }
    textureStore(out_integrated, p, vec4f(half_safe(light), 1.0));
    textureStore(out_moments, p, select(vec4f(0.0), mom, all(abs(mom) < vec4f(3.0e38))));
}
