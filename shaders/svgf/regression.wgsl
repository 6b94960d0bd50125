// The final filter of settled light: a local regression of the accumulated light (in the manner
// of BMFR, Koskela et al. 2019, per pixel rather than per block) whose reach is chosen per pixel
// by the intersection of confidence intervals (the ICI rule, Katkovnik 1999; Goldenshluger and
// Nemirovski 1997). Nested windows of radius 1, 2, 4, 8 and 16 pixels each give an estimate of
// the light at the pixel, beta_0 of a weighted least-squares fit over the window's taps
// (regression_order: a mean, a plane or a quadric in screen space; SVGF's depth and normal
// edge-stops, eq. (3)-(4), weighed against the features' own variances where the pre-filter
// gives them (common/feature_weight.wgsl); the signal's reach Gaussian), with its standard
// deviation from the taps' pooled variance of the accumulated light.
//
// The filter keeps widening while a window's interval [beta_0 - gamma sigma, beta_0 + gamma
// sigma] still meets every smaller window's and the pixel's own, and shows the last estimate that
// did. Where the light is flat the widest window fits 192 taps; where a window starts to reach
// across a gradient no feature separates (a contact shadow, a room's corner, a penumbra) its fit
// leaves the smaller windows' intervals and the reach stops there. The intervals narrow as the
// history's variance falls, so the reach falls with it and a still view converges to its
// accumulated mean. No weight depends on the light itself, so Monte Carlo noise's skew (rare
// bright samples) biases nothing, where a luminance edge-stop drops bright taps more often than
// dark ones. Light that has not settled (fewer than `regression_samples`' worth) passes the
// a-trous output on.
//
// The fit reads each tap's light less what the variance stage's spike cut took off it
// (SvgfSettings::spike_ratio: a lone pixel that one rare path made bright), and the pixel shows
// the fit plus the cut light's mean over its surface (svgf/spread.wgsl), whatever window the
// intervals chose: a rare path's light is spread over its surface rather than held as a dot or
// refused by the intervals, which left caustic-lit surfaces dark.

var src: texture_2d<f32>;
// The variance stage's output: rgb the accumulated light, a its variance (of the mean with
// variance_of_mean).
var light: texture_2d<f32>;
// The light the spike cut took off each pixel (svgf/variance.wgsl).
var excess: texture_2d<f32>;
var moments: texture_2d<f32>;
var taps: texture_2d<u32>;
// The cut light's mean over each pixel's surface (svgf/spread.wgsl).
var spread: texture_2d<f32>;
var dst: texture_storage_2d<rgba16float, write>;

// Windows 1..WINDOWS: radius 2^(k-1) (at most regression_radius); a window's new taps lie on a
// grid of its radius / 4 pixels (every pixel up to radius 4), outside the previous window.
const WINDOWS: i32 = 6;

// The half-width of the pixel's own interval and the 3x3 window's, in standard deviations. They
// hold too few samples to judge the wider windows by at `regression_k`: at 1 sigma a third of
// all pixels, those whose mean lies over a sigma from their neighbours', would stop there and
// show their noise. At 3 sigma one pixel in 370 does, and a window that blurs an edge (a shadow's,
// a contact's) by more than 3 sigma of the accumulated light is still refused, so that the
// smallest reach too falls with the variance and a still view converges.
const NARROW_GAMMA: f32 = 3.0;

