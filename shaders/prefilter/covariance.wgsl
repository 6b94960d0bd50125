// Pre-filter step 1: per pixel, the covariance of the world-position samples (appendix B)
// smoothed by a Gaussian of 1.5 pixels (§5: "we have also applied the same Gaussian filtering to
// the per-pixel covariance matrix S_c since [its] elements ... can be noisy"), regularised and
// inverted for the Mahalanobis distance of eq. (4).
//
// The regularisation: samples of a surface lie in its plane, so S is singular along the normal
// (and wholly zero with one sample). Adding (REGULARISATION x the pixel's footprint)^2 to the
// diagonal bounds S^-1: two neighbours a twentieth of a pixel apart along the normal are then
// one standard deviation apart, so a depth step stops the filter while a plane does not.
const REGULARISATION: f32 = 0.05;

var pf_inv_a: texture_storage_2d<rgba32float, write>;
var pf_inv_b: texture_storage_2d<rgba32float, write>;
var pf_position: texture_storage_2d<rgba32float, write>;
var pf_half: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let c = vec2i(gid.xy);
    if !inside(c) {
        return;
    }
    let ci = pixel_index(c);
    let mc = moments_at(ci);
    if mc.n < 1.0 {
        textureStore(pf_inv_a, c, vec4f(0.0));
        textureStore(pf_inv_b, c, vec4f(0.0));
        textureStore(pf_position, c, vec4f(0.0));
        textureStore(pf_half, c, vec4f(0.0));
        return;
    }
    var sa = vec4f(0.0);
    var sb = vec2f(0.0);
    var wsum = 0.0;
    for (var dy = -WINDOW_RADIUS; dy <= WINDOW_RADIUS; dy++) {
        for (var dx = -WINDOW_RADIUS; dx <= WINDOW_RADIUS; dx++) {
            let q = c + vec2i(dx, dy);
            if !inside(q) {
                continue;
            }
            let m = moments_at(pixel_index(q));
            if m.n < 1.0 {
                continue;
            }
            let g = exp(-f32(dx * dx + dy * dy) / (2.0 * SMOOTH_SIGMA * SMOOTH_SIGMA));
            sa += g * m.s_a;
            sb += g * m.s_b;
            wsum += g;
        }
    }
    sa /= wsum;
    sb /= wsum;
    let fp = pixel_footprint(mc.p);
    let eps = max(REGULARISATION * REGULARISATION * fp * fp, 1e-30);
    sa += vec4f(eps, 0.0, 0.0, eps);
    sb += vec2f(0.0, eps);
    // The inverse of a symmetric 3x3 matrix by its cofactors.
    let xx = sa.x; let xy = sa.y; let xz = sa.z; let yy = sa.w; let yz = sb.x; let zz = sb.y;
    let c00 = yy * zz - yz * yz;
    let c01 = xz * yz - xy * zz;
    let c02 = xy * yz - xz * yy;
    let det = xx * c00 + xy * c01 + xz * c02;
    var inv_a = vec4f(1.0 / eps, 0.0, 0.0, 1.0 / eps);
    var inv_b = vec2f(0.0, 1.0 / eps);
    if det > 0.0 && det < 3.0e38 {
        let r = 1.0 / det;
        inv_a = vec4f(c00, c01, c02, xx * zz - xz * xz) * r;
        inv_b = vec2f(xy * xz - xx * yz, xx * yy - xy * xy) * r;
    }
    if !(finite4(inv_a) && finite4(vec4f(inv_b, 0.0, 0.0))) {
        inv_a = vec4f(1.0 / eps, 0.0, 0.0, 1.0 / eps);
        inv_b = vec2f(0.0, 1.0 / eps);
    }
    // sigma^2(p~_c): the per-coordinate variance of the raw samples, the noise of the model
    // p~_c = p_c + eps_c I of §4.4; over n for the variance of their mean.
    let sigma2 = (mc.s_a.x + mc.s_a.w + mc.s_b.y) / 3.0;
    textureStore(pf_inv_a, c, inv_a);
    textureStore(pf_inv_b, c, vec4f(inv_b, sigma2 / mc.n, mc.n));
    textureStore(pf_position, c, vec4f(mc.p, 0.0));
    textureStore(pf_half, c, vec4f(mc.p_a, mc.n_a));
}
