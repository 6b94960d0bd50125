// Stage (8), glossy temporal (Mara et al. §3.4; Voorhuis §4.2.3): reproject the glossy history
// with the reflection motion vectors of glossy/motion.wgsl, weigh it by a confidence, clip it to
// the pre-blurred current neighbourhood and blend as the matte temporal does (history length n
// in alpha; new sample weight max(1 - c, 1 / n), in a still view 1 / n: matte/common.wgsl's
// new_frame_weight).
//
// Confidence c, by how the pixel was reprojected:
// - surface motion vectors (rough surfaces, --reflection-mv primary, or a static view): eq. (11)
//   on the primary surface, as the matte temporal, and the previous texel's normal within
//   gp.reprojection_min_cos of this one's. The jitter puts a crease's two faces, or a ledge
//   thinner than a pixel and what lies behind it, under one pixel in turn; eq. (11) passes
//   both (they are within a footprint), but they reflect different things under different
//   F(w_s), and the chain filters light divided by F, so their mix is biased, not just noisy;
// - reflection motion vectors on a mirror: eq. (11) on the reflected hit (exact for mirrors),
//   in pixel footprints at the reflected hit (reflected_footprint: curved mirrors minify);
// - reflection motion vectors on a glossy surface: with glossy.hit_test (and traced
//   representative rays), eq. (11) on the reflected hit as for mirrors, in reaches grown by the
//   lobe's spread (glossy/reproject.wgsl: hit_reach), since its samples scatter and a tighter
//   test would reject good history; without, h wherever the previous pixel had a glossy
//   surface, as Voorhuis, who drops the consistency test there and lets the neighbourhood clip
//   remove ghosts.
// Output: history (rgb, n) and info (c, clip amount, n, 0).

var prev_depth: texture_depth_2d;
var history: texture_2d<f32>;
var prev_normal: texture_2d<f32>;
var neighbourhood: texture_2d<f32>;
var dst: texture_storage_2d<rgba32float, write>;
var motion: texture_2d<f32>;
var out_info: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let current = glossy_input(p);
    if !has_surface(p) || !gstage_on(GSTAGE_TEMPORAL) {
        textureStore(dst, p, vec4f(current, 1.0));
        textureStore(out_info, p, vec4f(0.0, 0.0, 1.0, 0.0));
        return;
    }
    let x = position_at(p);
    let roughness = roughness_at(p);
    // In a static view the reflection stood still too (glossy/motion.wgsl): the surface test
    // is then exact for every lobe, mirrors included, and does not depend on the reflected hits,
    // which differ between frames with the jitter and the sampled ray.
    let reflected = roughness < gp.roughness_threshold && gp.mode != MV_PRIMARY && gp.static_view == 0u;
    let prev = vec2f(p) + 0.5 + textureLoad(motion, p, 0).xy;
    // The lobe whose reflected hit is tested (HIT_NONE: none is).
    let lobe_class = tested_class(roughness, gstage_on(GSTAGE_HIT_TEST));
    var r = Reprojection(vec2i(floor(prev)), true, -1.0);
    var c = 0.0;
    // What the texel was tested with, for the bilinear taps: the surface's expected point and
    // frame, or the reflected hit and its reach.
    var expected = x;
    var s = SurfaceFrame(vec3f(0.0), 1.0, 1.0);
    var hit = x;
    var reach = 1.0;
    if frame.history_valid != 0u {
        if !reflected {
            expected = previous_surface(textureLoad(gb_object, p, 0).xy, x);
            s = surface_frame(p, x);
            r = reproject(prev_depth, prev_normal, prev, expected, s, gp.reprojection_min_cos);
        }
        // The previous pixel must have had a glossy lobe (its hit class is set).
        if in_bounds(r.texel) && decode_hit_class(textureLoad(prev_hit, r.texel, 0).w) != HIT_NONE {
            if !reflected {
                c = confidence(gp.hysteresis, r.distance);
            } else if lobe_class != HIT_NONE {
                hit = representative_hit(p, x);
                reach = hit_reach(p, x, roughness);
                r = reproject_hit(prev, hit, reach, lobe_class);
                if r.distance >= 0.0 {
                    c = gp.hysteresis * (1.0 - smoothstep(gp.d0_px, gp.d1_px, r.distance));
                }
            } else {
                c = gp.hysteresis;
            }
        }
    }
    var result = current;
    var n = 1.0;
    var clip = 0.0;
    var own = 0.0;
    if c > 0.0 {
        let texel = textureLoad(history, r.texel, 0);
        let still = gp.static_view != 0u && gp.still_frames > 0.0 && c >= gp.hysteresis;
        n = next_length(texel.a, still);
        var hist = half_safe(texel.rgb);
        if r.bilinear {
            // Each tap tested as the texel was: a glossy lobe, and the surface (eq. (11) on the
            // primary surface) or, where it is tested, the reflected hit.
            let b = bilinear_taps(prev);
            var ok = lobe_taps(b);
            if !reflected {
                ok = ok & surface_taps(prev_depth, prev_normal, b, expected, s, gp.reprojection_min_cos);
            } else if lobe_class != HIT_NONE {
                ok = hit_taps(b, hit, reach, lobe_class);
            }
            hist = half_safe(load_taps(history, b, passing_weights(b, ok)).rgb);
            n = resampled_length(n, prev, gp.resampled_history_frames);
        }
        n = rescaled_length(n - 1.0) + 1.0;
        own = select(0.0, 1.0, all(r.texel == p) && (!r.bilinear || all(prev == vec2f(p) + 0.5)));
        var clipped = hist;
        if gstage_on(GSTAGE_CLIPPING) && roughness < gp.clip_roughness {
            clipped = clip_to_neighbourhood(neighbourhood, p, hist);
            clip = clamp(length(clipped - hist) / max(length(hist), 1e-4), 0.0, 1.0);
        }
        result = mix(clipped, current, new_frame_weight(c, n, gp.still_frames, still));
    }
    textureStore(dst, p, vec4f(half_safe(result), n));
    textureStore(out_info, p, vec4f(c, clip, n, own));
}
