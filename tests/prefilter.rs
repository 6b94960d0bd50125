//! Moon et al. 2017's G-buffer pre-filter (engine/src/passes/prefilter.rs) against a CPU
//! computation of the same equations on a synthetic image, NaN/Inf safety, and the traced
//! primaries' world-position covariance against the thin lens's.
//!
//! The synthetic image (64x32 pixels, a camera looking down -Z): the left half is a flat wall
//! seen out of focus (circle of confusion 4 pixels: noisy positions and normals, a wide
//! covariance), the right half in focus (positions within their pixel) with a depth step at
//! column 48 between two walls of different colour.

use bytemuck::Zeroable;
use hush_engine::frame::FrameParams;
use hush_engine::gpu::{Gpu, GpuMemory, GpuRequirements, readback_buffer};
use hush_engine::passes::prefilter::{Prefilter, PrefilterTargets, bindings};
use hush_engine::passes::primaries::PrimaryTargets;

const W: usize = 64;
const H: usize = 32;
const EDGE: usize = 48;
const K: f32 = 4.0;
/// tan(fov / 2): a pixel at depth z is z * 2 * TH / H wide.
const TH: f32 = 0.5;
const BANDWIDTHS: [f64; 5] = [0.4, 0.8, 1.2, 1.6, 2.0];
const REGULARISATION: f64 = 0.05;

struct Rng(u64);
impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        (-2.0 * self.uniform().ln()).sqrt() * (std::f64::consts::TAU * self.uniform()).cos()
    }
}

/// One pixel of the primaries' output (shaders/realtime/primaries.wgsl's layout).
#[derive(Clone, Copy, Default)]
struct Pixel {
    normal_depth: [f32; 4],
    base: [f32; 4],
    spec: [f32; 4],
    emission: [f32; 4],
    p: [f32; 3],
    n: f32,
    s_a: [f32; 4],
    s_b: [f32; 2],
    n_a: f32,
    p_a: [f32; 3],
}

fn footprint(z: f64) -> f64 {
    z * 2.0 * TH as f64 / H as f64
}

fn synthetic() -> Vec<Pixel> {
    let mut rng = Rng(7);
    let mut px = vec![Pixel::default(); W * H];
    for y in 0..H {
        for x in 0..W {
            let defocused = x < W / 2;
            let z = if x >= EDGE { 5.5 } else { 5.0 };
            let fp = footprint(z);
            // In-plane variance: the circle of confusion (radius R pixels: R^2 / 4 per axis, a
            // uniform disk) plus the pixel's own square (1 / 12).
            let var = if defocused { 4.0 * 4.0 / 4.0 + 1.0 / 12.0 } else { 1.0 / 12.0 } * fp * fp;
            let sd = (var / K as f64).sqrt();
            let truth = [
                (x as f64 + 0.5 - W as f64 / 2.0) * fp,
                (H as f64 / 2.0 - y as f64 - 0.5) * fp,
                -z,
            ];
            let p = [truth[0] + sd * rng.normal(), truth[1] + sd * rng.normal(), truth[2]];
            let p_a = [p[0] + sd * rng.normal(), p[1] + sd * rng.normal(), p[2]];
            let noise = if defocused { 0.3 } else { 0.0 };
            let nrm = [noise * rng.normal(), noise * rng.normal(), 1.0];
            let base = if x >= EDGE {
                0.9
            } else if defocused {
                0.5 + 0.2 * rng.normal()
            } else {
                0.1 + 0.1 * ((x + y) % 2) as f64
            };
            px[y * W + x] = Pixel {
                normal_depth: [nrm[0] as f32, nrm[1] as f32, nrm[2] as f32, z as f32],
                base: [base as f32, base as f32, base as f32, 0.0],
                spec: [0.04, 0.04, 0.04, 0.5],
                emission: [0.0; 4],
                p: p.map(|v| v as f32),
                n: K,
                s_a: [var as f32, 0.0, 0.0, var as f32],
                s_b: [0.0, 0.0],
                n_a: K / 2.0,
                p_a: p_a.map(|v| v as f32),
            };
        }
    }
    px
}

/// The pre-filter's outputs, read back.
struct Output {
    inverse: Vec<[f32; 8]>,
    bandwidth: Vec<f32>,
    features: Vec<[[f32; 4]; 5]>,
}

