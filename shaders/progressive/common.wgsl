// Shared by the progressive filter's stages (Dundr et al., progressive SVGF, §4-5):
// parameters, the schedule test, the weights of §4.4. engine/src/denoise/progressive.rs
// mirrors ProgressiveParams and Level.

struct ProgressiveParams {
    // a of r = max(a, 1 / age) (§4.2); in a still view at most 1 / still_samples.
    alpha: f32,
    still_samples: f32,
    // §4.4.1-4.4.3: sigma_N, sigma_D, sigma_L, epsilon of the luminance weight.
    sigma_n: f32,
    sigma_d: f32,
    sigma_l: f32,
    epsilon_l: f32,
    // 1: accumulate over samples (§4.2); 0: each frame alone.
    temporal: u32,
    // In a still view epsilon_l falls as this / age past this many samples (0: never).
    epsilon_full_samples: f32,
    // The feedback level's output becomes the history of a pixel traced this frame whose
    // history holds fewer samples than this (0: never).
    feedback_samples: f32,
    // 1: w_L reads the larger of the centre's and the tap's variances; 0: the centre's (Dundr).
    symmetric_luminance: u32,
    // In a still view a level of step s filters a pixel whose light holds at most this x
    // (16 / s)^2 samples (0: every level everywhere).
    reach_samples: f32,
    // w_L's symmetric bandwidth takes a tap's variance up to this x the centre's (0: no cap).
    variance_cap: f32,
    // The temporal stage's reprojection passes a previous texel only where its normal is within
    // this cosine of the surface's.
    normal_min_cos: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

// Per dispatch: the a-trous step (large scale first), whether the signal only fills pixels
// without samples (the direct light: it carries the material, which a filter would blur), and
// whether this level's output feeds the history (Dundr §4.4: the step-1 level, run first).
struct Level {
    step: i32,
    fill_only: u32,
    feedback: u32,
    _pad0: u32,
}

var<uniform> pp: ProgressiveParams;
// Linear depth, its screen-space gradient and the octahedral normal (progressive/features).
var features: texture_2d<f32>;

// Dundr's luminance (§4.2: 0.299 R + 0.587 G + 0.114 B).
fn luma(c: vec3f) -> f32 {
    return dot(c, vec3f(0.299, 0.587, 0.114));
}

// §4.4: w = w_N w_D w_L between pixel p (features fc, normal nc, luminance lc, variance;
// lc < 0: no light there yet, no luminance weight) and tap q `offset` pixels away.
// The luminance weight's epsilon at a pixel whose light accumulated `age` samples: epsilon_l,
// and in a still view past epsilon_full_samples epsilon_l x epsilon_full_samples / age. The
// variance term beside it is the variance of the mean, which falls as 1 / age; a fixed epsilon
// (Dundr's 0.01 to 0.1, in displayed luminance) outlasts it and keeps the 61-pixel filter
// blurring a converged view's shading.
fn luminance_epsilon(age: f32) -> f32 {
    if frame.static_view == 0u || pp.epsilon_full_samples <= 0.0 {
        return pp.epsilon_l;
    }
    return pp.epsilon_l * min(1.0, pp.epsilon_full_samples / max(age, 1.0));
}

fn dundr_weight(fc: vec2f, nc: vec3f, lc: f32, variance: f32, epsilon: f32, fq: vec2f, nq: vec3f, lq: f32, offset: f32) -> f32 {
    // §4.4.1
    let w_n = pow(max(dot(nc, nq), 0.0), pp.sigma_n);
    // §4.4.2: deviation from the local slope; epsilon 0.5% of the depth (Dundr's 0.005 of a
    // normalised depth buffer). Very steep surfaces (a tenth of the depth per pixel) keep the
    // normal weight alone.
    var w_d = 1.0;
    if fc.y < 0.1 * fc.x {
        w_d = exp(-abs(fc.x - fq.x) / (abs(pp.sigma_d * fc.y * offset) + 0.005 * fc.x));
    }
    // §4.4.3
    var w_l = 1.0;
    if lc >= 0.0 {
        w_l = exp(-abs(lc - lq) / (pp.sigma_l * variance + epsilon));
    }
    return w_n * w_d * w_l;
}
