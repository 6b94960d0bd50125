//! The real-time frame: converged accumulation against the reference mode, motion vectors,
//! feature-driven allocation, the default level.

use glam::{DVec3, Vec2, Vec4};
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer, View};
use hush_engine::quality::Image;
use hush_engine::scene::{Camera, load_gltf};
use hush_engine::settings::FrameSettings;
use hush_tests::reproject::{pixel_centre_hit, project};
use hush_tests::{half, oracle, realtime_accumulate, render, trimmed_bias};

/// Accumulated real-time frames converge to the reference tracer's image. The real-time frame
/// samples the same integral with a different structure (exhaustive punctual lights, separate
/// matte and glossy paths with their own MIS), so the two agree only in expectation: the test
/// measures both images' noise and allows relMSE up to `SLACK` times the noise prediction.
/// Real-time variance comes from two independent halves a, b: var(mean) = E[(a - b)^2] / 4.
/// The slack covers the noise of the variance estimate on heavy-tailed pixels (the 0.05-roughness
/// highlight of point_glossy); a bias of 1% over the image would add 1e-4 and stays visible in
/// the trimmed mean bias, bounded by 5 standard errors.
const SLACK: f64 = 2.0;

fn converges(name: &str, size: u32, frames: u32, spp: u32) {
    let scene = load_gltf(&oracle(name).join(format!("{name}.gltf"))).unwrap();
    let a = realtime_accumulate(&scene, size, size, frames / 2, 1).unwrap();
    let b = realtime_accumulate(&scene, size, size, frames / 2, 2).unwrap();
    let reference = render(&scene, size, size, spp, 3).unwrap();
    let n = a.data.len();
    let mut rt = Image::new(size, size);
    for i in 0..n {
        rt.data[i] = (a.data[i] + b.data[i]) * 0.5;
    }
    let (mut relmse, mut expected) = (0f64, 0f64);
    for i in 0..n {
        let y = reference.mean.data[i];
        for k in 0..3 {
            let d = (rt.data[i][k] - y[k]) as f64;
            let var_rt = ((a.data[i][k] - b.data[i][k]) as f64).powi(2) / 4.0;
            let w = 1.0 / (y[k] as f64 * y[k] as f64 + 0.01);
            relmse += d * d * w;
            expected += (var_rt + reference.variance_of_mean.data[i][k] as f64) * w;
        }
        assert!(rt.data[i].is_finite(), "{name}: non-finite pixel {i}");
    }
    relmse /= (3 * n) as f64;
    expected /= (3 * n) as f64;
    let (bias, allowed) = trimmed_bias(&rt, &reference.mean, |i, k| {
        ((a.data[i][k] - b.data[i][k]) as f64).powi(2) / 4.0
            + reference.variance_of_mean.data[i][k] as f64
    });
    println!(
        "{name}: {size}x{size}, {frames} real-time frames vs {spp} reference spp: relMSE {relmse:.5} (noise predicts {expected:.5}), \
         trimmed bias {:+.4} {:+.4} {:+.4} (allowed {:.4} {:.4} {:.4})",
        bias[0], bias[1], bias[2], allowed[0], allowed[1], allowed[2]
    );
    assert!(relmse <= SLACK * expected, "{name}: relMSE {relmse} > {SLACK} x predicted {expected}");
    for k in 0..3 {
        assert!(
            bias[k].abs() <= allowed[k],
            "{name}: channel {k} biased by {:+.4} (allowed {:.4})",
            bias[k],
            allowed[k]
        );
    }
}

#[test]
fn accumulation_converges_to_the_reference_mirror() {
    converges("cornell_mirror", 48, 256, 256);
}

#[test]
fn accumulation_converges_to_the_reference_glossy_point_light() {
    converges("point_glossy", 48, 256, 256);
}

/// The thin lens: the real-time frame traces its primaries through the lens (one per pixel per
/// frame in the accumulate mode) and continues from that hit.
#[test]
fn accumulation_converges_to_the_reference_thin_lens() {
    converges("cornell_dof", 48, 256, 256);
}

#[test]
fn accumulation_converges_to_the_reference_furnace() {
    converges("furnace", 32, 64, 64);
}

