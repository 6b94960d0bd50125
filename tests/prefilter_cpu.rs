//! The pre-filter's statistics computed on the CPU (f64), step by step as the shaders do it
//! (Moon et al. 2017, eq. 3-6 and appendix A), for `prefilter.rs` to hold the GPU's against.

use super::*;
pub(crate) fn gauss(dx: i64, dy: i64) -> f64 {
    (-((dx * dx + dy * dy) as f64) / (2.0 * 1.5 * 1.5)).exp()
}

pub(crate) fn window(x: usize, y: usize) -> impl Iterator<Item = (i64, i64, usize)> {
    (-3i64..=3).flat_map(move |dy| (-3i64..=3).map(move |dx| (dx, dy))).filter_map(
        move |(dx, dy)| {
            let (qx, qy) = (x as i64 + dx, y as i64 + dy);
            (qx >= 0 && qy >= 0 && qx < W as i64 && qy < H as i64)
                .then(|| (dx, dy, qy as usize * W + qx as usize))
        },
    )
}

pub(crate) type Sym = [f64; 6]; // xx, xy, xz, yy, yz, zz

pub(crate) fn invert(s: Sym) -> Sym {
    let [xx, xy, xz, yy, yz, zz] = s;
    let c00 = yy * zz - yz * yz;
    let c01 = xz * yz - xy * zz;
    let c02 = xy * yz - xz * yy;
    let det = xx * c00 + xy * c01 + xz * c02;
    [
        c00 / det,
        c01 / det,
        c02 / det,
        (xx * zz - xz * xz) / det,
        (xy * xz - xx * yz) / det,
        (xx * yy - xy * xy) / det,
    ]
}

pub(crate) fn mul(a: Sym, v: [f64; 3]) -> [f64; 3] {
    [
        a[0] * v[0] + a[1] * v[1] + a[2] * v[2],
        a[1] * v[0] + a[3] * v[1] + a[4] * v[2],
        a[2] * v[0] + a[4] * v[1] + a[5] * v[2],
    ]
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn sub(a: [f32; 3], b: [f32; 3]) -> [f64; 3] {
    [(a[0] - b[0]) as f64, (a[1] - b[1]) as f64, (a[2] - b[2]) as f64]
}

/// Step 1: S smoothed by the 1.5-pixel Gaussian, regularised, inverted.
pub(crate) fn cpu_inverse(px: &[Pixel]) -> Vec<Sym> {
    (0..W * H)
        .map(|c| {
            let (x, y) = (c % W, c / W);
            let mut s = [0.0; 6];
            let mut wsum = 0.0;
            for (dx, dy, q) in window(x, y) {
                let g = gauss(dx, dy);
                let p = &px[q];
                for (k, v) in
                    [p.s_a[0], p.s_a[1], p.s_a[2], p.s_a[3], p.s_b[0], p.s_b[1]].iter().enumerate()
                {
                    s[k] += g * *v as f64;
                }
                wsum += g;
            }
            let z = -px[c].p[2] as f64;
            let eps = (REGULARISATION * footprint(z)).powi(2);
            let mut s = s.map(|v| v / wsum);
            s[0] += eps;
            s[3] += eps;
            s[5] += eps;
            invert(s)
        })
        .collect()
}

/// Step 2: SURE (eq. 6) for every bandwidth; returns (chosen h, margin to the runner-up).
pub(crate) fn cpu_sure(px: &[Pixel], inv: &[Sym], c: usize) -> (f64, f64) {
    let (x, y) = (c % W, c / W);
    let pc = &px[c];
    let sigma2_n = (pc.s_a[0] + pc.s_a[3] + pc.s_b[1]) as f64 / 3.0 / pc.n as f64;
    let mut scores = vec![(0.0, sigma2_n)];
    for h in BANDWIDTHS {
        let (mut w_sum, mut wd, mut sd, mut sad) = (0.0, 0.0, [0.0; 3], [0.0; 3]);
        for (_, _, q) in window(x, y) {
            let delta = sub(px[q].p, pc.p);
            let a: Sym = std::array::from_fn(|k| inv[c][k] + inv[q][k]);
            let ad = mul(a, delta);
            let d = dot(delta, ad);
            let w = (-d / (2.0 * h * h)).exp();
            w_sum += w;
            wd += w * d;
            for k in 0..3 {
                sd[k] += w * delta[k];
                sad[k] += w * ad[k];
            }
        }
        let m = sd.map(|v| v / w_sum);
        let div = (3.0 + (wd - dot(m, sad)) / (h * h)) / w_sum;
        scores.push((h, dot(m, m) / 3.0 - sigma2_n + 2.0 * sigma2_n * div / 3.0));
    }
    let mut sorted = scores.clone();
    sorted.sort_by(|a, b| a.1.total_cmp(&b.1));
    (sorted[0].0, (sorted[1].1 - sorted[0].1) / sigma2_n)
}

/// Step 3: the bandwidth smoothed, then the base colour filtered with eq. (3)'s weights.
pub(crate) fn cpu_base(px: &[Pixel], inv: &[Sym], h_raw: &[f32], c: usize) -> f64 {
    let (x, y) = (c % W, c / W);
    let (mut h, mut g_sum) = (0.0, 0.0);
    for (dx, dy, q) in window(x, y) {
        h += gauss(dx, dy) * h_raw[q] as f64;
        g_sum += gauss(dx, dy);
    }
    h /= g_sum;
    if h < 0.05 {
        return px[c].base[0] as f64;
    }
    let (mut sum, mut wsum) = (0.0, 0.0);
    for (_, _, q) in window(x, y) {
        let delta = sub(px[q].p, px[c].p);
        let a: Sym = std::array::from_fn(|k| inv[c][k] + inv[q][k]);
        let w = (-dot(delta, mul(a, delta)) / (2.0 * h * h)).exp();
        sum += w * px[q].base[0] as f64;
        wsum += w;
    }
    sum / wsum
}
