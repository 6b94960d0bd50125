// Shared by SVGF's stages (Schied et al. 2017, with Voorhuis §4 and §6): parameters, the
// per-signal and per-level uniforms, the edge-stopping weights and the moment integration.
// engine/src/denoise/svgf/mod.rs mirrors SvgfParams and Level.

struct SvgfParams {
    // Switches (SV_*), SvgfSettings::bits.
    bits: u32,
    // Weights of the current frame in the moving averages of the light and the moments.
    alpha: f32,
    alpha_moments: f32,
    // Edge-stopping: luminance in standard deviations, normal exponent, depth in gradients.
    sigma_l: f32,
    sigma_n: f32,
    sigma_z: f32,
    // In a still view the moving averages' weights fall to 1 / this (0: never).
    still_frames: f32,
    // Light of at least this many samples' worth runs only the first settled_levels levels.
    settled_samples: f32,
    settled_levels: u32,
    // The final regression (svgf/regression.wgsl): window radius (pixels), residual stop (standard
    // deviations), and the samples' worth below which it passes the a-trous output on.
    regression_radius: f32,
    regression_k: f32,
    regression_samples: f32,
    regression_order: f32,
    // Past this many samples' worth the intervals narrow as sqrt(this / samples) (0: never).
    regression_full_samples: f32,
    // The spike cut's ratio to the second brightest neighbour (0: off; SvgfSettings::spike_ratio).
    spike_ratio: f32,
    // The temporal stages' reprojection passes a previous texel only where its normal is
    // within this cosine of the surface's (Schied et al. §4.1's normal test).
    normal_min_cos: f32,
}

// Per dispatch: which a-trous level (step 2^level pixels), whether it writes the history.
struct Level {
    step: i32,
    write_history: u32,
    index: u32,
    _pad0: u32,
}

var<uniform> sv: SvgfParams;

const SV_TEMPORAL: u32 = 1u;
const SV_SPATIAL_VARIANCE: u32 = 2u;
const SV_ACCUMULATED_MOMENTS: u32 = 4u;
const SV_BANDWIDTH_BOOST: u32 = 8u;
const SV_VARIANCE_FILTERING: u32 = 16u;
const SV_FIREFLY: u32 = 32u;
const SV_REFLECTION_REPROJECTION: u32 = 64u;
const SV_CLIPPING: u32 = 128u;
const SV_MIRROR_FEATURES: u32 = 256u;
const SV_VARIANCE_OF_MEAN: u32 = 512u;
const SV_FILTERED_HISTORY: u32 = 1024u;
const SV_GLOSSY_TEMPORAL: u32 = 2048u;
const SV_REGRESSION: u32 = 4096u;
const SV_HIT_TEST: u32 = 8192u;

fn sv_on(bit: u32) -> bool {
    return (sv.bits & bit) != 0u;
}

// A pixel's edge-stopping features: linear view depth, its screen-space gradient (|dz/dx| +
// |dz/dy|, SVGF's fwidth) and the normal. The signal module (features_matte.wgsl,
// features_glossy.wgsl) says which surface's features a signal edge-stops on.
struct Features {
    z: f32,
    dz: f32,
    n: vec3f,
}

// SVGF eq. (3)-(5): the depth, normal and luminance terms of the a-trous weight of tap q
// (offset `offset` pixels from p), before the kernel's h(q). phi_l = sigma_l sqrt(g(var)).
fn edge_weight(c: Features, t: Features, offset: f32, lc: f32, lt: f32, phi_l: f32) -> f32 {
    let wz = abs(c.z - t.z) / (sv.sigma_z * max(c.dz, 1e-6) * offset + 1e-6);
    let wn = pow(max(dot(c.n, t.n), 0.0), sv.sigma_n);
    let wl = abs(lc - lt) / (phi_l + 1e-10);
    return exp(-wz - wl) * wn;
}

// Running moments of one signal: first and second moment of luminance, the history length h
// (frames, this one included) and the sum of the squared weights the light was integrated with
// (its variance is the samples' times this), as stored in the moments texture (m1, m2, h, s).
// Schied et al. §4.1: mu'_i = mix(mu_i history, mu_i now, alpha) with alpha = 0.2 once a
// history exists; Voorhuis §6 averages the first frames truly (alpha = 1 / h up to h = 5, four
// reprojections). The light follows max(alpha, 1 / h) either way, so that its first frames are
// a mean and not the first sample's echo. In a still view both fall as 1 / h to
// 1 / still_frames.
struct Integrated {
    light: vec3f,
    moments: vec4f,
}

