// Moon et al. 2017, "Noise Reduction on G-Buffers for Monte Carlo Filtering": the pre-filter of
// the traced primaries' features (realtime/primaries.wgsl writes pr_features and pr_moments in
// the layout described there). Shared by prefilter/covariance.wgsl, sure.wgsl and features.wgsl.

var<storage, read> pr_features: array<vec4u>;
var<storage, read> pr_moments: array<vec4u>;

// The filter window Omega_c: 7x7 (§5).
const WINDOW_RADIUS: i32 = 3;
// Std. deviation (pixels) of the Gaussian that smooths the covariances and the bandwidths (§5).
const SMOOTH_SIGMA: f32 = 1.5;

fn pixel_index(p: vec2i) -> u32 {
    return u32(p.y) * frame.size.x + u32(p.x);
}

fn inside(p: vec2i) -> bool {
    return all(p >= vec2i(0)) && all(p < vec2i(frame.size));
}

fn finite4(v: vec4f) -> bool {
    return all(v == v) && all(abs(v) <= vec4f(3.0e38));
}

// A pixel's world-position statistics; n = 0 where no sample hit or where anything is not finite.
struct Moments {
    p: vec3f,
    n: f32,
    // xx, xy, xz, yy and yz, zz
    s_a: vec4f,
    s_b: vec2f,
    n_a: f32,
    p_a: vec3f,
}

fn moments_at(i: u32) -> Moments {
    let a = bitcast<vec4f>(pr_moments[i * 4u]);
    let b = bitcast<vec4f>(pr_moments[i * 4u + 1u]);
    let c = bitcast<vec4f>(pr_moments[i * 4u + 2u]);
    let d = bitcast<vec4f>(pr_moments[i * 4u + 3u]);
    var m = Moments(a.xyz, a.w, b, c.xy, c.z, d.xyz);
    if !(finite4(a) && finite4(b) && finite4(c) && finite4(d)) || a.w < 1.0 {
        m.n = 0.0;
    }
    return m;
}

// Symmetric 3x3 matrices as (xx, xy, xz, yy) and (yz, zz).
fn sym_mul(a: vec4f, b: vec2f, v: vec3f) -> vec3f {
    return vec3f(
        a.x * v.x + a.y * v.y + a.z * v.z,
        a.y * v.x + a.w * v.y + b.x * v.z,
        a.z * v.x + b.x * v.y + b.y * v.z,
    );
}

// What prefilter/covariance.wgsl keeps per pixel for the later steps, as textures (a texel
// read is one load per lane on a CPU driver, a storage-buffer read a loop over the lanes):
// the inverse of the smoothed, regularised covariance, sigma^2 / n of eq. (6), the hits n
// (0: no usable surface), the mean position and the even samples' mean position.
struct Stats {
    // S^-1 as xx, xy, xz, yy and yz, zz.
    a: vec4f,
    b: vec2f,
    sigma2_n: f32,
    n: f32,
    p: vec3f,
    p_a: vec3f,
    n_a: f32,
}
// Eq. (4): the Mahalanobis distance of p_i from p_c under S_c^-1 + S_i^-1; d.xyz is
// (S_c^-1 + S_i^-1) delta, d.w the distance.
fn mahalanobis(c: Stats, i: Stats, delta: vec3f) -> vec4f {
    let ad = sym_mul(c.a + i.a, c.b + i.b, delta);
    return vec4f(ad, dot(delta, ad));
}

// Eq. (3).
fn weight(d: f32, h: f32) -> f32 {
    return exp(-d / (2.0 * h * h));
}

// The world-space size of a pixel at view depth z.
fn pixel_footprint(p: vec3f) -> f32 {
    let z = max(dot(p - frame.cam_pos.xyz, normalize(frame.cam_fwd.xyz)), 0.0);
    return z * 2.0 * length(frame.cam_up.xyz) / f32(frame.size.y);
}
