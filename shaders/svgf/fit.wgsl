// The weighted least-squares fit of svgf/regression.wgsl: L(q) over the basis phi(u, v),
// (u, v) = (q - p) / 32: (1), (1, u, v) or (1, u, v, u^2, uv, v^2) (n = 1, 3, 6 unknowns),
// summed window by window. tests/svgf_fit.rs checks it against a CPU solve. The normal
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

// The fit at the pixel (beta_0, rgb) and (A^-1)_00 of the ridge-regularised normal matrix A: in
// a window symmetric about the pixel the first-order beta_0 is the weighted mean; in one cut by
// an edge the slopes take out what the mean's off-centre centroid would add, and the second
// order the curvature of a falloff.
struct Fit {
    beta0: vec3f,
    inv00: f32,
    ok: bool,
}

// The inverse of a 3x3 matrix by its cofactors (rows of the inverse: the cross products of the
// columns over the determinant), and the determinant.
struct Inverse3 {
    m: mat3x3f,
    det: f32,
}

fn inverse3(a: mat3x3f) -> Inverse3 {
    let c0 = cross(a[1], a[2]);
    let det = dot(a[0], c0);
    let cofactors = mat3x3f(c0, cross(a[2], a[0]), cross(a[0], a[1]));
    return Inverse3(transpose(cofactors) * (1.0 / det), det);
}

// The fit with n unknowns. Only row 0 of A^-1 is needed: beta_0 = sum_i (A^-1)_0i b_i. A is split
// into 3x3 blocks over (1, u, v) and (u^2, uv, v^2), A = [[P, Q], [Q^T, R]], and row 0 of its
// inverse is [p0^T + (Y h)^T, -h^T] with p0 = P^-1 e_0, Y = P^-1 Q, h = S^-1 Q^T p0 and the Schur
// complement S = R - Q^T Y. Every quantity is a vec3 or mat3x3 in registers: a 6x6 Cholesky over
// private arrays indexed by loop counters cost lavapipe (which indexes such arrays through a
// ladder over their entries) half the stage (docs/decisions.md). A Gram matrix plus the ridge is
// positive definite, so P and S are too; a determinant that is not positive is a fit lost to
// rounding or non-finite input, and the window is skipped.
fn solve(s: Sums, n: i32) -> Fit {
    let fail = Fit(vec3f(0.0), 0.0, false);
    if n == 1 {
        if !(s.m0.x > 1e-20) {
            return fail;
        }
        return Fit(s.b0 / s.m0.x, 1.0 / s.m0.x, true);
    }
    let ridge = 1e-3 * s.m0.x;
    let p = inverse3(mat3x3f(
        vec3f(s.m0.x, s.m0.y, s.m0.z),
        vec3f(s.m0.y, s.m0.w + ridge, s.m1.x),
        vec3f(s.m0.z, s.m1.x, s.m1.y + ridge),
    ));
    if !(p.det > 0.0) {
        return fail;
    }
    let p0 = p.m[0];
    if n == 3 {
        return Fit(p0.x * s.b0 + p0.y * s.b1 + p0.z * s.b2, p0.x, true);
    }
    // Q's columns: (A_03, A_13, A_23), (A_04, ...), (A_05, ...).
    let q = mat3x3f(
        vec3f(s.m0.w, s.m1.z, s.m1.w),
        vec3f(s.m1.x, s.m1.w, s.m2.x),
        vec3f(s.m1.y, s.m2.x, s.m2.y),
    );
    let r = mat3x3f(
        vec3f(s.m2.z + ridge, s.m2.w, s.m3.x),
        vec3f(s.m2.w, s.m3.x + ridge, s.m3.y),
        vec3f(s.m3.x, s.m3.y, s.m3.z + ridge),
    );
    let y = p.m * q;
    let qt = transpose(q);
    let schur = inverse3(r - qt * y);
    if !(schur.det > 0.0) {
        return fail;
    }
    let h = schur.m * (qt * p0);
    let k = p0 + y * h;
    let beta0 = k.x * s.b0 + k.y * s.b1 + k.z * s.b2 - (h.x * s.b3 + h.y * s.b4 + h.z * s.b5);
    return Fit(beta0, k.x, true);
}
