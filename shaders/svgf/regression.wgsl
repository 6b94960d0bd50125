// The final filter of settled light: a local regression of the accumulated light (in the manner
// of BMFR, Koskela et al. 2019, per pixel rather than per block) whose reach is chosen per pixel
// by the intersection of confidence intervals (the ICI rule, Katkovnik 1999; Goldenshluger and
// Nemirovski 1997). Nested windows of radius 1, 2, 4, 8 and 16 pixels each give an estimate of
// the light at the pixel, beta_0 of a weighted least-squares fit over the window's taps
// (regression_order: a mean, a plane or a quadric in screen space; SVGF's depth and normal
// edge-stops, eq. (3)-(4); the signal's reach Gaussian), with its standard deviation from the
// taps' pooled variance of the accumulated light.
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

var src: texture_2d<f32>;
// The variance stage's output: rgb the accumulated light, a its variance (of the mean with
// variance_of_mean).
var light: texture_2d<f32>;
var moments: texture_2d<f32>;
var taps: texture_2d<u32>;
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

// The weighted fit of L(q) over the basis phi(u, v), (u, v) = (q - p) / 32: (1), (1, u, v) or
// (1, u, v, u^2, uv, v^2) for regression_order 0, 1, 2, summed window by window. The normal
// matrix of the quadric basis holds only the 15 weighted moments sum w u^a v^b, a + b <= 4, so a
// tap adds four vec4 FMAs instead of a 6x6 outer product, whose matrix, indexed by loop
// counters, would live in local memory on GPUs and in per-lane stack slots on lavapipe (its
// cost: docs/decisions.md). The right-hand sides b (rgb each, one per basis function), sum w^2
// and sum w var give the estimate's variance.
struct Sums {
    // sum w (1, u, v, u^2), (uv, v^2, u^3, u^2 v), (u v^2, v^3, u^4, u^3 v), (u^2 v^2, u v^3, v^4, 0)
    m0: vec4f,
    m1: vec4f,
    m2: vec4f,
    m3: vec4f,
    // sum w phi_i L, i = 0..5
    b0: vec3f,
    b1: vec3f,
    b2: vec3f,
    b3: vec3f,
    b4: vec3f,
    b5: vec3f,
    w2: f32,
    wvar: f32,
}

fn unknowns() -> i32 {
    return array<i32, 3>(1, 3, 6)[min(u32(sv.regression_order), 2u)];
}

fn add_tap(s: ptr<function, Sums>, w: f32, u: f32, v: f32, l: vec3f, variance: f32) {
    let uu = u * u;
    let uv = u * v;
    let vv = v * v;
    (*s).m0 += w * vec4f(1.0, u, v, uu);
    (*s).m1 += w * vec4f(uv, vv, uu * u, uu * v);
    (*s).m2 += w * vec4f(u * vv, vv * v, uu * uu, uu * uv);
    (*s).m3 += w * vec4f(uu * vv, uv * vv, vv * vv, 0.0);
    let wl = w * l;
    (*s).b0 += wl;
    (*s).b1 += u * wl;
    (*s).b2 += v * wl;
    (*s).b3 += uu * wl;
    (*s).b4 += uv * wl;
    (*s).b5 += vv * wl;
    (*s).w2 += w * w;
    (*s).wvar += w * variance;
}

// The fit at the pixel (beta_0, rgb) and (A^-1)_00, by the Cholesky factors of the ridge-
// regularised matrix: in a window symmetric about the pixel the first-order beta_0 is the
// weighted mean; in one cut by an edge the slopes take out what the mean's off-centre centroid
// would add, and the second order the curvature of a falloff.
struct Fit {
    beta0: vec3f,
    inv00: f32,
    ok: bool,
}

