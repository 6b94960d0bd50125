//! Motion blur (a shutter open over an interval: FrameInput::shutter, PreparedScene::expose)
//! in the default level, whose cube spins and rises: the reference tracer's blurred image equals
//! the mean of still images over the shutter, and the real-time frame's accumulation converges
//! to it.

use glam::DVec3;
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer, ShutterOpen};
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::passes::reference::{Accumulation, ReferenceTracer, TraceView};
use hush_engine::quality::Image;
use hush_engine::scene::{Camera, Scene};
use hush_engine::settings::FrameSettings;
use hush_tests::trimmed_bias;

const SIZE: (u32, u32) = (64, 40);
/// The shutter: open at 0.25 s, closed at 0.5 s (the cube turns 22.5 degrees and rises 5 cm),
/// while the camera slides 10 cm to its right.
const OPEN: f64 = 0.25;
const CLOSE: f64 = 0.5;
const SLICES: u32 = 64;
/// Direct light only (as Mitsuba counts path length): the sun's and sky's light on the cube and
/// its shadow carry the motion with little noise.
const MAX_DEPTH: i32 = 2;

fn camera_at(s: f64) -> Camera {
    let slide = DVec3::new(0.1 * (1.0 - s), 0.0, 0.0);
    Camera::look_at(DVec3::new(1.8, 1.6, 3.2) - slide, DVec3::new(0.0, 1.4, 0.0) - slide, 50.0)
}

fn view(camera: Camera, shutter_camera: Option<Camera>, seed: u32) -> TraceView {
    TraceView {
        camera,
        width: SIZE.0,
        height: SIZE.1,
        max_depth: MAX_DEPTH,
        seed,
        shutter_camera,
        texture_lod: true,
    }
}

/// The reference tracer over the whole shutter, `spp` samples per pixel.
fn blurred(scene: &Scene, spp: u32) -> Accumulation {
    let mut prepared = PreparedScene::new(scene, BvhKind::DEFAULT).unwrap();
    prepared.expose(scene, CLOSE, Some(OPEN));
    assert!(prepared.shutter_moves(), "the level's cube moves during the shutter");
    let gpu = Gpu::headless(&prepared.requirements((SIZE.0 * SIZE.1) as u64, 32)).unwrap();
    let gscene = prepared.upload(&gpu);
    let mut t = ReferenceTracer::new(
        &gpu,
        &prepared,
        &gscene,
        &view(camera_at(1.0), Some(camera_at(0.0)), 1),
    )
    .unwrap();
    t.dispatch(&gpu, spp);
    t.readback(&gpu).unwrap()
}

/// The mean of `SLICES` still images at the middles of equal slices of the shutter, `spp` /
/// `SLICES` samples each (one tracer accumulating over them); and the still at the close alone.
fn stills(scene: &Scene, spp: u32) -> (Accumulation, Accumulation) {
    let mut prepared = PreparedScene::new(scene, BvhKind::DEFAULT).unwrap();
    let gpu = Gpu::headless(&prepared.requirements((SIZE.0 * SIZE.1) as u64, 32)).unwrap();
    let mut gscene = prepared.upload(&gpu);
    let mut tracer: Option<ReferenceTracer> = None;
    for i in 0..SLICES {
        let s = (i as f64 + 0.5) / SLICES as f64;
        let moved = prepared.animate(scene, OPEN + s * (CLOSE - OPEN));
        let generation = gscene.generation;
        gscene.update_geometry(&gpu, &prepared, moved);
        let v = view(camera_at(s), None, 2);
        match tracer.as_mut() {
            Some(t) if gscene.generation == generation => t.set_view(&prepared, &v),
            _ => {
                // A rebuilt tree outgrew a buffer: the samples so far move to a new tracer's
                // sum through its accumulation buffer.
                let old = tracer.take();
                let mut t = ReferenceTracer::new(&gpu, &prepared, &gscene, &v).unwrap();
                if let Some(old) = old {
                    let mut enc = gpu.device.create_command_encoder(&Default::default());
                    enc.copy_buffer_to_buffer(
                        old.accumulation_buffer(),
                        0,
                        t.accumulation_buffer(),
                        0,
                        old.accumulation_buffer().size(),
                    );
                    gpu.queue.submit([enc.finish()]);
                    t.samples = old.samples;
                }
                tracer = Some(t);
            }
        }
        tracer.as_mut().unwrap().dispatch(&gpu, spp / SLICES);
        gpu.wait().unwrap();
    }
    let mean = tracer.unwrap().readback(&gpu).unwrap();
    prepared.animate(scene, CLOSE);
    let gscene = prepared.upload(&gpu);
    let mut t =
        ReferenceTracer::new(&gpu, &prepared, &gscene, &view(camera_at(1.0), None, 3)).unwrap();
    t.dispatch(&gpu, spp);
    (mean, t.readback(&gpu).unwrap())
}