fn integrate(current: vec3f, history: vec3f, moments_in: vec4f, reprojected: bool) -> Integrated {
    // After a change of size the history was resampled (realtime/rescale.wgsl): it counts as
    // at most frame.rescaled_frames, and its light's variance as that many frames' mean.
    var moments = moments_in;
    let h_cap = rescaled_length(moments.z);
    if h_cap < moments.z {
        moments = vec4f(moments.xy, h_cap, max(moments.w, 1.0 / h_cap));
    }
    let l = luminance(current);
    let now = vec2f(l, l * l);
    if !reprojected {
        return Integrated(current, vec4f(now, 1.0, 1.0));
    }
    // 2^24: frames stay whole numbers in f32 (77 hours at 60 frames per second).
    let h = min(moments.z + 1.0, 16777216.0);
    var floor_alpha = sv.alpha;
    var floor_moments = sv.alpha_moments;
    if frame.static_view != 0u && sv.still_frames > 0.0 {
        floor_alpha = min(floor_alpha, 1.0 / sv.still_frames);
        floor_moments = min(floor_moments, 1.0 / sv.still_frames);
    }
    let alpha = max(floor_alpha, 1.0 / h);
    var alpha_m = floor_moments;
    if sv_on(SV_ACCUMULATED_MOMENTS) || floor_moments < sv.alpha_moments {
        alpha_m = max(floor_moments, select(0.0, 1.0 / h, h <= 5.0 || floor_moments < sv.alpha_moments));
    }
    let m = mix(moments.xy, now, alpha_m);
    let s = (1.0 - alpha) * (1.0 - alpha) * clamp(moments.w, 0.0, 1.0) + alpha * alpha;
    return Integrated(mix(history, current, alpha), vec4f(m, h, s));
}

// What TAA follows of a signal (taa/matte.wgsl, in matte/reason's format), from the moments the
// temporal stage stored: REASON_DISOCCLUDED where the history restarted this frame,
// REASON_NEIGHBOUR where it was not this pixel's own texel (`own`: read exactly, under a zero
// motion vector), and above the 8 flag bits the samples' worth of the light (1 / the sum of the
// squared integration weights), so that TAA follows a still view's mean but keeps averaging
// SVGF's 0.2 moving average (about 9 samples' worth). A still pixel on a silhouette or a room's
// corner reads a neighbour whenever the jitter moved its sample to the other surface: its light
// then jumps between the two surfaces' from frame to frame, and TAA averages it, as it does
// under Mara's chain (matte/temporal.wgsl), instead of showing the last surface's alone.
fn follow_state(moments: vec4f, own: bool) -> u32 {
    var state = select(REASON_NEIGHBOUR, 0u, own);
    if moments.z < 2.0 {
        state = REASON_DISOCCLUDED;
    }
    let worth = 1.0 / max(moments.w, 1e-6);
    return state | (u32(clamp(worth + 0.5, 0.0, 16777215.0)) << 8u);
}

// Whether a motion vector is zero (the history texel under it is read exactly).
fn still_motion(mv: vec2f) -> bool {
    return dot(mv, mv) <= 1e-8;
}

// The variance the filter steers by, from the samples' variance and the moments texel: of one
// sample (Schied et al.) or of the integrated light (SV_VARIANCE_OF_MEAN).
fn steering_variance(sample_variance: f32, moments: vec4f) -> f32 {
    var v = max(sample_variance, 0.0);
    if sv_on(SV_VARIANCE_OF_MEAN) {
        v *= clamp(moments.w, 0.0, 1.0);
    }
    return min(v, 65000.0);
}

// A pixel's edge-stopping features as the variance stage packs them into its taps record
// (variance.wgsl: pack_taps), and the signal's reach bound (signal_sigma) in its fourth word.
fn tap_features(t: vec4u) -> Features {
    return Features(bitcast<f32>(t.x), bitcast<f32>(t.y), oct_decode(unpack2x16snorm(t.z)));
}

fn tap_reach(t: vec4u) -> f32 {
    return bitcast<f32>(t.w);
}