fn solve(s: Sums) -> Fit {
    let n = unknowns();
    // The lower triangle of the 6x6 normal matrix from the moments. Basis functions past the
    // order's n are decoupled (unit diagonal, no right-hand side), which leaves beta_0 that of
    // the n x n system while every loop below keeps a constant trip count and unrolls into
    // registers.
    let m0 = s.m0;
    let m1 = s.m1;
    let m2 = s.m2;
    let m3 = s.m3;
    var a = array<f32, 36>(
        m0.x, 0.0, 0.0, 0.0, 0.0, 0.0,
        m0.y, m0.w, 0.0, 0.0, 0.0, 0.0,
        m0.z, m1.x, m1.y, 0.0, 0.0, 0.0,
        m0.w, m1.z, m1.w, m2.z, 0.0, 0.0,
        m1.x, m1.w, m2.x, m2.w, m3.x, 0.0,
        m1.y, m2.x, m2.y, m3.x, m3.y, m3.z,
    );
    var b = array<vec3f, 6>(s.b0, s.b1, s.b2, s.b3, s.b4, s.b5);
    for (var i = 1; i < 6; i++) {
        if i >= n {
            for (var j = 0; j < i; j++) {
                a[i * 6 + j] = 0.0;
            }
            a[i * 6 + i] = 1.0;
            b[i] = vec3f(0.0);
        }
    }
    var l: array<f32, 36>;
    let ridge = 1e-3 * m0.x;
    for (var i = 0; i < 6; i++) {
        for (var j = 0; j <= i; j++) {
            var sum = a[i * 6 + j];
            if i == j && i > 0 {
                sum += ridge;
            }
            for (var k = 0; k < j; k++) {
                sum -= l[i * 6 + k] * l[j * 6 + k];
            }
            if i == j {
                if !(sum > 1e-20) {
                    return Fit(vec3f(0.0), 0.0, false);
                }
                l[i * 6 + i] = sqrt(sum);
            } else {
                l[i * 6 + j] = sum / l[j * 6 + j];
            }
        }
    }
    // Forward then back substitution, for the rgb right-hand side and for e_0.
    var y: array<vec3f, 6>;
    var e: array<f32, 6>;
    for (var i = 0; i < 6; i++) {
        var sy = b[i];
        var se = select(0.0, 1.0, i == 0);
        for (var k = 0; k < i; k++) {
            sy -= l[i * 6 + k] * y[k];
            se -= l[i * 6 + k] * e[k];
        }
        y[i] = sy / l[i * 6 + i];
        e[i] = se / l[i * 6 + i];
    }
    for (var i = 5; i >= 0; i--) {
        var sy = y[i];
        var se = e[i];
        for (var k = i + 1; k < 6; k++) {
            sy -= l[k * 6 + i] * y[k];
            se -= l[k * 6 + i] * e[k];
        }
        y[i] = sy / l[i * 6 + i];
        e[i] = se / l[i * 6 + i];
    }
    return Fit(y[0], e[0], true);
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
    if !sv_on(SV_REGRESSION) || !has_surface(p) || samples < sv.regression_samples {
        textureStore(dst, p, passed);
        return;
    }
    let fc = signal_features(p);
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
    var s: Sums;
    add_tap(&s, 1.0, 0.0, 0.0, c.rgb, max(c.a, 0.0));
    var shown = c.rgb;
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
                let w = exp(-0.5 * offset * offset / (reach * reach)) * edge_weight(fc, fq, offset, 0.0, 0.0, 1.0);
                if w > 1e-3 {
                    let t = textureLoad(light, q, 0);
                    add_tap(&s, w, f32(dx) / 32.0, f32(dy) / 32.0, t.rgb, max(t.a, 0.0));
                }
            }
        }
        // One variance for every tap, the window's mean: a pixel that missed the rare bright
        // paths has a low mean and a low variance of its own, and would hold its interval shut.
        let var_pool = s.wvar / s.m0.x;
        if k == 1 {
            // The pixel alone, its standard deviation the 3x3 window's pooled one.
            let l0 = luminance(c.rgb);
            lo = l0 - narrow_gamma * sqrt(var_pool);
            hi = l0 + narrow_gamma * sqrt(var_pool);
        }
        let fit = solve(s);
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
        shown = c.rgb;
    }
    textureStore(dst, p, vec4f(half_safe(max(shown, vec3f(0.0))), passed.a));
}