fn run(pixels: &[Pixel]) -> Output {
    let gpu = Gpu::headless(&GpuRequirements::default()).unwrap();
    let d = &gpu.device;
    let mut mem = GpuMemory::default();
    let size = (W as u32, H as u32);
    let primaries = PrimaryTargets::new(d, &mut mem, size, 0);
    let targets = PrefilterTargets::new(d, &mut mem, size, 0);
    let mut fp = FrameParams::zeroed();
    fp.size = [W as u32, H as u32];
    fp.cam_pos = [0.0, 0.0, 0.0, 1e-4];
    fp.cam_fwd = [0.0, 0.0, -1.0, 0.0];
    fp.cam_up = [0.0, TH, 0.0, 0.0];
    fp.cam_right = [TH * W as f32 / H as f32, 0.0, 0.0, 0.0];
    let frame = mem.buffer(
        d,
        "frame",
        size_of::<FrameParams>() as u64,
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    );
    gpu.queue.write_buffer(&frame, 0, bytemuck::bytes_of(&fp));
    let mut features: Vec<f32> = vec![];
    let mut moments: Vec<f32> = vec![];
    for p in pixels {
        for f in [p.normal_depth, p.base, p.spec, p.emission] {
            features.extend(f);
        }
        features.extend([0.0f32; 4]);
        moments.extend([p.p[0], p.p[1], p.p[2], p.n]);
        moments.extend(p.s_a);
        moments.extend([p.s_b[0], p.s_b[1], p.n_a, 0.0]);
        moments.extend([p.p_a[0], p.p_a[1], p.p_a[2], 0.0]);
    }
    gpu.queue.write_buffer(&primaries.features, 0, bytemuck::cast_slice(&features));
    gpu.queue.write_buffer(&primaries.moments, 0, bytemuck::cast_slice(&moments));
    let mut prefilter = Prefilter::default();
    let mut enc = d.create_command_encoder(&Default::default());
    let offered = bindings(&frame, &primaries, &targets);
    let mut rec = hush_engine::gpu::Recorder::new(&gpu, &mut enc, None);
    prefilter.record(&mut rec, Default::default(), size, &offered).unwrap();
    gpu.queue.submit([enc.finish()]);
    let read = |b: &wgpu::Buffer| -> Vec<f32> {
        bytemuck::cast_slice(&readback_buffer(d, &gpu.queue, b, b.size()).unwrap()).to_vec()
    };
    let texels = |t: &wgpu::Texture| -> Vec<[f32; 4]> {
        bytemuck::cast_slice::<u8, f32>(&hush_engine::gpu::readback_texture(&gpu, t).unwrap())
            .chunks(4)
            .map(|c| c.try_into().unwrap())
            .collect()
    };
    let (a, b) = (texels(&targets.stats[0].0), texels(&targets.stats[1].0));
    let inverse = (0..W * H)
        .map(|i| [a[i][0], a[i][1], a[i][2], a[i][3], b[i][0], b[i][1], b[i][2], b[i][3]])
        .collect();
    let bandwidth = read(&targets.bandwidth)[..W * H].to_vec();
    let features = read(&targets.features)
        .chunks(20)
        .take(W * H)
        .map(|c| [0, 1, 2, 3, 4].map(|w| c[w * 4..w * 4 + 4].try_into().unwrap()))
        .collect();
    Output { inverse, bandwidth, features }
}

// The CPU computation (f64), step by step as the shaders do it: prefilter_cpu.rs.
mod prefilter_cpu;
use prefilter_cpu::*;