#[test]
fn a_diffuse_only_scene_allocates_no_glossy_buffers() {
    let scene = load_gltf(&oracle("cornell_diffuse").join("cornell_diffuse.gltf")).unwrap();
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, (32, 32)).unwrap();
    assert!(!r.prepared.features.glossy, "cornell_diffuse has only Lambertian materials");
    let labels: Vec<String> = r.allocations().into_iter().map(|(l, _)| l).collect();
    for forbidden in [
        "trace/glossy",
        "trace/reflection",
        "trace/mirror",
        "scene/object motion",
        "composite/accumulation",
    ] {
        assert!(!labels.iter().any(|l| l == forbidden), "{forbidden} allocated: {labels:?}");
    }
    // G-buffer 36 + matte 8 + direct 8 + HDR 16 bytes per pixel.
    assert_eq!(r.bytes_per_pixel(), 68.0, "{}", r.report());
    let input = FrameInput { camera: r.scene.camera_or_default(), time: 0.0, shutter: None };
    r.render(&gpu, &input, &FrameSettings::default(), None).unwrap();
    assert!(r.read_texture(&gpu, "trace/glossy").is_err());
    let img = r.read_hdr(&gpu).unwrap();
    assert!(
        img.data.iter().all(|p| p.is_finite()) && img.data.iter().any(|p| p.max_element() > 0.0)
    );
}

/// Motion vectors under camera and object motion, in the default level: for every pixel with a
/// surface, the G-buffer's motion must equal the motion computed on the CPU from the exact hit
/// point (ray through the pixel centre and the stored triangle), the object's motion and the two
/// cameras. The bound, 0.02 px + 2^-10 of the motion, is the Rg16Float storage precision (10-bit
/// mantissa) plus f32 projection rounding. Then the previous frame's object ids, fetched at
/// pixel + motion, must match the current ones where the previous frame's 2x2 footprint around
/// that point lies on one object (away from silhouettes): at least 98% of those pixels (the rest
/// are disocclusions; 99.1% match on lavapipe).
#[test]
fn motion_vectors_follow_camera_and_object_motion() {
    let scene = hush_engine::scene::default_level();
    let size = (96u32, 64u32);
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, size).unwrap();
    let settings = FrameSettings::default();
    // Look at the animated cube from near the plinth, then step and turn the camera a little.
    let cam0 = Camera::look_at(DVec3::new(1.8, 1.6, 3.2), DVec3::new(0.0, 1.4, 0.0), 50.0);
    let cam1 = Camera::look_at(DVec3::new(1.6, 1.65, 3.0), DVec3::new(0.05, 1.45, 0.0), 50.0);
    let (t0, t1) = (0.30, 0.35);
    r.render(&gpu, &FrameInput { camera: cam0, time: t0, shutter: None }, &settings, None).unwrap();
    let ids0 = r.read_texture(&gpu, "gbuffer/ids").unwrap().0;
    let setup0 = r.camera_setup(&cam0);
    r.render(&gpu, &FrameInput { camera: cam1, time: t1, shutter: None }, &settings, None).unwrap();
    let ids1 = r.read_texture(&gpu, "gbuffer/ids").unwrap().0;
    let motion = r.read_texture(&gpu, "gbuffer/motion").unwrap().0;
    let setup1 = r.camera_setup(&cam1);
    let cube = r.scene.objects.iter().position(|o| o.animation.is_some()).unwrap() as u32;

    let id_at = |ids: &[u8], x: usize, y: usize| -> (u32, u32) {
        let o = (y * size.0 as usize + x) * 8;
        (
            u32::from_le_bytes(ids[o..o + 4].try_into().unwrap()),
            u32::from_le_bytes(ids[o + 4..o + 8].try_into().unwrap()),
        )
    };
    let tris = &r.prepared.tris;
    let (mut worst, mut checked, mut on_cube, mut matched, mut comparable) = (0f32, 0, 0, 0, 0);
    for y in 0..size.1 as usize {
        for x in 0..size.0 as usize {
            let (obj, slot) = id_at(&ids1, x, y);
            if slot == u32::MAX {
                continue;
            }
            // The exact hit of the ray through the pixel centre on the stored triangle.
            let p = pixel_centre_hit(&setup1, size, (x, y), tris, slot);
            let prev = r.prepared.prev_from_current[obj as usize] * Vec4::from((p, 1.0));
            let expected = project(&setup0.view_proj, prev.truncate() / prev.w, size)
                - project(&setup1.view_proj, p, size);
            let o = (y * size.0 as usize + x) * 4;
            let got = Vec2::new(half(&motion[o..]), half(&motion[o + 2..]));
            let err = (got - expected).length();
            let bound = 0.02 + expected.length() / 1024.0;
            assert!(
                err <= bound,
                "pixel ({x}, {y}) object {obj}: motion {got} expected {expected} (error {err} > {bound})"
            );
            worst = worst.max(err);
            checked += 1;
            if obj == cube {
                on_cube += 1;
            }
            let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) + got;
            // The 2x2 texels around q (pixel centres at +0.5).
            let q = q - Vec2::splat(0.5);
            let (qx, qy) = (q.x.floor() as i64, q.y.floor() as i64);
            if qx >= 0 && qy >= 0 && qx + 1 < size.0 as i64 && qy + 1 < size.1 as i64 {
                let around: Vec<u32> = [(0, 0), (1, 0), (0, 1), (1, 1)]
                    .iter()
                    .map(|(dx, dy)| id_at(&ids0, (qx + dx) as usize, (qy + dy) as usize).0)
                    .collect();
                if around.iter().all(|&i| i == around[0]) {
                    comparable += 1;
                    matched += (around[0] == obj) as u32;
                }
            }
        }
    }
    let rate = matched as f64 / comparable as f64;
    println!(
        "motion vectors: {checked} pixels ({on_cube} on the moving cube), worst error {worst:.4} px; previous ids match at {:.2}% of {comparable}",
        rate * 100.0
    );
    assert!(on_cube > 100, "the moving cube covers only {on_cube} pixels");
    assert!(rate >= 0.98, "reprojected object ids match at only {:.2}%", rate * 100.0);
}

