// Pre-filter step 3: the bandwidths SURE chose, smoothed by a Gaussian of 1.5 pixels (§5: they
// "can be very noisy"), filter every feature with the same world-position weights (eq. (1), (3),
// (4)): normal, view depth, base colour and metallic, F0 and roughness, emission and f90. Motion
// and ids pass unchanged. The variances of the filtered normal and view depth come from dual
// buffers (§5, after Rousselle et al. 2013): the features filtered once with the weights of the
// even samples' positions and once with the odd samples', their squared difference over 4.

var<storage, read> pf_bandwidth: array<f32>;
var<storage, read_write> pf_features: array<vec4u>;
// x the filtered view depth's relative variance (dual buffers), y the bandwidth after smoothing,
// z the world positions' spread (RMS distance from their mean) in pixels, w the filtered
// normal's variance (dual buffers): the later stages' `gb_uncertainty`.
var pf_view: texture_storage_2d<rgba16float, write>;
// xy the raw octahedral normal (the G-buffer holds the filtered one), z the filtered view
// depth's relative variance (dual buffers), w unused.
var pf_normals: texture_storage_2d<rgba16float, write>;

// A tap below this weight adds nothing visible (and its features are not read).
const MIN_WEIGHT: f32 = 1e-4;

fn feature(i: u32, w: u32) -> vec4f {
    return bitcast<vec4f>(pr_features[i * 5u + w]);
}

fn finite_or_zero(v: vec4f) -> vec4f {
    return select(vec4f(0.0), v, finite4(v));
}

fn features_finite(i: u32) -> bool {
    return finite4(feature(i, 0u)) && finite4(feature(i, 1u)) && finite4(feature(i, 2u)) && finite4(feature(i, 3u));
}

// The odd samples' mean position, from the mean of all and of the even ones.
fn odd_position(s: Stats) -> vec3f {
    let n_b = s.n - s.n_a;
    return select(s.p, (s.p * s.n - s.p_a * s.n_a) / max(n_b, 1.0), n_b >= 1.0);
}

fn oct_of(n: vec3f) -> vec2f {
    let len = length(n);
    return select(vec2f(0.0), oct_encode(n / len), len > 1e-12);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let c = vec2i(gid.xy);
    if !inside(c) {
        return;
    }
    let ci = pixel_index(c);
    // Unfiltered (non-finite values zeroed) unless the filter below replaces them.
    for (var w = 0u; w < 4u; w++) {
        pf_features[ci * 5u + w] = bitcast<vec4u>(finite_or_zero(feature(ci, w)));
    }
    pf_features[ci * 5u + 4u] = pr_features[ci * 5u + 4u];
    let sc = stats_at(c);
    let raw_n = finite_or_zero(feature(ci, 0u));
    if sc.n < 1.0 || !features_finite(ci) {
        textureStore(pf_view, c, vec4f(0.0));
        textureStore(pf_normals, c, vec4f(oct_of(raw_n.xyz), 0.0, 0.0));
        return;
    }
    // The bandwidth, smoothed over the pixels with a surface.
    var h = 0.0;
    var g_sum = 0.0;
    for (var dy = -WINDOW_RADIUS; dy <= WINDOW_RADIUS; dy++) {
        for (var dx = -WINDOW_RADIUS; dx <= WINDOW_RADIUS; dx++) {
            let q = c + vec2i(dx, dy);
            if !inside(q) || textureLoad(pf_inv_b, q, 0).w < 1.0 {
                continue;
            }
            let g = exp(-f32(dx * dx + dy * dy) / (2.0 * SMOOTH_SIGMA * SMOOTH_SIGMA));
            h += g * pf_bandwidth[pixel_index(q)];
            g_sum += g;
        }
    }
    h /= g_sum;
    let cov_trace = 3.0 * sc.sigma2_n * sc.n;
    let spread = sqrt(max(cov_trace, 0.0)) / max(pixel_footprint(sc.p), 1e-30);
    var variance = 0.0;
    var depth_variance = 0.0;
    if h >= 0.05 {
        var sum_w = 0.0;
        var normal_depth = vec4f(0.0);
        var base = vec4f(0.0);
        var spec = vec4f(0.0);
        var emission = vec4f(0.0);
        // Dual buffers: the even samples' positions (a) and the odd samples' (b).
        var w_ab = vec2f(0.0);
        var nd_a = vec4f(0.0);
        var nd_b = vec4f(0.0);
        let pb_c = odd_position(sc);
        for (var dy = -WINDOW_RADIUS; dy <= WINDOW_RADIUS; dy++) {
            for (var dx = -WINDOW_RADIUS; dx <= WINDOW_RADIUS; dx++) {
                let q = c + vec2i(dx, dy);
                if !inside(q) {
                    continue;
                }
                let sq = stats_at(q);
                if sq.n < 1.0 {
                    continue;
                }
                let wi = weight(mahalanobis(sc, sq, sq.p - sc.p).w, h);
                let wa = weight(mahalanobis(sc, sq, sq.p_a - sc.p_a).w, h);
                let wb = weight(mahalanobis(sc, sq, odd_position(sq) - pb_c).w, h);
                if max(wi, max(wa, wb)) < MIN_WEIGHT {
                    continue;
                }
                // Each feature read once (a storage-buffer read is a loop over the lanes on a
                // CPU driver).
                let qi = pixel_index(q);
                let nd = feature(qi, 0u);
                let fb = feature(qi, 1u);
                let fs = feature(qi, 2u);
                let fe = feature(qi, 3u);
                if !(finite4(nd) && finite4(fb) && finite4(fs) && finite4(fe)) {
                    continue;
                }
                sum_w += wi;
                normal_depth += wi * nd;
                base += wi * fb;
                spec += wi * fs;
                emission += wi * fe;
                w_ab += vec2f(wa, wb);
                nd_a += wa * nd;
                nd_b += wb * nd;
            }
        }
        let inv = 1.0 / sum_w;
        let f = ci * 5u;
        pf_features[f] = bitcast<vec4u>(normal_depth * inv);
        pf_features[f + 1u] = bitcast<vec4u>(base * inv);
        pf_features[f + 2u] = bitcast<vec4u>(spec * inv);
        pf_features[f + 3u] = bitcast<vec4u>(emission * inv);
        let diff = nd_a / max(w_ab.x, 1e-30) - nd_b / max(w_ab.y, 1e-30);
        variance = dot(diff.xyz, diff.xyz) / 4.0;
        let z = max(abs(normal_depth.w * inv), 1e-30);
        depth_variance = diff.w * diff.w / 4.0 / (z * z);
    }
    textureStore(pf_view, c, vec4f(min(depth_variance, 65000.0), h, min(spread, 65000.0), min(variance, 65000.0)));
    textureStore(pf_normals, c, vec4f(oct_of(raw_n.xyz), min(depth_variance, 65000.0), 0.0));
}