/// The GPU's inverse covariances, chosen bandwidths and filtered base colour equal the CPU's:
/// the inverse within 0.1% of its largest element (f32 cofactors of a matrix whose condition
/// number is up to 6,400), the bandwidth wherever SURE's best and second-best scores differ by
/// more than 0.1% of sigma^2 / n (closer than that, f32 rounding may pick either), the base colour
/// within 1e-4. Then what SURE is for: on the out-of-focus wall (away from its border) at least
/// 90% of the pixels choose h >= 1.2 (measured 92%) and the filter cuts the normals' noise at
/// least 4x (measured 35x); in focus at least 95% keep h = 0 (measured 99%), the pixels beside
/// the depth step (columns 47 and 48, walls of base colour 0.1-0.2 and 0.9) all h <= 0.4, and
/// the filter moves none of their colours by more than 0.01: the step stays sharp.
#[test]
fn sure_and_world_position_weights_match_a_cpu_computation() {
    let px = synthetic();
    let out = run(&px);
    let inv = cpu_inverse(&px);
    for (c, cpu) in inv.iter().enumerate().take(W * H) {
        let gpu = out.inverse[c];
        let g = [gpu[0], gpu[1], gpu[2], gpu[3], gpu[4], gpu[5]];
        let scale = cpu.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for k in 0..6 {
            assert!(
                (g[k] as f64 - cpu[k]).abs() <= 1e-3 * scale,
                "pixel {c}: S^-1[{k}] {} vs CPU {}",
                g[k],
                cpu[k]
            );
        }
        assert_eq!(gpu[7], K, "hits");
    }
    let (mut compared, mut compared_out_of_focus) = (0, 0);
    for c in 0..W * H {
        let (h, margin) = cpu_sure(&px, &inv, c);
        if margin > 1e-3 {
            compared_out_of_focus += (c % W < W / 2) as usize;
            assert!(
                (out.bandwidth[c] as f64 - h).abs() < 1e-6,
                "pixel ({}, {}): GPU chose h = {}, CPU {h} (margin {margin:.4})",
                c % W,
                c / W,
                out.bandwidth[c]
            );
            compared += 1;
        }
    }
    let in_focus: Vec<f32> =
        (0..W * H).filter(|c| c % W >= W / 2).map(|c| out.bandwidth[c]).collect();
    let hist_focus: Vec<usize> = [0.0, 0.4, 0.8, 1.2, 1.6, 2.0]
        .iter()
        .map(|h| in_focus.iter().filter(|b| (**b - *h as f32).abs() < 1e-6).count())
        .collect();
    println!(
        "{compared} of {} pixels had a clear SURE choice ({compared_out_of_focus} out of focus); in focus, bandwidths 0..2: {hist_focus:?}",
        W * H
    );
    assert!(
        compared_out_of_focus * 10 >= W * H / 2 * 9,
        "out of focus only {compared_out_of_focus} pixels had a clear SURE choice"
    );
    // In focus no neighbour has weight at h <= 0.8, so SURE ties h = 0, 0.4 and 0.8 (eq. (6) is
    // then sigma^2 / n for each) and the smallest wins: the in-focus half, its depth step
    // included, stays unfiltered.
    assert!(
        hist_focus[0] * 100 >= in_focus.len() * 95,
        "in focus only {} of {} pixels chose h = 0",
        hist_focus[0],
        in_focus.len()
    );
    for y in 0..H {
        for x in [EDGE - 1, EDGE] {
            assert!(
                out.bandwidth[y * W + x] <= 0.4 + 1e-6,
                "in-focus step at ({x}, {y}) chose h = {}",
                out.bandwidth[y * W + x]
            );
        }
    }
    for c in 0..W * H {
        let cpu = cpu_base(&px, &inv, &out.bandwidth, c);
        assert!(
            (out.features[c][1][0] as f64 - cpu).abs() < 1e-4,
            "pixel {c}: filtered base {} vs CPU {cpu}",
            out.features[c][1][0]
        );
    }
    // The out-of-focus wall, 4 pixels from its borders.
    let interior: Vec<usize> =
        (4..H - 4).flat_map(|y| (4..W / 2 - 4).map(move |x| y * W + x)).collect();
    let wide = interior.iter().filter(|&&c| out.bandwidth[c] >= 1.2).count();
    let (mut raw, mut filtered) = (0.0, 0.0);
    for &c in &interior {
        raw += (px[c].normal_depth[0].powi(2) + px[c].normal_depth[1].powi(2)) as f64;
        filtered += (out.features[c][0][0].powi(2) + out.features[c][0][1].powi(2)) as f64;
    }
    let hist: Vec<usize> = [0.0, 0.4, 0.8, 1.2, 1.6, 2.0]
        .iter()
        .map(|h| {
            out.bandwidth
                .iter()
                .enumerate()
                .filter(|(c, b)| (**b - *h as f32).abs() < 1e-6 && c % W < W / 2)
                .count()
        })
        .collect();
    println!(
        "out of focus: {wide} of {} interior pixels chose h >= 1.2 (bandwidth histogram 0..2: {hist:?}); normal noise {raw:.3} -> {filtered:.3} ({:.1}x)",
        interior.len(),
        raw / filtered
    );
    assert!(
        wide * 10 >= interior.len() * 9,
        "out of focus, only {wide} of {} pixels chose a wide bandwidth",
        interior.len()
    );
    assert!(raw >= 4.0 * filtered, "normal noise only {raw} -> {filtered}");
    for y in 0..H {
        for x in [EDGE - 1, EDGE] {
            let c = y * W + x;
            let moved = (out.features[c][1][0] - px[c].base[0]).abs();
            assert!(
                moved <= 0.01,
                "in-focus step at ({x}, {y}): base colour moved by {moved} (h = {})",
                out.bandwidth[c]
            );
        }
    }
}

