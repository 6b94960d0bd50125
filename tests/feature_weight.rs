//! The edge-stops that weigh features against their own variances (shaders/common/
//! feature_weight.wgsl: SVGF's regression where the pre-filter gives the filtered normal's and
//! depth's dual-buffer variances) against a CPU computation of the same distances in f64, and
//! the properties that make them worth having: with no variance they are SVGF's eq. (3) and (4)
//! terms, a difference the two features' noise explains costs nothing, and a difference well past
//! the noise is still stopped.

use hush_engine::gpu::{Gpu, GpuRequirements};
use hush_tests::Xorshift;
use hush_tests::compute::{Input, run_compute};

const WEIGHT_TEST: &str = r#"
struct Case {
    // depth_distance's dz, s, var_c, var_t
    depth: vec4f,
    // normal_weight's cos, sigma_n, var_c, var_t
    normal: vec4f,
}

@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read_write> result: array<vec2f>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let i = gid.x;
    if i >= arrayLength(&cases) {
        return;
    }
    let c = cases[i];
    result[i] = vec2f(
        depth_distance(c.depth.x, c.depth.y, c.depth.z, c.depth.w),
        normal_weight(c.normal.x, c.normal.y, c.normal.z, c.normal.w),
    );
}
"#;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable, Default)]
struct Case {
    depth: [f32; 4],
    normal: [f32; 4],
}

/// Rousselle et al. 2013's feature distance, as the shader's comment states it: the squared
/// difference less var_c + min(var_c, var_t), over the larger of s^2 and var_c.
fn cpu_depth(dz: f64, s: f64, vc: f64, vt: f64) -> f64 {
    ((dz * dz - (vc + vc.min(vt))).max(0.0) / (s * s).max(vc)).sqrt()
}

/// |n_c - n_t|^2 / 2 = 1 - cos less half the normals' noise, then SVGF's (cos')^sigma_n.
fn cpu_normal(cos: f64, sigma_n: f64, vc: f64, vt: f64) -> f64 {
    let d = (1.0 - cos - 0.5 * (vc + vc.min(vt))).max(0.0);
    (1.0 - d).max(0.0).powf(sigma_n)
}

fn run(cases: &[Case]) -> Vec<[f32; 2]> {
    let gpu = Gpu::headless(&GpuRequirements::default()).unwrap();
    let out = run_compute(
        &gpu,
        WEIGHT_TEST,
        &["common/feature_weight.wgsl"],
        &[Input::Storage(bytemuck::cast_slice(cases))],
        (cases.len() * 8) as u64,
        ((cases.len() as u32).div_ceil(64), 1),
    );
    bytemuck::cast_slice::<u8, [f32; 2]>(&out).to_vec()
}

