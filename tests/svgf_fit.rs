//! SVGF's final regression solves its weighted least-squares fit (shaders/svgf/fit.wgsl) as a
//! CPU solve in f64 does: the fit at the pixel and (A^-1)_00, for a mean, a plane and a quadric,
//! over windows like the regression's (radius 1, 4 and 16, whole and cut by an edge on one
//! side, some neighbours edge-stopped).

use hush_engine::gpu::{Gpu, GpuRequirements};
use hush_tests::compute::{Input, run_compute};

const FIT_TEST: &str = r#"
struct Tap {
    w: f32,
    u: f32,
    v: f32,
    _pad: f32,
    l: vec4f,
}

@group(0) @binding(0) var<storage, read> taps: array<Tap>;
@group(0) @binding(1) var<storage, read_write> result: array<vec4f>;

const TAPS: u32 = 81u;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let c = gid.x;
    if c * TAPS >= arrayLength(&taps) {
        return;
    }
    var s: Sums;
    for (var i = 0u; i < TAPS; i++) {
        let t = taps[c * TAPS + i];
        if t.w > 0.0 {
            add_tap(&s, t.w, t.u, t.v, t.l.rgb, 0.0);
        }
    }
    let unknowns = array<i32, 3>(1, 3, 6);
    for (var k = 0u; k < 3u; k++) {
        let f = solve(s, unknowns[k]);
        result[c * 3u + k] = vec4f(f.beta0, select(-1.0, f.inv00, f.ok));
    }
}
"#;

const TAPS: usize = 81;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Default)]
struct Tap {
    w: f32,
    u: f32,
    v: f32,
    _pad: f32,
    l: [f32; 4],
}

/// xorshift32: the cases are the same on every run.
struct Rng(u32);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        (self.0 >> 8) as f32 / (1 << 24) as f32
    }
}

/// One window: the centre (weight 1) and a (2k + 1)^2 grid of radius r around it, as the
/// regression lays its taps ((u, v) = offset / 32); `cut` keeps only the side dx >= 0; a fifth
/// of the neighbours are edge-stopped (weight 0), the rest weigh 0.05 to 1. The light is a
/// smooth field (a quadric in (u, v), per channel) plus noise.
fn window(rng: &mut Rng, r: i32, cut: bool, stopped_all: bool) -> Vec<Tap> {
    let step = (r / 4).max(1);
    let mut taps = vec![];
    let coef: Vec<[f32; 6]> = (0..3)
        .map(|_| std::array::from_fn(|i| if i == 0 { 0.2 + rng.next() } else { rng.next() - 0.5 }))
        .collect();
    for dy in (-r..=r).step_by(step as usize) {
        for dx in (-r..=r).step_by(step as usize) {
            let centre = dx == 0 && dy == 0;
            let (u, v) = (dx as f32 / 32.0, dy as f32 / 32.0);
            let phi = [1.0, u, v, u * u, u * v, v * v];
            let l: [f32; 3] = std::array::from_fn(|c| {
                let smooth: f32 = coef[c].iter().zip(phi).map(|(a, p)| a * p).sum();
                (smooth + 0.2 * (rng.next() - 0.5)).max(0.0)
            });
            let mut w = 0.05 + 0.95 * rng.next();
            if rng.next() < 0.2 || (cut && dx < 0) || stopped_all {
                w = 0.0;
            }
            if centre {
                w = 1.0;
            }
            taps.push(Tap { w, u, v, _pad: 0.0, l: [l[0], l[1], l[2], 0.0] });
        }
    }
    taps.resize(TAPS, Tap::default());
    taps
}