/// Non-finite statistics or features (a NaN normal, an infinite position or covariance) leave
/// every output finite: such a pixel counts as having no surface, and no neighbour takes from it.
#[test]
fn nan_and_inf_never_leave_the_prefilter() {
    let mut px = synthetic();
    px[5 * W + 10].p[0] = f32::NAN;
    px[6 * W + 11].s_a[0] = f32::INFINITY;
    px[7 * W + 12].normal_depth[1] = f32::NAN;
    px[8 * W + 13].base[0] = f32::INFINITY;
    px[9 * W + 40].p_a[2] = f32::NEG_INFINITY;
    px[10 * W + 41].s_b[1] = f32::NAN;
    let out = run(&px);
    for c in 0..W * H {
        assert!(out.bandwidth[c].is_finite(), "bandwidth at {c}");
        assert!(
            out.inverse[c].iter().all(|v| v.is_finite()),
            "inverse at {c}: {:?}",
            out.inverse[c]
        );
        for w in 0..4 {
            assert!(
                out.features[c][w].iter().all(|v| v.is_finite()),
                "feature {w} at ({}, {}): {:?}",
                c % W,
                c / W,
                out.features[c][w]
            );
        }
    }
}

/// The traced primaries' world-position covariance (appendix B, eq. (10)) against the thin
/// lens's, on a plane facing the camera 4 m away with the lens focused at 2 m: a lens ray through
/// the focus point F from lens point L meets the plane at L (1 - z/f) + F z/f, so the samples
/// spread over a disk of radius R = r |1 - z/f| (variance R^2 / 4 per axis, (n - 1) / n of it in
/// expectation as eq. (10) divides by n) plus the covariance of the n sample positions in the
/// pixel (scaled by its footprint), and not at all along the normal. 64 samples a pixel, mean over 64x64 pixels: the sample variance of
/// one pixel has a relative standard deviation of about 1/8, the mean over 4096 pixels 0.2%;
/// allowed 2%.
#[test]
fn primaries_covariance_matches_the_thin_lens() {
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::scene::{Camera, ThinLens, load_gltf};
    use hush_tests::gltf_writer::{GltfWriter, Prim};
    let mut g = GltfWriter::default();
    let grey = g.lambert([0.5; 3]);
    let positions =
        [[-50.0, -50.0, 0.0], [50.0, -50.0, 0.0], [50.0, 50.0, 0.0], [-50.0, 50.0, 0.0]];
    let mesh = g.mesh(Prim {
        positions: &positions,
        normals: None,
        indices: Some(&[0, 1, 2, 0, 2, 3]),
        material: grey,
    });
    g.node(serde_json::json!({"mesh": mesh}));
    let scene = load_gltf(&g.write("lens_plane")).unwrap();
    let (z, f, r, fov) = (4.0f64, 2.0f64, 0.05f64, 40.0f64);
    let camera = Camera {
        lens: Some(ThinLens::new(r, f).unwrap()),
        ..Camera::look_at(glam::DVec3::new(0.0, 0.0, z), glam::DVec3::ZERO, fov as f32)
    };
    let size = 64u32;
    let (gpu, mut renderer) =
        Renderer::headless(scene, hush_engine::accel::BvhKind::DEFAULT, (size, size)).unwrap();
    let n = 64u32;
    let settings = hush_engine::settings::FrameSettings {
        primary_samples: n,
        prefilter: false,
        ..Default::default()
    };
    renderer
        .render(&gpu, &FrameInput { camera, time: 0.0, shutter: None }, &settings, None)
        .unwrap();
    let moments: Vec<f32> =
        bytemuck::cast_slice(&renderer.read_buffer(&gpu, "primaries/moments").unwrap()).to_vec();
    let pixels = (size * size) as usize;
    let mean =
        |k: usize| (0..pixels).map(|i| moments[i * 16 + k] as f64).sum::<f64>() / pixels as f64;
    let (xx, xy, yy, zz, hits) = (mean(4), mean(5), mean(7), mean(9), mean(3));
    let footprint = z * 2.0 * (fov.to_radians() / 2.0).tan() / size as f64;
    let radius = r * (1.0 - z / f).abs();
    // Every pixel samples the same n positions (realtime/lens.wgsl: the R2 sequence from the
    // frame's jitter, 0.5 without TAA): their own covariance, image y pointing down the world's.
    let offsets: Vec<(f64, f64)> = (0..n)
        .map(|j| ((0.5 + j as f64 * 0.7548776662).fract(), (0.5 + j as f64 * 0.5698402910).fract()))
        .collect();
    let m = offsets.iter().fold((0.0, 0.0), |a, o| (a.0 + o.0 / n as f64, a.1 + o.1 / n as f64));
    let cov = |f: &dyn Fn(&(f64, f64)) -> f64| {
        offsets.iter().map(f).sum::<f64>() / n as f64 * footprint * footprint
    };
    let jitter = [
        cov(&|o| (o.0 - m.0).powi(2)),
        -cov(&|o| (o.0 - m.0) * (o.1 - m.1)),
        cov(&|o| (o.1 - m.1).powi(2)),
    ];
    let lens = (n as f64 - 1.0) / n as f64 * radius * radius / 4.0;
    let expected = [lens + jitter[0], jitter[1], lens + jitter[2]];
    println!(
        "S xx {xx:.4e} xy {xy:.3e} yy {yy:.4e} (expected {:.4e} {:.3e} {:.4e}), zz {zz:.2e}, hits {hits}",
        expected[0], expected[1], expected[2]
    );
    assert_eq!(hits, n as f64);
    for (name, v, e) in [("xx", xx, expected[0]), ("xy", xy, expected[1]), ("yy", yy, expected[2])]
    {
        assert!((v - e).abs() < 0.02 * expected[0], "S {name} {v:.4e}, expected {e:.4e}");
    }
    assert!(zz.abs() < 1e-3 * expected[0], "S zz {zz:.3e}: the samples lie on the plane");
    // Click-to-focus reads the G-buffer's (mean) view depth: the plane's distance.
    let focus = renderer.view_depth_at(&gpu, (size / 2, size / 2)).unwrap().unwrap();
    assert!((focus - z).abs() < 1e-3 * z, "view depth {focus}, plane at {z}");
}

