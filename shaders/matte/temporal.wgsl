// Stage (3), matte temporal: reverse-reproject the history with the motion vectors (through
// `reproject`, which tolerates the raster's jitter at silhouettes), weigh it by
// the confidence of eq. (11), c = h smoothstep(d1, d0, |X_expected - X_actual|) (so c falls to 0
// as the distance grows past d1; the paper writes the arguments in the other order), clamp it to
// the current 3x3 neighbourhood and blend h c of it in. Output rgb = the blend, a = c.
//
// One addition to the paper: the history carries its length n (frames since it was reset, in
// its alpha), and the new sample's weight is max(1 - c, 1 / (n + 1)). A fresh history then
// averages its first frames equally instead of keeping 0.98^k of its first, noisy sample (after
// 60 frames that sample would still weigh 30%); once n passes 1 / (1 - h) it is the paper's
// exponential blend. In a still view at full confidence the weight falls on as 1 / n (to
// 1 / still_frames): the history is then a true mean and converges to the reference. The
// reason texture carries n above its 8 flag bits. A history resampled
// between texels (the surface moved on screen) is a little blurred each time, and counts as at
// most resampled_history_frames, so that motion's blur fades within a few frames of a stop; so
// does every history on the frame after a change of size (realtime/rescale.wgsl).

var prev_depth: texture_depth_2d;
var history: texture_2d<f32>;
var prev_normal: texture_2d<f32>;
var out_temporal: texture_storage_2d<rgba32float, write>;
var out_reason: texture_storage_2d<r32uint, write>;
// c alone for stage (5)'s minimum, 1 off the surface (which needs no filling): its horizontal
// pass then reads 4 bytes a tap where it read this output's 16 and the G-buffer's ids.
var out_confidence: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let current = half_safe(matte_input(p));
    if !has_surface(p) || !stage_on(STAGE_TEMPORAL) {
        textureStore(out_temporal, p, vec4f(current, 0.0));
        textureStore(out_reason, p, vec4u(select(0u, REASON_DISOCCLUDED, has_surface(p)) | (1u << 8u), 0u, 0u, 0u));
        textureStore(out_confidence, p, vec4f(select(1.0, 0.0, has_surface(p)), 0.0, 0.0, 0.0));
        return;
    }
    // Where this surface was: through the motion vector, and by its own (object) motion.
    let x = position_at(p);
    let ids = textureLoad(gb_object, p, 0);
    let expected = previous_surface(ids.xy, x);
    let s = surface_frame(p, x);
    let prev = vec2f(p) + 0.5 + textureLoad(gb_motion, p, 0).xy;
    var reason = 0u;
    var c = 0.0;
    var r = Reprojection(vec2i(floor(prev)), true, -1.0);
    // A long still-view history tests normals too (MatteSettings::still_normal_degrees).
    var min_cos = mp.reprojection_min_cos;
    if frame.history_valid != 0u {
        let own = clamp(vec2i(floor(prev)), vec2i(0), vec2i(frame.size) - 1);
        if frame.static_view != 0u && mp.edge_stop_full_frames > 0.0 && textureLoad(history, own, 0).a > mp.edge_stop_full_frames {
            min_cos = max(min_cos, mp.still_normal_min_cos);
        }
        r = reproject(prev_depth, prev_normal, prev, expected, s, min_cos);
    }
    if r.distance < 0.0 {
        reason = REASON_DISOCCLUDED;
    } else {
        c = confidence(mp.hysteresis, r.distance);
        if c < 0.5 * mp.hysteresis {
            reason = REASON_LOW_CONFIDENCE;
        }
    }
    var result = current;
    var n = 1.0;
    if c > 0.0 {
        let texel = textureLoad(history, r.texel, 0);
        let still = frame.static_view != 0u && mp.still_frames > 0.0 && c >= mp.hysteresis;
        n = next_length(texel.a, still);
        var hist = half_safe(texel.rgb);
        if r.bilinear {
            let b = bilinear_taps(prev);
            let w = passing_weights(b, surface_taps(prev_depth, prev_normal, b, expected, s, min_cos));
            hist = half_safe(load_taps(history, b, w).rgb);
            n = resampled_length(n, prev, mp.resampled_history_frames);
        } else {
            reason |= REASON_NEIGHBOUR;
        }
        n = rescaled_length(n - 1.0) + 1.0;
        var clamped = hist;
        if mp.clamp_sigma > 0.0 {
            // The current neighbourhood's mean and standard deviation: the paper's 3x3, plus 24
            // sparse taps on the same surface within 4 pixels. At one sample per pixel an indirectly
            // lit region is mostly zeros with rare bright samples; nine samples are then often all
            // zero (sigma = 0), and clamping to them would erase a correct history every frame (the
            // living room's interior came out 3x too dark). 33 samples rarely miss every bright one.
            var m = Moments(vec4f(0.0), vec4f(0.0), 0.0);
            for (var dy = -1; dy <= 1; dy++) {
                for (var dx = -1; dx <= 1; dx++) {
                    m = moments_add(m, half_safe(matte_input(clamp(p + vec2i(dx, dy), vec2i(0), vec2i(frame.size) - 1))));
                }
            }
            m = surface_moments(m, p, x, s.n, s.footprint, 24u, 4.0);
            let m1 = m.m1.xyz / m.count;
            let sigma = sqrt(max(m.m2.xyz / m.count - m1 * m1, vec3f(0.0)));
            let lo = m1 - mp.clamp_sigma * sigma;
            let hi = m1 + mp.clamp_sigma * sigma;
            clamped = clamp(hist, lo, hi);
            if any(clamped != hist) {
                reason |= REASON_CLAMPED;
            }
        }
        result = mix(clamped, current, new_frame_weight(c, n, mp.still_frames, still));
    }
    // A history that restarts here (a surface a move uncovered) counts this frame's sample as
    // the paths the trace averaged into it (more where it saw the surface uncovered), and
    // starts from the radiance cache's prior where there is one (passes/cache.rs): its cell's
    // mean, weighed as the frames' worth of samples it holds, instead of this one sample.
    if c <= 0.0 && frame.history_valid != 0u {
        n = matte_paths(p);
        let prior = cache_prior_at(p);
        if prior.a > 0.0 {
            result = mix(prior.rgb, current, n / (n + prior.a));
            n += prior.a;
        }
    }
    textureStore(out_temporal, p, vec4f(half_safe(result), c));
    textureStore(out_confidence, p, vec4f(c, 0.0, 0.0, 0.0));
    textureStore(out_reason, p, vec4u(reason | (u32(n) << 8u), 0u, 0u, 0u));
}
