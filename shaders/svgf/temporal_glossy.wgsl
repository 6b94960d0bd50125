// SVGF §4.1 for the glossy light, with Voorhuis §4: below the roughness threshold the history
// follows the reflection motion vectors of the diamond search (glossy/motion.wgsl) without the
// surface consistency tests (the reflected hit is tested instead, glossy/reproject.wgsl), and
// below the clip roughness it is clipped to the 5x5 box of the 7x7-blurred current frame
// (glossy/prefilter.wgsl; §4.2.3); above, it is reprojected as the matte light. Behind mirrors the light is divided by the reflected surface's reflectance
// (glossy_input, §4.1) and multiplied back by the final stage.
// Outputs: integrated (rgb, this frame's raw luminance), moments (m1, m2, h).

var prev_depth: texture_depth_2d;
var prev_normal: texture_2d<f32>;
var history: texture_2d<f32>;
var moments: texture_2d<f32>;
var motion: texture_2d<f32>;
var neighbourhood: texture_2d<f32>;
var out_integrated: texture_storage_2d<rgba32float, write>;
var out_moments: texture_storage_2d<rgba32float, write>;
// What TAA follows of the light (svgf/common.wgsl: follow_state).
var out_state: texture_storage_2d<r32uint, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let current = glossy_input(p);
    if !has_surface(p) {
        textureStore(out_integrated, p, vec4f(current, luminance(current)));
        textureStore(out_moments, p, vec4f(0.0));
        textureStore(out_state, p, vec4u(follow_state(vec4f(0.0), false), 0u, 0u, 0u));
        return;
    }
    let x = position_at(p);
    let roughness = roughness_at(p);
    var reprojected = false;
    // The history is this pixel's own texel, read exactly.
    var own = false;
    var hist = vec3f(0.0);
    var mom = vec4f(0.0);
    if sv_on(SV_TEMPORAL) && sv_on(SV_GLOSSY_TEMPORAL) && frame.history_valid != 0u {
        // In a static view the reflection stood still too: the surface test is exact there.
        let reflected = sv_on(SV_REFLECTION_REPROJECTION) && roughness < gp.roughness_threshold && gp.static_view == 0u;
        let prev = vec2f(p) + 0.5 + textureLoad(motion, p, 0).xy;
        var r = Reprojection(vec2i(floor(prev)), true, -1.0);
        let lobe_class = select(HIT_NONE, tested_class(roughness, true), sv_on(SV_HIT_TEST));
        // What the texel was tested with, for the bilinear taps: the surface's expected point
        // and frame, or the reflected hit and its reach.
        var expected = x;
        var s = SurfaceFrame(vec3f(0.0), 1.0, 1.0);
        var hit = x;
        var reach = 1.0;
        if reflected && lobe_class != HIT_NONE {
            // The reflected hit is tested as the glossy chain tests it (glossy/reproject.wgsl);
            // untested, the history kept what the surface reflected before a reflected object
            // moved.
            hit = representative_hit(p, x);
            reach = hit_reach(p, x, roughness);
            r = reproject_hit(prev, hit, reach, lobe_class);
            if r.distance > gp.d1_px {
                r.distance = -1.0;
            }
        } else if reflected {
            r.distance = select(-1.0, 0.0, in_bounds(r.texel));
        } else {
            expected = previous_surface(textureLoad(gb_object, p, 0).xy, x);
            s = surface_frame(p, x);
            r = reproject(prev_depth, prev_normal, prev, expected, s, sv.normal_min_cos);
            if r.distance > frame.d1_px || (r.distance >= 0.0 && !same_object(p, r.texel)) {
                r.distance = -1.0;
            }
        }
        // The previous pixel must have had a glossy lobe (its hit class is set).
        if r.distance >= 0.0 && decode_hit_class(textureLoad(prev_hit, r.texel, 0).w) != HIT_NONE {
            mom = textureLoad(moments, r.texel, 0);
            hist = half_safe(textureLoad(history, r.texel, 0).rgb);
            if r.bilinear {
                // Each tap tested as the texel was: a glossy lobe, and where the surface test
                // applies, the surface and its object.
                let b = bilinear_taps(prev);
                var ok = lobe_taps(b);
                if !reflected {
                    ok = same_object_taps(p, b, ok & surface_taps(prev_depth, prev_normal, b, expected, s, sv.normal_min_cos));
                } else if lobe_class != HIT_NONE {
                    ok = hit_taps(b, hit, reach, lobe_class);
                }
                let w = passing_weights(b, ok);
                hist = half_safe(load_taps(history, b, w).rgb);
                mom = vec4f(load_taps(moments, b, w).xy, mom.zw);
            }
            reprojected = mom.z >= 1.0;
            own = r.bilinear && still_motion(textureLoad(gb_motion, p, 0).xy);
            if reprojected && sv_on(SV_CLIPPING) && roughness < gp.clip_roughness {
                hist = clip_to_neighbourhood(neighbourhood, p, hist);
            }
        }
    }
    let i = integrate(current, hist, mom, reprojected);
    textureStore(out_integrated, p, vec4f(half_safe(i.light), luminance(current)));
    textureStore(out_moments, p, i.moments);
    textureStore(out_state, p, vec4u(follow_state(i.moments, own), 0u, 0u, 0u));
}