/// G-buffer error (Moon et al. fig. 5): on cornell_dof (the walls and the box out of focus, the
/// sphere in focus) the pre-filtered 4-sample G-buffer is closer to a 256-sample one than the raw
/// 4-sample G-buffer. The gain grows with the circle of confusion in pixels: measured at 128x128,
/// MSE of the normal 1.66x lower, base colour 1.73x, view depth 1.02x; at the scene's 256x256,
/// 2.46x, 2.90x and 1.50x. Asserted (128x128): normal and base colour at least 1.4x lower, depth
/// no more than 1.1x higher; on in-focus pixels (positions spread over less than a pixel) the
/// normal's MSE no higher than 1.1x raw (no loss of in-focus detail; measured 0.84x). Read from
/// the primaries' and the pre-filter's feature buffers (the G-buffer takes the filtered normal
/// and depth, and the raw material: gbuffer/resolve).
#[test]
fn prefiltered_gbuffer_is_closer_to_the_converged_one() {
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::scene::load_gltf;
    use hush_engine::settings::FrameSettings;
    let scene = load_gltf(&hush_tests::oracle("cornell_dof").join("cornell_dof.gltf")).unwrap();
    let size = (128u32, 128u32);
    let pixels = (size.0 * size.1) as usize;
    let camera = scene.camera_or_default();
    // Per pixel the features (primaries.wgsl's layout, as f32) and, with the pre-filter, its
    // features and the positions' spread in pixels.
    let run = |settings: &FrameSettings| {
        let (gpu, mut r) =
            Renderer::headless(scene.clone(), hush_engine::accel::BvhKind::DEFAULT, size).unwrap();
        r.render(&gpu, &FrameInput { camera, time: 0.0, shutter: None }, settings, None).unwrap();
        let floats = |b: Vec<u8>| -> Vec<f32> { bytemuck::cast_slice(&b).to_vec() };
        let raw = floats(r.read_buffer(&gpu, "primaries/features").unwrap());
        let filtered = r.read_buffer(&gpu, "prefilter/features").map(floats).unwrap_or_default();
        let spread: Vec<f32> = r
            .read_texture(&gpu, "prefilter/view")
            .map(|t| (0..pixels).map(|i| hush_tests::half(&t.0[i * 8 + 4..])).collect())
            .unwrap_or_default();
        (raw, filtered, spread)
    };
    let (reference, _, _) = run(&FrameSettings {
        primary_samples: 256,
        prefilter: false,
        seed: 9,
        ..Default::default()
    });
    let (raw, filtered, spread) =
        run(&FrameSettings { primary_samples: 4, prefilter: true, ..Default::default() });
    let surface = |f: &[f32], i: usize| f[i * 20 + 19].to_bits() != u32::MAX;
    let normal = |f: &[f32], i: usize| {
        glam::Vec3::new(f[i * 20], f[i * 20 + 1], f[i * 20 + 2]).normalize_or_zero()
    };
    // Normal, base colour (linear) and view depth (relative) squared errors, over the pixels
    // with a surface in both; `in_focus`: only where the positions spread over less than a pixel.
    let mse = |f: &[f32], in_focus: bool| {
        let (mut n, mut b, mut d, mut count) = (0.0, 0.0, 0.0, 0usize);
        for i in 0..pixels {
            if !surface(&raw, i) || !surface(&reference, i) || (in_focus && spread[i] >= 1.0) {
                continue;
            }
            n += (normal(f, i) - normal(&reference, i)).length_squared() as f64;
            b +=
                (4..7).map(|k| (f[i * 20 + k] - reference[i * 20 + k]).powi(2) as f64).sum::<f64>()
                    / 3.0;
            d += (f[i * 20 + 3] as f64 / reference[i * 20 + 3] as f64 - 1.0).powi(2);
            count += 1;
        }
        let c = count.max(1) as f64;
        (n / c, b / c, d / c, count)
    };
    let (rn, rb, rd, rc) = mse(&raw, false);
    let (fnm, fb, fd, _) = mse(&filtered, false);
    let (rn_focus, _, _, focus_count) = mse(&raw, true);
    let (fn_focus, _, _, _) = mse(&filtered, true);
    println!(
        "G-buffer MSE against 256 samples over {rc} pixels, raw 4 samples -> pre-filtered: normal {rn:.5} -> {fnm:.5} ({:.2}x), base colour {rb:.6} -> {fb:.6} ({:.2}x), relative depth {rd:.6} -> {fd:.6} ({:.2}x); in focus ({focus_count} pixels) normal {rn_focus:.6} -> {fn_focus:.6}",
        rn / fnm,
        rb / fb,
        rd / fd
    );
    assert!(fnm * 1.4 <= rn, "normal MSE {rn} -> {fnm}");
    assert!(fb * 1.4 <= rb, "base colour MSE {rb} -> {fb}");
    assert!(fd <= 1.1 * rd, "depth MSE {rd} -> {fd}");
    assert!(focus_count > 500, "only {focus_count} in-focus pixels");
    assert!(fn_focus <= 1.1 * rn_focus, "in-focus normal MSE {rn_focus} -> {fn_focus}");
}

