//! Helpers shared by the GPU integration tests: paths to the oracle scenes (in the repository) and
//! to `../shared`, rendering a scene with the reference tracer, a small glTF writer for synthetic
//! scenes, eq. (11)'s reprojection distance on the CPU, and one shader function run on the GPU.

pub mod compute;
pub mod gltf_writer;
pub mod reproject;

use anyhow::Result;
use hush_engine::accel::BvhKind;
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::passes::{Accumulation, ReferenceTracer, TraceView};
use hush_engine::scene::Scene;
use std::path::PathBuf;

/// `../shared` beside the checkout (CI has it there; a bare clone does not). Tests that read its
/// real scenes carry `#[cfg_attr(not(hush_shared_scenes), ignore = ...)]` (see `build.rs`).
pub fn shared() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared")
}

/// An oracle scene's folder: its glTF, the Mitsuba reference and `render_info.json`, copied
/// from `../shared/oracle` into `tests/oracle` so that the parity tests run on a bare clone
/// (`oracle_copies_match_shared` keeps the copies honest).
pub fn oracle(scene: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("oracle").join(scene)
}

/// A scene of Hush's own with a Mitsuba reference (`tests/mitsuba`, written and rendered by
/// `tools/scripts/make_*_scene.py` under the oracle's conventions).
pub fn mitsuba_scene(scene: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("mitsuba").join(scene)
}

/// Render `scene` with the reference tracer: `spp` samples per pixel at `w` x `h`.
pub fn render(scene: &Scene, w: u32, h: u32, spp: u32, seed: u32) -> Result<Accumulation> {
    render_with(scene, w, h, spp, seed, BvhKind::DEFAULT)
}

pub fn render_with(
    scene: &Scene,
    w: u32,
    h: u32,
    spp: u32,
    seed: u32,
    kind: BvhKind,
) -> Result<Accumulation> {
    render_lod(scene, (w, h), spp, seed, kind, true)
}

/// [`render_with`], with ray cones choosing texture mip levels after the primary hit or not.
pub fn render_lod(
    scene: &Scene,
    (w, h): (u32, u32),
    spp: u32,
    seed: u32,
    kind: BvhKind,
    texture_lod: bool,
) -> Result<Accumulation> {
    let prepared = PreparedScene::new(scene, kind)?;
    trace(scene, &prepared, (w, h), spp, seed, texture_lod)
}

/// `spp` reference samples of `prepared` (as placed by its last `animate`) from `scene`'s camera.
fn trace(
    scene: &Scene,
    prepared: &PreparedScene,
    (w, h): (u32, u32),
    spp: u32,
    seed: u32,
    texture_lod: bool,
) -> Result<Accumulation> {
    let gpu = Gpu::headless(&prepared.requirements(w as u64 * h as u64, 32))?;
    let gscene = prepared.upload(&gpu);
    let view = TraceView {
        texture_lod,
        ..TraceView::new(scene.camera_or_default(), (w, h), scene.max_depth, seed)
    };
    let mut tracer = ReferenceTracer::new(&gpu, prepared, &gscene, &view)?;
    let mut done = 0;
    while done < spp {
        let n = (spp - done).min(16);
        tracer.dispatch(&gpu, n);
        gpu.wait()?;
        done += n;
    }
    tracer.readback(&gpu)
}

/// [`render`] with the scene's animation at `time` seconds (objects moved, meshes posed).
pub fn render_at(
    scene: &Scene,
    size: (u32, u32),
    spp: u32,
    seed: u32,
    time: f64,
) -> Result<Accumulation> {
    let mut prepared = PreparedScene::new(scene, BvhKind::DEFAULT)?;
    prepared.animate(scene, time);
    trace(scene, &prepared, size, spp, seed, true)
}

/// Render `frames` real-time frames of `scene` in accumulate mode (still camera) and return
/// their mean, linear HDR.
pub fn realtime_accumulate(
    scene: &Scene,
    w: u32,
    h: u32,
    frames: u32,
    seed: u32,
) -> Result<hush_engine::quality::Image> {
    let settings = hush_engine::settings::FrameSettings {
        max_depth: scene.max_depth,
        seed,
        accumulate: true,
        ..Default::default()
    };
    realtime_frames(scene, (w, h), &settings, frames)
}

/// Render `frames` real-time frames of `scene` from its camera with `settings` and return the
/// last one shown, linear HDR.
pub fn realtime_frames(
    scene: &Scene,
    size: (u32, u32),
    settings: &hush_engine::settings::FrameSettings,
    frames: u32,
) -> Result<hush_engine::quality::Image> {
    let (gpu, r) = realtime_renderer(scene, size, settings, frames)?;
    r.read_hdr(&gpu)
}