/// The default level: with each denoiser every debug view renders, nothing is NaN, the glossy
/// buffers exist.
#[test]
fn the_default_level_renders_without_nan() {
    let start = std::time::Instant::now();
    let scene = hush_engine::scene::default_level();
    let prepared = hush_engine::gpu::PreparedScene::new(&scene, BvhKind::DEFAULT).unwrap();
    let load = start.elapsed();
    println!(
        "default level: {} triangles, built and prepared in {:.1} ms",
        prepared.triangle_count(),
        load.as_secs_f64() * 1e3
    );
    // What animation costs on the CPU per frame: re-flatten the cube, rebuild the BVH.
    let mut p2 = hush_engine::gpu::PreparedScene::new(&scene, BvhKind::DEFAULT).unwrap();
    let t = std::time::Instant::now();
    for k in 1..=10 {
        assert!(p2.animate(&scene, k as f64 / 60.0));
    }
    println!(
        "animation: BVH rebuild and re-flatten {:.2} ms per frame",
        t.elapsed().as_secs_f64() * 100.0
    );
    let gpu = hush_engine::gpu::Gpu::headless(&prepared.realtime_requirements((80, 45))).unwrap();
    let mut r = Renderer::new(&gpu, scene, prepared, (80, 45)).unwrap();
    assert!(
        r.prepared.features.glossy && r.prepared.features.animated && r.prepared.features.textures
    );
    // The views below are drawn after the frames: SVGF's and the progressive filter's
    // intermediates must outlive them (a frame keeps the texture of the view it renders with,
    // and no other), and the trace must write its reflection data, which it writes only while
    // something reads it.
    r.keep(&["svgf/", "progressive/", "trace/"]);
    // Each built-in denoiser in turn: the frame's views and its own.
    for entry in hush_engine::denoise::entries().iter().filter(|e| e.make.is_some()) {
        let mut denoised = FrameSettings {
            denoiser: hush_engine::settings::Denoiser::named(entry.info.name),
            ..Default::default()
        };
        // Off by default; on here so that the glossy/clipping view has something to show.
        denoised.glossy.clipping = true;
        for k in 0..3 {
            let input = FrameInput {
                camera: r.scene.camera_or_default(),
                time: 1.0 + k as f64 / 60.0,
                shutter: None,
            };
            r.render(&gpu, &input, &denoised, None).unwrap();
            let img = r.read_hdr(&gpu).unwrap();
            assert!(
                img.data.iter().all(|p| p.is_finite()),
                "NaN or Inf in the default level with {}",
                entry.info.name
            );
        }
        // Emission may be off screen, and SVGF's spike cut waits for 4 frames' samples, its
        // spread for the regression's 16 (tests/svgf_spikes.rs reads both); every other view
        // shows something from the level's camera (the radiance cache's after a jump:
        // tests/radiance_cache.rs; the upscaler's where it runs: tests/upscale.rs).
        let own = hush_engine::settings::FRAME_VIEWS
            .iter()
            .filter(|v| !v.needs_traced_primaries() && !v.needs_cache() && !v.needs_upscaler())
            .chain(entry.info.views);
        let views: Vec<View> =
            std::iter::once(View::FINAL).chain(own.map(|v| View::named(v.name))).collect();
        let blank = [
            "gbuffer/emission",
            "svgf/matte spikes",
            "svgf/glossy spikes",
            "svgf/matte spread",
            "svgf/glossy spread",
        ];
        for v in views.into_iter().filter(|v| !blank.contains(&v.name())) {
            let settings = FrameSettings { view: v.clone(), ..denoised.clone() };
            let shown = r.display_image(&gpu, &settings).unwrap();
            assert!(
                shown.pixels().any(|p| p.0[..3] != [0, 0, 0]),
                "view {} is black with {}",
                v.name(),
                entry.info.name
            );
        }
    }
    // Through a thin lens: the traced primaries and the pre-filter, and their views.
    let lens = hush_engine::scene::ThinLens::new(0.2, 1.0).unwrap();
    let camera = Camera { lens: Some(lens), ..r.scene.camera_or_default() };
    let settings =
        FrameSettings { denoiser: hush_engine::settings::Denoiser::MARA, ..Default::default() };
    for k in 0..2 {
        r.render(
            &gpu,
            &FrameInput { camera, time: 1.0 + k as f64 / 60.0, shutter: None },
            &settings,
            None,
        )
        .unwrap();
        assert!(
            r.read_hdr(&gpu).unwrap().data.iter().all(|p| p.is_finite()),
            "NaN or Inf through a thin lens"
        );
    }
    for v in hush_engine::settings::FRAME_VIEWS.iter().filter(|v| v.needs_traced_primaries()) {
        let shown = r
            .display_image(&gpu, &FrameSettings { view: View::named(v.name), ..settings.clone() })
            .unwrap();
        assert!(
            shown.pixels().any(|p| p.0[..3] != [0, 0, 0]),
            "view {} is black through a thin lens",
            v.name
        );
    }
}