/// A final filter driven by the features' uncertainty: with a thin lens the pre-filter passes on
/// each pixel's world-position spread (`prefilter/view` z, pixels at the surface), and the
/// glossy filters then reach at least the circle of confusion it measures, spread / sqrt(2) per
/// axis, at most MAX_GLOSSY_SIGMA_PX (realtime/uncertainty.wgsl): Mara's glossy bilateral
/// (glossy/bilateral.wgsl; its sigma in `glossy/scratch` alpha) and SVGF's glossy a-trous and
/// regression (svgf/features_glossy.wgsl; the reach in the fourth word of `svgf/glossy taps`).
/// Against a CPU computation from the read-back textures (cornell_dof at 128x128 with a 1 m
/// aperture, so that the back of the room is defocused past every roughness's own sigma; the
/// second frame of a still camera):
/// - every surface pixel's sigma is at least that reach;
/// - where the reach exceeds the largest sigma the roughness gives (GlossySettings::sigma_px
///   with no ray differential: 8 px at roughness 1), the sigma equals it;
/// - without the pre-filter no sigma exceeds the roughness's, nor, for Mara's bilateral, while
///   the camera moves (it takes the reach in a still view only).
///
/// Tolerance: Mara's sigma and the spread are stored as half floats (2^-11 relative), the sigma
/// after an f32 product.
#[test]
fn the_glossy_reach_takes_the_pre_filters_circle_of_confusion() {
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::scene::load_gltf;
    use hush_engine::settings::{Denoiser, FrameSettings, GlossySettings, MAX_GLOSSY_SIGMA_PX};
    let scene = load_gltf(&hush_tests::oracle("cornell_dof").join("cornell_dof.gltf")).unwrap();
    let size = (128u32, 128u32);
    let pixels = (size.0 * size.1) as usize;
    let mut camera = scene.camera_or_default();
    camera.lens.as_mut().expect("cornell_dof has a thin lens").aperture_radius = 1.0;
    let glossy = GlossySettings::default();
    // The largest sigma any roughness gives (no ray differential shrinks it).
    let roughness_sigma = |r: f32| glossy.sigma_px(r, 0.0);
    let mut moved = camera;
    moved.world.w_axis.x += 0.01;
    let run = |denoiser: Denoiser, prefilter: bool, last: hush_engine::scene::Camera| {
        let svgf = denoiser == Denoiser::SVGF;
        let settings =
            FrameSettings { denoiser, primary_samples: 4, prefilter, ..Default::default() };
        let (gpu, mut r) =
            Renderer::headless(scene.clone(), hush_engine::accel::BvhKind::DEFAULT, size).unwrap();
        // SVGF's taps are read after the frame.
        r.keep(&["svgf/glossy taps"]);
        for camera in [camera, last] {
            r.render(&gpu, &FrameInput { camera, time: 0.0, shutter: None }, &settings, None)
                .unwrap();
        }
        let halves = |label: &str, channel: usize| -> Vec<f32> {
            r.read_texture(&gpu, label)
                .map(|t| {
                    (0..pixels).map(|i| hush_tests::half(&t.0[i * 8 + channel * 2..])).collect()
                })
                .unwrap_or_default()
        };
        let sigma: Vec<f32> = if svgf {
            let taps = r.read_texture(&gpu, "svgf/glossy taps").unwrap().0;
            bytemuck::cast_slice::<u8, f32>(&taps).chunks(4).map(|t| t[3]).collect()
        } else {
            halves("glossy/scratch", 3)
        };
        let spread = halves("prefilter/view", 2);
        let roughness: Vec<f32> = r.read_texture(&gpu, "gbuffer/specular").unwrap().0[..pixels * 4]
            .chunks(4)
            .map(|t| t[3] as f32 / 255.0)
            .collect();
        // A pixel whose first lens sample missed has no surface (its other samples may hit).
        let surface: Vec<bool> = r.read_texture(&gpu, "gbuffer/ids").unwrap().0[..pixels * 8]
            .chunks(8)
            .map(|t| u32::from_le_bytes([t[0], t[1], t[2], t[3]]) != u32::MAX)
            .collect();
        (sigma, spread, roughness, surface)
    };
    let tolerance = 2.0 / 2048.0;
    for denoiser in [Denoiser::MARA, Denoiser::SVGF] {
        let (sigma, spread, roughness, surface) = run(denoiser.clone(), true, camera);
        let (mut checked, mut dominated, mut worst) = (0usize, 0usize, 0.0f32);
        for i in 0..pixels {
            if !surface[i] || spread[i] <= 0.0 {
                continue;
            }
            checked += 1;
            let reach = (spread[i] * std::f32::consts::FRAC_1_SQRT_2).min(MAX_GLOSSY_SIGMA_PX);
            assert!(
                sigma[i] >= reach * (1.0 - tolerance),
                "{denoiser:?}, pixel {i}: sigma {} below the circle of confusion's {reach}",
                sigma[i]
            );
            if reach > roughness_sigma(roughness[i]) * (1.0 + tolerance) {
                dominated += 1;
                worst = worst.max((sigma[i] / reach - 1.0).abs());
                assert!(
                    (sigma[i] - reach).abs() <= reach * tolerance,
                    "{denoiser:?}, pixel {i}: sigma {} where the circle of confusion gives {reach}",
                    sigma[i]
                );
            }
        }
        println!(
            "{denoiser:?}: {checked} surface pixels with a spread; {dominated} where the circle of confusion sets the glossy sigma (largest relative difference {worst:.5})"
        );
        assert!(
            dominated > 1000,
            "{denoiser:?}: only {dominated} pixels defocused past their roughness's sigma"
        );
        let (sigma, spread, roughness, surface) = run(denoiser.clone(), false, camera);
        assert!(spread.is_empty(), "the pre-filter's statistics exist without it");
        let mut within = vec![("without the pre-filter", sigma, roughness, surface)];
        if denoiser == Denoiser::MARA {
            let (sigma, _, roughness, surface) = run(denoiser.clone(), true, moved);
            within.push(("while the camera moves", sigma, roughness, surface));
        }
        for (case, sigma, roughness, surface) in within {
            for i in (0..pixels).filter(|&i| surface[i]) {
                assert!(
                    sigma[i] <= roughness_sigma(roughness[i]) * (1.0 + tolerance),
                    "{denoiser:?}, pixel {i}: sigma {} past the roughness's {} {case}",
                    sigma[i],
                    roughness_sigma(roughness[i])
                );
            }
        }
    }
}