/// A real-time renderer of `scene` that has rendered `frames` frames from the scene's camera
/// with `settings`, for a test to read its textures.
pub fn realtime_renderer(
    scene: &Scene,
    size: (u32, u32),
    settings: &hush_engine::settings::FrameSettings,
    frames: u32,
) -> Result<(Gpu, hush_engine::frame::Renderer)> {
    use hush_engine::frame::{FrameInput, Renderer};
    let (gpu, mut r) = Renderer::headless(scene.clone(), BvhKind::DEFAULT, size)?;
    let input = FrameInput { camera: scene.camera_or_default(), time: 0.0, shutter: None };
    for _ in 0..frames {
        r.render(&gpu, &input, settings, None)?;
    }
    Ok((gpu, r))
}

/// The texture tests' 4 x 2 texels, each a different colour (8-bit RGB, top row first).
pub const TILE_COLOURS: [[u8; 3]; 8] = [
    [255, 0, 0],
    [0, 255, 0],
    [0, 0, 255],
    [255, 255, 0],
    [0, 255, 255],
    [255, 0, 255],
    [40, 40, 40],
    [200, 120, 60],
];

/// Per-channel relative mean bias of `test` against `reference` after leaving out the 0.1% of
/// pixels whose luminances differ most (caustic and highlight pixels whose means a few rare
/// samples dominate), and 5 standard errors of it: `variance(i, k)` is the variance of pixel
/// i's difference in channel k.
pub fn trimmed_bias(
    test: &hush_engine::quality::Image,
    reference: &hush_engine::quality::Image,
    variance: impl Fn(usize, usize) -> f64,
) -> ([f64; 3], [f64; 3]) {
    use hush_engine::quality::luminance;
    let n = reference.data.len();
    let mut diffs: Vec<(f32, usize)> = (0..n)
        .map(|i| ((luminance(test.data[i]) - luminance(reference.data[i])).abs(), i))
        .collect();
    diffs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let keep: Vec<usize> = diffs[..n - n / 1000 - 1].iter().map(|d| d.1).collect();
    let mut bias = [0f64; 3];
    let mut five_se = [0f64; 3];
    for k in 0..3 {
        let (mut sx, mut sy, mut var) = (0f64, 0f64, 0f64);
        for &i in &keep {
            sx += test.data[i][k] as f64;
            sy += reference.data[i][k] as f64;
            var += variance(i, k);
        }
        bias[k] = (sx - sy) / sy;
        five_se[k] = 5.0 * var.sqrt() / sy;
    }
    (bias, five_se)
}

/// A little-endian IEEE half (Rg16Float / Rgba16Float texels read back) as f32.
pub fn half(b: &[u8]) -> f32 {
    half::f16::from_le_bytes([b[0], b[1]]).to_f32()
}

/// The `i`th little-endian f32 of a texture's bytes.
pub fn f32_at(b: &[u8], i: usize) -> f32 {
    f32::from_le_bytes(b[i * 4..i * 4 + 4].try_into().unwrap())
}

/// Rgba16Float texels read back, as [r, g, b, a].
pub fn halves(bytes: &[u8]) -> Vec<[f32; 4]> {
    bytes
        .chunks_exact(8)
        .map(|t| [half(&t[0..2]), half(&t[2..4]), half(&t[4..6]), half(&t[6..8])])
        .collect()
}

/// A G-buffer normal texel (Rg16Float, octahedral) as a unit vector, as oct_decode in
/// shaders/realtime/frame.wgsl reads it.
pub fn oct_normal(texel: &[u8]) -> glam::Vec3 {
    oct_decode(half(texel), half(&texel[2..]))
}

/// An octahedral encoding (x, y) as a unit vector, as oct_decode in shaders/realtime/frame.wgsl.
pub fn oct_decode(x: f32, y: f32) -> glam::Vec3 {
    let mut n = glam::Vec3::new(x, y, 1.0 - x.abs() - y.abs());
    if n.z < 0.0 {
        n = glam::Vec3::new((1.0 - y.abs()) * x.signum(), (1.0 - x.abs()) * y.signum(), n.z);
    }
    n.normalize()
}

/// Schied et al.'s temporal error between two consecutive frames: the mean absolute change of
/// luminance per pixel.
pub fn luminance_change(a: &hush_engine::quality::Image, b: &hush_engine::quality::Image) -> f64 {
    use hush_engine::quality::luminance;
    a.data
        .iter()
        .zip(&b.data)
        .map(|(x, y)| (luminance(*x) - luminance(*y)).abs() as f64)
        .sum::<f64>()
        / a.data.len() as f64
}