/// The level written as glTF loads back with the same content and renders without NaN.
#[test]
fn the_default_level_gltf_loads_and_renders_without_nan() {
    let built = hush_engine::scene::default_level();
    let dir = hush_tests::gltf_writer::temp_dir("level_gltf");
    let path = dir.join("level.gltf");
    hush_engine::scene::save_gltf(&built, &path).unwrap();
    let start = std::time::Instant::now();
    let scene = load_gltf(&path).unwrap();
    println!("level.gltf loaded in {:.1} ms", start.elapsed().as_secs_f64() * 1e3);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.triangle_count(), built.triangle_count());
    assert_eq!(scene.objects.len(), built.objects.len());
    assert_eq!(scene.lights.len(), 1);
    assert!(
        scene.procedural_sky
            && matches!(scene.environment, hush_engine::scene::Environment::Map(_))
    );
    // The animated cube follows the same motion after the round trip.
    let a = built.objects.iter().find(|o| o.animation.is_some()).unwrap();
    let b = scene
        .objects
        .iter()
        .find(|o| o.animation.is_some())
        .expect("the animation survives export");
    for t in [0.0, 0.7, 2.5, 5.1] {
        let d = a
            .transform_at(t)
            .to_cols_array()
            .iter()
            .zip(b.transform_at(t).to_cols_array())
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(d < 1e-5, "transform at t = {t} differs by {d}");
    }
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, (64, 36)).unwrap();
    for k in 0..3 {
        let input =
            FrameInput { camera: r.scene.camera_or_default(), time: k as f64 * 0.5, shutter: None };
        r.render(&gpu, &input, &FrameSettings::default(), None).unwrap();
        let img = r.read_hdr(&gpu).unwrap();
        assert!(img.data.iter().all(|p| p.is_finite()), "NaN or Inf in frame {k}");
        assert!(img.data.iter().map(|p| p.max_element()).sum::<f32>() > 0.0);
    }
}