/// With k traced primaries the G-buffer holds the mean of the k samples' materials and the
/// composite multiplies sample 0's light by it. Where the samples hit two materials (cornell_dof's
/// defocused metal box in front of the lit wall) the mean over frames of (sample 0's light) x
/// (mean material) is not the mean of the samples' radiance: the trace scales sample 0's light by
/// its own factor over the mean's (realtime/trace.wgsl: own_over_mean), so that the composite
/// gives sample 0's own radiance. Measured: no denoiser, TAA and the still-view mean off, the
/// composite of k = 4 averaged over 128 frames against the accumulate mode's 128 frames (one
/// primary per frame: exact) at 128x128, the signed relative difference of the two means per
/// 16x16 tile, averaged over the tiles below the top row: -0.03% (rms over the tiles 3.7%, the
/// two runs' noise); scaled by the mean material alone, as before, -2.01% (rms 5.8%; the box's
/// tiles 7-17% dark). The top row is left out: without TAA the frame does not jitter, so each
/// sample j sits at a fixed point of its pixel (the centre, then R2 steps from it) where the
/// accumulate mode box-filters, and the ceiling's tiles beside the in-focus edge of the light
/// differ by up to 20% for that alone. With about 3% of noise per tile the mean of 56 tiles has a
/// standard error near 0.5%: asserted within 1.2%.
#[test]
fn defocused_edges_keep_the_mean_of_their_samples() {
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::quality::luminance;
    use hush_engine::scene::load_gltf;
    use hush_engine::settings::{Denoiser, FrameSettings, disable_stage};
    let scene = load_gltf(&hush_tests::oracle("cornell_dof").join("cornell_dof.gltf")).unwrap();
    let (w, h) = (128usize, 128usize);
    let frames = 128;
    let mut settings = FrameSettings {
        denoiser: Denoiser::NONE,
        primary_samples: 4,
        max_depth: scene.max_depth,
        ..Default::default()
    };
    assert!(disable_stage(&mut settings, "taa") && disable_stage(&mut settings, "converge"));
    let size = (w as u32, h as u32);
    let (gpu, mut r) =
        Renderer::headless(scene.clone(), hush_engine::accel::BvhKind::DEFAULT, size).unwrap();
    let input = FrameInput { camera: scene.camera_or_default(), time: 0.0, shutter: None };
    let mut mean = vec![0.0f64; w * h];
    for _ in 0..frames {
        r.render(&gpu, &input, &settings, None).unwrap();
        let img = r.read_hdr(&gpu).unwrap();
        for (m, px) in mean.iter_mut().zip(img.data.iter()) {
            *m += luminance(*px) as f64 / frames as f64;
        }
    }
    let exact = hush_tests::realtime_accumulate(&scene, size.0, size.1, frames, 1).unwrap();
    let tile = 16;
    let mut diffs = vec![];
    for ty in 1..h / tile {
        for tx in 0..w / tile {
            let (mut a, mut b) = (0.0, 0.0);
            for y in ty * tile..(ty + 1) * tile {
                for x in tx * tile..(tx + 1) * tile {
                    a += mean[y * w + x];
                    b += luminance(exact.data[y * w + x]) as f64;
                }
            }
            diffs.push((a - b) / b.max(1e-9));
        }
    }
    let n = diffs.len() as f64;
    let bias = diffs.iter().sum::<f64>() / n;
    let rms = (diffs.iter().map(|d| d * d).sum::<f64>() / n).sqrt();
    println!("tiles' mean difference {:.2}%, rms {:.2}%", bias * 100.0, rms * 100.0);
    assert!(
        bias.abs() < 0.012,
        "k = 4 primaries' composite differs from the exact mean by {:.2}% over the tiles",
        bias * 100.0
    );
}
