// SVGF §4.1 for the matte light: reverse-reproject last frame's filtered light and moments with
// the G-buffer's motion vectors, test the previous depth and normal (matte/common.wgsl's
// `reproject`: the texel under the vector sampled bilinearly where it passes, from those of the
// four taps that pass too, else the closest of its 3x3 neighbours) and object (matte/common.wgsl:
// same_object), and integrate (common.wgsl). Also writes the features every later stage
// edge-stops on: linear depth and its gradient.
// Outputs: integrated (rgb, this frame's raw luminance), moments (m1, m2, h), features (z, dz).
// Where the history restarts, the radiance cache's prior (cache/prior.wgsl) stands in for it.

var prev_depth: texture_depth_2d;
var prev_normal: texture_2d<f32>;
var history: texture_2d<f32>;
var moments: texture_2d<f32>;
var out_integrated: texture_storage_2d<rgba32float, write>;
var out_moments: texture_storage_2d<rgba32float, write>;
// What TAA follows of the light (svgf/common.wgsl: follow_state).
var out_state: texture_storage_2d<r32uint, write>;
var out_features: texture_storage_2d<rg32float, write>;

// The luminance variance of the matte light over the 3x3 pixels with a surface that averaged k
// paths, as this one did (0 where fewer than two did).
fn paths_variance(p: vec2i, k: f32) -> f32 {
    var m = vec3f(0.0);
    for (var j = 0; j < 9; j++) {
        let q = p + vec2i(j % 3 - 1, j / 3 - 1);
        if in_bounds(q) && has_surface(q) && matte_paths(q) == k {
            let l = luminance(half_safe(matte_input(q)));
            m += vec3f(1.0, l, l * l);
        }
    }
    if m.x < 2.0 {
        return 0.0;
    }
    let mean = m.y / m.x;
    return max(m.z / m.x - mean * mean, 0.0) * m.x / (m.x - 1.0);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let current = half_safe(matte_input(p));
    if !has_surface(p) {
        textureStore(out_integrated, p, vec4f(current, luminance(current)));
        textureStore(out_moments, p, vec4f(0.0));
        textureStore(out_state, p, vec4u(follow_state(vec4f(0.0), false), 0u, 0u, 0u));
        textureStore(out_features, p, vec4f(-1.0, 0.0, 0.0, 0.0));
        return;
    }
    let x = position_at(p);
    let z = linear_depth(x);
    let dz = depth_gradient(p, z);
    textureStore(out_features, p, vec4f(z, dz, 0.0, 0.0));

    var reprojected = false;
    // The history is this pixel's own texel, read exactly.
    var own = false;
    var hist = vec3f(0.0);
    var mom = vec4f(0.0);
    if sv_on(SV_TEMPORAL) && frame.history_valid != 0u {
        let mv = textureLoad(gb_motion, p, 0).xy;
        let prev = vec2f(p) + 0.5 + mv;
        let expected = previous_surface(textureLoad(gb_object, p, 0).xy, x);
        let s = surface_frame(p, x);
        let r = reproject(prev_depth, prev_normal, prev, expected, s, sv.normal_min_cos);
        if r.distance >= 0.0 && r.distance <= frame.d1_px && same_object(p, r.texel) {
            mom = textureLoad(moments, r.texel, 0);
            hist = half_safe(textureLoad(history, r.texel, 0).rgb);
            if r.bilinear {
                let b = bilinear_taps(prev);
                let ok = surface_taps(prev_depth, prev_normal, b, expected, s, sv.normal_min_cos);
                let w = passing_weights(b, same_object_taps(p, b, ok));
                hist = half_safe(load_taps(history, b, w).rgb);
                mom = vec4f(load_taps(moments, b, w).xy, mom.zw);
            }
            // A previous texel without a history (a miss then) does not count.
            reprojected = mom.z >= 1.0;
            own = r.bilinear && still_motion(mv);
        }
    }
    var i = integrate(current, hist, mom, reprojected);
    // A history that restarts here counts this frame's sample as the k paths the trace averaged
    // into it (more where it saw the surface uncovered: realtime/uncovered.wgsl), and starts
    // from the radiance cache's prior where there is one (passes/cache.rs), as `prior.a`
    // samples of the cell's mean beside them. Its moments are one path's, as the history's
    // are: the k-path mean's luminance, and k times the variance of that mean across the
    // neighbours that took k paths too; the prior's from the cell's samples (their luminance's
    // mean and mean square). A history of k + a paths takes its variance from the moments (the
    // variance pass's spatial estimate is for fewer than 4), and one sample's would be 0.
    if !reprojected && sv_on(SV_TEMPORAL) && frame.history_valid != 0u {
        let k = matte_paths(p);
        if k > 1.0 {
            let l = luminance(current);
            i = Integrated(current, vec4f(l, l * l + k * paths_variance(p, k), k, 1.0 / k));
        }
        let prior = cache_prior_at(p);
        if prior.a > 0.0 {
            let w = k / (k + prior.a);
            let m = mix(vec2f(luminance(prior.rgb), cache_prior_m2_at(p)), i.moments.xy, w);
            i = Integrated(mix(prior.rgb, current, w), vec4f(m, k + prior.a, 1.0 / (k + prior.a)));
        }
    }
    textureStore(out_integrated, p, vec4f(half_safe(i.light), luminance(current)));
    textureStore(out_moments, p, i.moments);
    textureStore(out_state, p, vec4u(follow_state(i.moments, own), 0u, 0u, 0u));
}