/// The copy of the level committed under assets/ (written by `hush-cli level`) is current.
#[test]
fn the_committed_level_matches_the_generator() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/level/level.gltf");
    let committed = load_gltf(&path).unwrap();
    let built = hush_engine::scene::default_level();
    assert_eq!(
        committed.triangle_count(),
        built.triangle_count(),
        "run `hush-cli level` to refresh assets/level"
    );
    assert_eq!(
        committed.objects.len(),
        built.objects.len(),
        "run `hush-cli level` to refresh assets/level"
    );
    assert_eq!(
        committed.materials.len(),
        built.materials.len() + 1,
        "the importer appends its default material"
    );
}

/// Why punctual lights bypass the filters: evaluated exhaustively at the primary hit, their
/// direct light is the same in every frame (no random choice, no random point on the light),
/// while the sampled matte light changes from frame to frame. Two frames from the same camera:
/// `trace/direct` must be bitwise equal, `trace/matte` not.
#[test]
fn punctual_direct_light_carries_no_noise() {
    let scene = hush_engine::scene::default_level();
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, (64, 36)).unwrap();
    let input = FrameInput { camera: r.scene.camera_or_default(), time: 0.0, shutter: None };
    let s = FrameSettings::default();
    let mut direct = vec![];
    let mut matte = vec![];
    for _ in 0..2 {
        r.render(&gpu, &input, &s, None).unwrap();
        direct.push(r.read_texture(&gpu, "trace/direct").unwrap().0);
        matte.push(r.read_texture(&gpu, "trace/matte").unwrap().0);
    }
    assert!(direct[0].iter().any(|b| *b != 0), "the sun lights part of the view");
    assert_eq!(direct[0], direct[1], "punctual direct light differs between frames");
    assert_ne!(matte[0], matte[1], "the matte light should be a new sample each frame");
    let lum =
        |b: &[u8], i: usize| (0..3).map(|k| half(&b[i * 8 + k * 2..])).sum::<f32>() as f64 / 3.0;
    let n = matte[0].len() / 8;
    let rel = (0..n)
        .map(|i| {
            (lum(&matte[0], i) - lum(&matte[1], i)).powi(2) / (lum(&matte[1], i).powi(2) + 0.01)
        })
        .sum::<f64>()
        / n as f64;
    println!("frame-to-frame relMSE: trace/direct 0 (bitwise equal), trace/matte {rel:.3}");
}

/// A lost device is an error a caller can tell from the others (`hush_engine::Error::DeviceLost`),
/// not a panic or a frame that silently does nothing. wgpu reports the loss of a destroyed device
/// once its queue is idle (a poll), as after a driver reset.
#[test]
fn a_lost_device_is_a_device_lost_error() {
    use hush_engine::Error;
    let scene = hush_engine::scene::default_level();
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, (16, 16)).unwrap();
    let camera = Camera::look_at(DVec3::new(0.0, 1.7, 8.5), DVec3::new(0.0, 1.4, -6.0), 60.0);
    let input = FrameInput { camera, time: 0.0, shutter: None };
    r.render(&gpu, &input, &FrameSettings::default(), None).unwrap();
    gpu.device.destroy();
    let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
    let e = r.render(&gpu, &input, &FrameSettings::default(), None).unwrap_err();
    assert!(matches!(Error::find(&e), Some(Error::DeviceLost { .. })), "{e:#}");
    let e = gpu.wait().unwrap_err();
    assert!(matches!(Error::find(&e), Some(Error::DeviceLost { .. })), "{e:#}");
}