/// relMSE of `a` against `b` (weights 1 / (b^2 + 0.01), as the oracle tests) and what the two
/// images' noise predicts for it.
fn relmse(a: &Image, var_a: &dyn Fn(usize, usize) -> f64, b: &Accumulation) -> (f64, f64) {
    let (mut e, mut predicted) = (0.0, 0.0);
    for i in 0..a.data.len() {
        for k in 0..3 {
            let y = b.mean.data[i][k] as f64;
            let w = 1.0 / (y * y + 0.01);
            e += (a.data[i][k] as f64 - y).powi(2) * w;
            predicted += (var_a(i, k) + b.variance_of_mean.data[i][k] as f64) * w;
        }
    }
    let n = (a.data.len() * 3) as f64;
    (e / n, predicted / n)
}

/// The blurred image and the mean of 64 stills agree within their noise (relMSE at most 2x what
/// the noise predicts, the trimmed mean bias within 5 standard errors; the stills' variance is
/// taken over all their samples, which overstates the noise of a stratified mean, so the bound
/// is conservative), while the still at the close differs by far more than the noise (the test
/// sees the motion: at least 10x the prediction).
#[test]
fn reference_motion_blur_is_the_mean_of_stills_over_the_shutter() {
    let scene = hush_engine::scene::default_level();
    let spp = 512;
    let blur = blurred(&scene, spp);
    let (mean, still) = stills(&scene, spp);
    if let Ok(dir) = std::env::var("HUSH_TEST_IMAGES") {
        blur.mean.save(&std::path::Path::new(&dir).join("blurred.exr")).unwrap();
        mean.mean.save(&std::path::Path::new(&dir).join("stills.exr")).unwrap();
        still.mean.save(&std::path::Path::new(&dir).join("still.exr")).unwrap();
    }
    let var = |i: usize, k: usize| blur.variance_of_mean.data[i][k] as f64;
    let (e, predicted) = relmse(&blur.mean, &var, &mean);
    let (e_still, predicted_still) = relmse(&blur.mean, &var, &still);
    let (bias, allowed) = trimmed_bias(&blur.mean, &mean.mean, |i, k| {
        var(i, k) + mean.variance_of_mean.data[i][k] as f64
    });
    println!(
        "blurred vs mean of {SLICES} stills: relMSE {e:.5} (noise predicts {predicted:.5}), bias {bias:?} (allowed {allowed:?}); vs the still at the close: {e_still:.5} (noise {predicted_still:.5})"
    );
    assert!(e <= 2.0 * predicted, "relMSE {e} > 2 x {predicted}");
    for k in 0..3 {
        assert!(
            bias[k].abs() <= allowed[k],
            "channel {k} biased by {:+.4} (allowed {:.4})",
            bias[k],
            allowed[k]
        );
    }
    assert!(
        e_still >= 10.0 * predicted_still,
        "the blurred image is as close to the still at the close ({e_still}) as noise ({predicted_still}): nothing moved"
    );
    assert_eq!(blur.nonfinite_samples, 0);
}

/// Real-time accumulation under the same shutter (one traced primary per pixel per frame, at
/// its own time; the path continues from it) converges to the reference's blurred image, within
/// 2x the noise the two images predict (the real-time variance from two independent halves).
#[test]
fn realtime_accumulation_converges_to_the_reference_motion_blur() {
    let scene = hush_engine::scene::default_level();
    let reference = blurred(&scene, 512);
    let input = FrameInput {
        camera: camera_at(1.0),
        time: CLOSE,
        shutter: Some(ShutterOpen { camera: camera_at(0.0), time: OPEN }),
    };
    let half = |seed: u32| {
        let (gpu, mut r) = Renderer::headless(scene.clone(), BvhKind::DEFAULT, SIZE).unwrap();
        let settings =
            FrameSettings { max_depth: MAX_DEPTH, seed, accumulate: true, ..Default::default() };
        for _ in 0..128 {
            r.render(&gpu, &input, &settings, None).unwrap();
        }
        r.read_hdr(&gpu).unwrap()
    };
    let (a, b) = (half(5), half(6));
    let mut rt = Image::new(SIZE.0, SIZE.1);
    for i in 0..rt.data.len() {
        rt.data[i] = (a.data[i] + b.data[i]) * 0.5;
        assert!(rt.data[i].is_finite(), "pixel {i}");
    }
    let var = |i: usize, k: usize| ((a.data[i][k] - b.data[i][k]) as f64).powi(2) / 4.0;
    let (e, predicted) = relmse(&rt, &var, &reference);
    let (bias, allowed) = trimmed_bias(&rt, &reference.mean, |i, k| {
        var(i, k) + reference.variance_of_mean.data[i][k] as f64
    });
    println!(
        "real-time accumulation (256 frames) vs reference (512 spp), motion blur: relMSE {e:.5} (noise predicts {predicted:.5}), bias {bias:?} (allowed {allowed:?})"
    );
    assert!(e <= 2.0 * predicted, "relMSE {e} > 2 x {predicted}");
    for k in 0..3 {
        assert!(
            bias[k].abs() <= allowed[k],
            "channel {k} biased by {:+.4} (allowed {:.4})",
            bias[k],
            allowed[k]
        );
    }
}