// The fit's sums and solve: svgf/fit.wgsl.
fn unknowns() -> i32 {
    return array<i32, 3>(1, 3, 6)[min(u32(sv.regression_order), 2u)];
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let passed = textureLoad(src, p, 0);
    let m = textureLoad(moments, p, 0);
    let samples = 1.0 / max(m.w, 1e-6);
    if !regression_fits(p, samples) {
        textureStore(dst, p, passed);
        return;
    }
    let fc = signal_features(p);
    // The variances are the primary surface's: none where the signal edge-stops on another.
    let uncertain = signal_primary_features(p);
    let vc = select(vec2f(0.0), feature_variance(p), uncertain);
    // The signal's reach bound, as the variance stage packed it: lavapipe (Mesa 22.3, LLVM 15)
    // aborts compiling the glossy program when this stage calls signal_sigma itself.
    let reach = tap_reach(textureLoad(taps, p, 0));
    let c = textureLoad(light, p, 0);
    // Past regression_full_samples the intervals narrow as sqrt(full / samples): at a fixed width
    // an accepted window's bias stays a fixed share of the noise, and relMSE a fixed multiple of
    // the accumulation's; narrowing, the reach falls faster than the noise and the view ends at
    // its own mean.
    var narrowing = 1.0;
    if sv.regression_full_samples > 0.0 {
        narrowing = sqrt(min(1.0, sv.regression_full_samples / samples));
    }
    let gamma = sv.regression_k * narrowing;
    let narrow_gamma = NARROW_GAMMA * narrowing;
    let spikes = sv.spike_ratio > 0.0;
    var cut = vec3f(0.0);
    if spikes {
        cut = textureLoad(excess, p, 0).rgb;
    }
    let own = c.rgb - cut;
    var s: Sums;
    add_tap(&s, 1.0, 0.0, 0.0, own, max(c.a, 0.0));
    var shown = own;
    var lo = -1e30;
    var hi = 1e30;
    let widest = min(WINDOWS, i32(floor(log2(max(sv.regression_radius, 1.0)))) + 1);
    for (var k = 1; k <= widest; k++) {
        let r = 1 << u32(k - 1);
        let inner = r / 2;
        let step = max(r / 4, 1);
        for (var dy = -r; dy <= r; dy += step) {
            for (var dx = -r; dx <= r; dx += step) {
                if max(abs(dx), abs(dy)) <= inner {
                    continue;
                }
                let q = p + vec2i(dx, dy);
                if !in_bounds(q) {
                    continue;
                }
                let fq = tap_features(textureLoad(taps, q, 0));
                if fq.dz < 0.0 {
                    continue;
                }
                let offset = length(vec2f(f32(dx), f32(dy)));
                let vq = select(vec2f(0.0), feature_variance(q), uncertain);
                let w = exp(-0.5 * offset * offset / (reach * reach)) * feature_weight(fc, fq, offset, vc, vq);
                if w > 1e-3 {
                    let t = textureLoad(light, q, 0);
                    var e = vec3f(0.0);
                    if spikes {
                        e = textureLoad(excess, q, 0).rgb;
                    }
                    add_tap(&s, w, f32(dx) / 32.0, f32(dy) / 32.0, t.rgb - e, max(t.a, 0.0));
                }
            }
        }
        // One variance for every tap, the window's mean: a pixel that missed the rare bright
        // paths has a low mean and a low variance of its own, and would hold its interval shut.
        let var_pool = s.wvar / s.m0.x;
        if k == 1 {
            // The pixel alone, its standard deviation the 3x3 window's pooled one.
            let l0 = luminance(own);
            lo = l0 - narrow_gamma * sqrt(var_pool);
            hi = l0 + narrow_gamma * sqrt(var_pool);
        }
        let fit = solve(s, unknowns());
        if !fit.ok {
            continue;
        }
        let lm = luminance(fit.beta0);
        // Var(beta_0) = var (A^-1)_00 for equal weights; sum w^2 / sum w scales it for others.
        let sd = sqrt(max(var_pool * fit.inv00 * s.w2 / s.m0.x, 0.0));
        let g = select(gamma, narrow_gamma, k < 2);
        lo = max(lo, lm - g * sd);
        hi = min(hi, lm + g * sd);
        if lo > hi {
            break;
        }
        shown = fit.beta0;
    }
    if any(shown != shown) {
        shown = own;
    }
    if spikes {
        shown += half_safe(textureLoad(spread, p, 0).rgb);
    }
    textureStore(dst, p, vec4f(half_safe(max(shown, vec3f(0.0))), passed.a));
}