/// The fit at the pixel (rgb) and (A^-1)_00 by Gaussian elimination with partial pivoting, in
/// f64, with the shader's ridge (1e-3 of sum w on every diagonal entry but the first).
fn cpu_fit(taps: &[Tap], n: usize) -> ([f64; 3], f64) {
    let mut a = vec![vec![0.0f64; n + 4]; n];
    let m0: f64 = taps.iter().map(|t| t.w as f64).sum();
    for t in taps.iter().filter(|t| t.w > 0.0) {
        let (u, v, w) = (t.u as f64, t.v as f64, t.w as f64);
        let phi = [1.0, u, v, u * u, u * v, v * v];
        for i in 0..n {
            for j in 0..n {
                a[i][j] += w * phi[i] * phi[j];
            }
            for c in 0..3 {
                a[i][n + c] += w * phi[i] * t.l[c] as f64;
            }
        }
    }
    for (i, row) in a.iter_mut().enumerate() {
        if i > 0 {
            row[i] += 1e-3 * m0;
        }
        // e_0, for (A^-1)_00.
        row[n + 3] = if i == 0 { 1.0 } else { 0.0 };
    }
    for col in 0..n {
        let pivot = (col..n).max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs())).unwrap();
        a.swap(col, pivot);
        let pivot_row = a[col].clone();
        for (row, r) in a.iter_mut().enumerate() {
            if row != col {
                let f = r[col] / pivot_row[col];
                for (x, p) in r.iter_mut().zip(&pivot_row).skip(col) {
                    *x -= f * p;
                }
            }
        }
    }
    let x = |k: usize| a[0][n + k] / a[0][0];
    ([x(0), x(1), x(2)], x(3))
}

/// Measured worst difference from the f64 solve, in units of the window's largest light:
/// 3.5e-7 (mean), 6.2e-7 (plane), 9.4e-7 (quadric), f32 rounding. A wrong moment or block in
/// the solve moves the fit by a share of the light (one of Q's entries misplaced: (A^-1)_00 off
/// by 2%), so 1e-3 leaves room for another device's rounding and still fails such a solve.
#[test]
fn the_regression_fit_matches_a_cpu_solve() {
    let gpu = Gpu::headless(&GpuRequirements::default()).unwrap();
    let mut rng = Rng(0x9e37_79b9);
    let mut cases = vec![];
    for _ in 0..8 {
        for r in [1, 4, 16] {
            for cut in [false, true] {
                cases.push(window(&mut rng, r, cut, false));
            }
        }
    }
    // Every neighbour edge-stopped: the pixel alone, whatever the order.
    cases.push(window(&mut rng, 4, false, true));
    let flat: Vec<Tap> = cases.concat();
    let out = run_compute(
        &gpu,
        FIT_TEST,
        &["svgf/fit.wgsl"],
        &[Input::Storage(bytemuck::cast_slice(&flat))],
        (cases.len() * 3 * 16) as u64,
        ((cases.len() as u32).div_ceil(64), 1),
    );
    let out: &[[f32; 4]] = bytemuck::cast_slice(&out);
    let mut worst = [0.0f64; 3];
    for (ci, taps) in cases.iter().enumerate() {
        let scale = taps.iter().flat_map(|t| t.l[..3].iter()).fold(0.0f32, |m, l| m.max(*l)) as f64;
        for (k, n) in [1, 3, 6].into_iter().enumerate() {
            let g = out[ci * 3 + k];
            assert!(g[3] > 0.0, "case {ci}, {n} unknowns: the solve failed");
            let (beta, inv00) = cpu_fit(taps, n);
            let err = (0..3).map(|c| (g[c] as f64 - beta[c]).abs()).fold(0.0, f64::max) / scale;
            worst[k] = worst[k].max(err);
            let inv_err = (g[3] as f64 - inv00).abs() / inv00;
            assert!(inv_err < 1e-3, "case {ci}, {n} unknowns: (A^-1)_00 {} against {inv00}", g[3]);
        }
    }
    println!(
        "worst fit error / light: mean {:.2e}, plane {:.2e}, quadric {:.2e}",
        worst[0], worst[1], worst[2]
    );
    for (k, w) in worst.iter().enumerate() {
        assert!(*w < 1e-3, "{} unknowns: fit off by {w:.2e} of the light", [1, 3, 6][k]);
    }
}