/// Random cases over the ranges the regression meets (depth differences up to a few times the
/// expected step, variances from none to several times the squared difference; normals from
/// equal to opposite, sigma_n 1 to 256), against the f64 computation. The worst relative error
/// measured is f32 rounding (2.4e-7 of the weight exp(-d), 2.3e-5 of the normal weight, whose large powers amplify it); a
/// missing min(), a variance not subtracted or a wrong normalisation moves them by a share of
/// the value, which 1e-3 catches.
#[test]
fn feature_weights_match_a_cpu_computation() {
    // xorshift32: the cases are the same on every run.
    let mut rng = Xorshift(0x2545_f491);
    let mut cases = vec![];
    for i in 0..512 {
        let s = 0.01 + rng.uniform();
        let dz = (rng.uniform() - 0.5) * 8.0 * s;
        // A quarter of the cases have no variance at all (a pixel in focus).
        let var =
            |r: &mut Xorshift| if i % 4 == 0 { 0.0 } else { (r.uniform() * 3.0 * dz).powi(2) };
        let (vc, vt) = (var(&mut rng), var(&mut rng));
        let cos = 1.0 - 2.0 * rng.uniform().powi(3);
        let sigma_n = [1.0, 32.0, 128.0, 256.0][i % 4];
        let nv = |r: &mut Xorshift| if i % 4 == 0 { 0.0 } else { 0.2 * r.uniform().powi(2) };
        let (nc, nt) = (nv(&mut rng), nv(&mut rng));
        cases.push(Case { depth: [dz, s, vc, vt], normal: [cos, sigma_n, nc, nt] });
    }
    let got = run(&cases);
    let (mut worst_z, mut worst_n) = (0.0f64, 0.0f64);
    for (i, (c, g)) in cases.iter().zip(&got).enumerate() {
        let [dz, s, vc, vt] = c.depth.map(f64::from);
        let want_z = (-cpu_depth(dz, s, vc, vt)).exp();
        let err_z = ((-g[0] as f64).exp() - want_z).abs() / want_z.max(1e-6);
        let [cos, sn, nc, nt] = c.normal.map(f64::from);
        let want_n = cpu_normal(cos, sn, nc, nt);
        let err_n = (g[1] as f64 - want_n).abs() / want_n.max(1e-6);
        // Below 1e-6 the weight drops the tap either way.
        if want_z > 1e-6 {
            worst_z = worst_z.max(err_z);
            assert!(err_z < 1e-3, "case {i}: depth weight {} against {want_z}", (-g[0]).exp());
        }
        if want_n > 1e-6 {
            worst_n = worst_n.max(err_n);
            assert!(err_n < 1e-3, "case {i}: normal weight {} against {want_n}", g[1]);
        }
    }
    println!("worst relative error: depth weight {worst_z:.2e}, normal weight {worst_n:.2e}");
}

/// No variance: SVGF's terms (|dz| / s and max(0, cos)^sigma_n). A difference the variances
/// explain: weight 1. Twice the noise's reach: still stopped, as without variance.
#[test]
fn feature_weights_reduce_to_svgf_and_forgive_only_noise() {
    let cases = [
        // SVGF: |dz| / s = 3; cos 0.9^128; an opposite normal.
        Case { depth: [0.3, 0.1, 0.0, 0.0], normal: [0.9, 128.0, 0.0, 0.0] },
        Case { depth: [-0.3, 0.1, 0.0, 0.0], normal: [-0.5, 128.0, 0.0, 0.0] },
        // Both pixels' variance 0.05 (noise 0.1 in dz^2): dz 0.3 -> dz^2 0.09 is explained; the
        // normals' 0.1 each: 1 - cos = 0.1 is explained.
        Case { depth: [0.3, 0.1, 0.05, 0.05], normal: [0.9, 128.0, 0.1, 0.1] },
        // The tap's variance is counted only up to the pixel's own (min): a noisy neighbour
        // does not open the pixel's filter.
        Case { depth: [0.3, 0.1, 0.0, 1.0], normal: [0.9, 128.0, 0.0, 1.0] },
        // Well past the noise: dz 1.0 against noise 0.1, normalised by var_c 0.05.
        Case { depth: [1.0, 0.1, 0.05, 0.05], normal: [0.5, 128.0, 0.1, 0.1] },
    ];
    let g = run(&cases);
    assert!((g[0][0] - 3.0).abs() < 1e-5, "{}", g[0][0]);
    assert!((g[0][1] - 0.9f32.powf(128.0)).abs() < 1e-9, "{}", g[0][1]);
    assert!((g[1][0] - 3.0).abs() < 1e-5 && g[1][1] == 0.0, "{:?}", g[1]);
    assert!(g[2][0] == 0.0 && (g[2][1] - 1.0).abs() < 1e-6, "{:?}", g[2]);
    assert!((g[3][0] - 3.0).abs() < 1e-5, "{:?}", g[3]);
    assert!((g[3][1] - 0.9f32.powf(128.0)).abs() < 1e-9, "{:?}", g[3]);
    // sqrt((1 - 0.1) / 0.05) = 4.24: the tap weighs exp(-4.24) = 1.4%.
    assert!((g[4][0] - (0.9f32 / 0.05).sqrt()).abs() < 1e-4, "{:?}", g[4]);
    assert!(g[4][1] < 1e-6, "{:?}", g[4]);
}