/// A still view's convergence against Mitsuba (the small-size check): cornell_diffuse
/// at 128x128, its reference box-filtered from 256², the plain accumulation of 256 frames, and
/// the frame `settings` shows after 64 and after 256 frames of the same view.
pub struct StillConvergence {
    pub plain: hush_engine::quality::Metrics,
    pub at_64: hush_engine::quality::Metrics,
    pub at_256: hush_engine::quality::Metrics,
}

pub fn still_convergence(settings: &hush_engine::settings::FrameSettings) -> StillConvergence {
    use hush_engine::frame::{FrameInput, Renderer};
    use hush_engine::quality::{Image, compare};
    let dir = oracle("cornell_diffuse");
    let scene = hush_engine::scene::load_gltf(&dir.join("cornell_diffuse.gltf")).unwrap();
    let reference = Image::load(&dir.join("reference.exr")).unwrap().box_downsample(2).unwrap();
    let input = FrameInput { camera: scene.camera_or_default(), time: 0.0, shutter: None };
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, (128, 128)).unwrap();
    let mut run = |s: &hush_engine::settings::FrameSettings, n: u32| {
        for _ in 0..n {
            r.render(&gpu, &input, s, None).unwrap();
        }
        compare(&r.read_hdr(&gpu).unwrap(), &reference).unwrap()
    };
    let accumulate =
        hush_engine::settings::FrameSettings { accumulate: true, ..Default::default() };
    let plain = run(&accumulate, 256);
    let at_64 = run(settings, 64);
    let at_256 = run(settings, 192);
    StillConvergence { plain, at_64, at_256 }
}

impl StillConvergence {
    /// The targets: relMSE at 256 frames within 1.2x of the plain accumulation's (a filter whose
    /// blur bias did not fall with the history's variance stays near its 64-frame error while
    /// the accumulation's halves twice), the mean within 0.5% of the reference per channel, and
    /// FLIP at 256 frames below FLIP at 64 (the history keeps accumulating).
    pub fn check(&self, name: &str) {
        let (plain, at_64, at_256) = (&self.plain, &self.at_64, &self.at_256);
        println!(
            "relMSE plain {:.6} {name} {:.6} ({:.2}x); bias {:?} (plain {:?}); FLIP at 64 {:.4}, at 256 {:.4}",
            plain.relmse,
            at_256.relmse,
            at_256.relmse / plain.relmse,
            at_256.mean_rel_bias,
            plain.mean_rel_bias,
            at_64.flip,
            at_256.flip
        );
        assert!(
            at_256.relmse <= 1.2 * plain.relmse,
            "{name}: relMSE {} after 256 frames, plain accumulation {}",
            at_256.relmse,
            plain.relmse
        );
        for b in at_256.mean_rel_bias {
            assert!(b.abs() < 0.005, "{name}: mean bias {b} against the reference");
        }
        assert!(
            at_256.flip < at_64.flip,
            "{name}: FLIP {} at 256 frames, {} at 64",
            at_256.flip,
            at_64.flip
        );
    }
}

/// A small deterministic generator for test rays (xorshift32).
pub struct Xorshift(pub u32);

impl Xorshift {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }

    /// A uniform direction on the sphere.
    pub fn dir(&mut self) -> glam::Vec3 {
        let z = self.uniform() * 2.0 - 1.0;
        let phi = self.uniform() * std::f32::consts::TAU;
        let s = (1.0 - z * z).max(0.0).sqrt();
        glam::Vec3::new(s * phi.cos(), s * phi.sin(), z)
    }
}

/// Each slot's input triangle index (the second vertex's w) and its three vertices in `tris`
/// and in `ends` (the same slots at another time), sorted by input index: GPU and CPU slots
/// compared whatever order their trees put them in.
pub fn triangles_by_input(
    tris: &[glam::Vec4],
    ends: &[glam::Vec4],
) -> Vec<(u32, [glam::Vec3; 3], [glam::Vec3; 3])> {
    let p = |v: &[glam::Vec4]| [v[0], v[1], v[2]].map(|p| p.truncate());
    let mut m: Vec<_> = tris
        .chunks_exact(3)
        .zip(ends.chunks_exact(3))
        .map(|(v, o)| (v[1].w.to_bits(), p(v), p(o)))
        .collect();
    m.sort_by_key(|e| e.0);
    m
}
