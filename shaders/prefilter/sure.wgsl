// Pre-filter step 2 (§4.4): per pixel, the bandwidth h of eq. (3) that minimises Stein's
// unbiased risk estimate (eq. (6)) of the error of the filtered world position (eq. (5)), from
// {0, 0.4, 0.8, 1.2, 1.6, 2.0} (§5). h = 0 leaves the pixel unfiltered, with error sigma^2 / n.
// The divergence of eq. (6) is appendix A's eq. (7)-(9), summed over the three coordinates:
//   div = (3 + (sum_i w_i d_i - m . sum_i w_i A_i delta_i) / h^2) / W
// with delta_i = p~_i - p~_c, A_i = S_c^-1 + S_i^-1, d_i = delta_i . A_i delta_i, W = sum_i w_i
// and m = p^_c - p~_c = sum_i w_i delta_i / W.

// The chosen h per pixel, before smoothing.
var<storage, read_write> pf_bandwidth: array<f32>;

const BANDWIDTHS: u32 = 5u;

fn bandwidth(b: u32) -> f32 {
    return 0.4 * f32(b + 1u);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let c = vec2i(gid.xy);
    if !inside(c) {
        return;
    }
    let ci = pixel_index(c);
    let sc = stats_at(c);
    if sc.n < 1.0 {
        pf_bandwidth[ci] = 0.0;
        return;
    }
    var w_sum: array<f32, BANDWIDTHS>;
    var wd_sum: array<f32, BANDWIDTHS>;
    var delta_sum: array<vec3f, BANDWIDTHS>;
    var ad_sum: array<vec3f, BANDWIDTHS>;
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
            let delta = sq.p - sc.p;
            let md = mahalanobis(sc, sq, delta);
            for (var b = 0u; b < BANDWIDTHS; b++) {
                let w = weight(md.w, bandwidth(b));
                w_sum[b] += w;
                wd_sum[b] += w * md.w;
                delta_sum[b] += w * delta;
                ad_sum[b] += w * md.xyz;
            }
        }
    }
    // h = 0: no filtering, the error is the input's variance.
    var best_h = 0.0;
    var best = sc.sigma2_n;
    for (var b = 0u; b < BANDWIDTHS; b++) {
        let h = bandwidth(b);
        let inv_w = 1.0 / w_sum[b];
        let m = delta_sum[b] * inv_w;
        let div = (3.0 + (wd_sum[b] - dot(m, ad_sum[b])) / (h * h)) * inv_w;
        let sure = dot(m, m) / 3.0 - sc.sigma2_n + 2.0 * sc.sigma2_n * div / 3.0;
        if sure < best {
            best = sure;
            best_h = h;
        }
    }
    pf_bandwidth[ci] = best_h;
}
