//! Shader hot reload on a copy of `shaders/`: a changed shared module rebuilds exactly the
//! pipelines that use it; a broken module keeps the last good pipeline and reports file and
//! line; fixing it recovers.

use glam::DVec3;
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::scene::Camera;
use hush_engine::settings::{Denoiser, FrameSettings};
use hush_engine::shader::{ShaderLibrary, ShaderWatcher, source_tree_dir};
use std::collections::HashMap;
use std::path::Path;
use std::time::{Duration, Instant};

const SIZE: (u32, u32) = (48, 32);

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let dest = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_dir(&p, &dest);
        } else {
            std::fs::copy(&p, &dest).unwrap();
        }
    }
}

/// The glossy scene with the denoiser on, so every kind of pipeline exists (raster, trace,
/// composite, display, both chains).
fn renderer(shaders: &Path) -> (Gpu, Renderer) {
    let scene = hush_engine::scene::builtin_scene("reflections").unwrap();
    let prepared = PreparedScene::new(&scene, BvhKind::DEFAULT).unwrap();
    let mut gpu = Gpu::headless(&prepared.realtime_requirements(SIZE)).unwrap();
    gpu.shaders = ShaderLibrary::from_dir(shaders).unwrap();
    let r = Renderer::new(&gpu, scene, prepared, SIZE).unwrap();
    (gpu, r)
}

fn frame(gpu: &Gpu, r: &mut Renderer) -> image::RgbaImage {
    let s = FrameSettings { denoiser: Denoiser::MARA, ..Default::default() };
    let camera = Camera::look_at(DVec3::new(0.0, 1.5, 4.0), DVec3::new(0.0, 0.5, 0.0), 60.0);
    r.render(gpu, &FrameInput { camera, time: 0.0, shutter: None }, &s, None).unwrap();
    r.display_image(gpu, &s).unwrap()
}

fn builds(r: &mut Renderer) -> HashMap<String, u32> {
    r.pipelines().iter().map(|p| (p.label().to_string(), p.builds())).collect()
}

/// Wait for the watcher to report `module` (debounced; inotify answers in milliseconds, the
/// bound only guards against a lost event).
fn wait_for(w: &ShaderWatcher, lib: &ShaderLibrary, module: &str) -> Vec<&'static str> {
    let start = Instant::now();
    let mut seen = vec![];
    while start.elapsed() < Duration::from_secs(20) {
        seen.extend(w.changed(lib));
        if seen.contains(&module) {
            return seen;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    panic!("the watcher did not report {module} within 20 s (saw {seen:?})");
}

#[test]
fn reload_rebuilds_dependents_keeps_last_good_and_recovers() {
    let dir = hush_tests::gltf_writer::temp_dir("reload").join("shaders");
    let _ = std::fs::remove_dir_all(&dir);
    copy_dir(&source_tree_dir(), &dir);
    let (gpu, mut r) = renderer(&dir);
    let first = frame(&gpu, &mut r);
    let before = builds(&mut r);
    let watcher = ShaderWatcher::new(&gpu.shaders).unwrap();

    // 1. A shared module: the denoisers' colour-space and NaN helpers.
    let shared = "matte/common.wgsl";
    let users: Vec<String> = r
        .pipelines()
        .iter()
        .filter(|p| p.modules().contains(&shared))
        .map(|p| p.label().to_string())
        .collect();
    assert!(
        !users.is_empty() && users.len() < before.len(),
        "{shared} should feed some pipelines, not all: {users:?}"
    );
    let path = dir.join(shared);
    let good = std::fs::read_to_string(&path).unwrap();
    std::fs::write(
        &path,
        format!(
            "{good}\n// edited while running\nfn hot_reload_probe() -> f32 {{ return 1.0; }}\n"
        ),
    )
    .unwrap();
    let seen = wait_for(&watcher, &gpu.shaders, shared);
    let (changed, errors) = gpu.shaders.refresh(&seen);
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(changed, vec![shared]);
    let outcomes = r.reload_shaders(&gpu, &changed);
    let mut rebuilt: Vec<String> = outcomes.iter().map(|o| o.label.clone()).collect();
    rebuilt.sort();
    let mut expected = users.clone();
    expected.sort();
    assert_eq!(rebuilt, expected, "exactly the pipelines that use {shared} are rebuilt");
    assert!(outcomes.iter().all(|o| o.error.is_none()), "{outcomes:?}");
    let ms: Vec<String> = outcomes.iter().map(|o| format!("{} {:.1} ms", o.label, o.ms)).collect();
    println!("reloading {shared}: {}", ms.join(", "));
    let after = builds(&mut r);
    for (label, n) in &before {
        let want = if users.contains(label) { n + 1 } else { *n };
        assert_eq!(after[label], want, "{label}: built {} times, expected {want}", after[label]);
    }

    // The BSDF feeds the raster and the trace: the largest program, for the reload time.
    let bsdf = "common/bsdf.wgsl";
    let text = std::fs::read_to_string(dir.join(bsdf)).unwrap();
    std::fs::write(dir.join(bsdf), format!("{text}\n// edited\n")).unwrap();
    let (changed, _) = gpu.shaders.refresh(&[bsdf]);
    let outcomes = r.reload_shaders(&gpu, &changed);
    let ms: Vec<String> = outcomes.iter().map(|o| format!("{} {:.1} ms", o.label, o.ms)).collect();
    println!("reloading {bsdf}: {}", ms.join(", "));
    assert!(
        outcomes.iter().any(|o| o.label == "trace") && outcomes.iter().all(|o| o.error.is_none()),
        "{outcomes:?}"
    );
    // Where a reload's time goes, for the trace (the largest program): composing the text and
    // naga's validation against the driver's pipeline compile.
    let t = Instant::now();
    let program =
        r.pipelines().iter().find(|p| p.label() == "trace").unwrap().program(&gpu).unwrap();
    let compose_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    program.validate().unwrap();
    let validate_ms = t.elapsed().as_secs_f64() * 1e3;
    let total = outcomes.iter().find(|o| o.label == "trace").unwrap().ms;
    println!(
        "trace reload {total:.1} ms: compose {compose_ms:.3} ms, naga parse + validate {validate_ms:.1} ms, the rest in the driver"
    );
    let after = builds(&mut r);

    // 2. A syntax error: the composite keeps its last good pipeline; the error names the file
    // and the line.
    let composite = "realtime/composite.wgsl";
    let path = dir.join(composite);
    let good = std::fs::read_to_string(&path).unwrap();
    // `good` ends in a newline: one blank line, then `fn broken`, then the bad line.
    let broken_line = good.lines().count() + 3;
    std::fs::write(&path, format!("{good}\nfn broken() -> f32 {{\n    return 1.0 +;\n}}\n"))
        .unwrap();
    let (changed, _) = gpu.shaders.refresh(&[composite]);
    let outcomes = r.reload_shaders(&gpu, &changed);
    assert_eq!(outcomes.len(), 1, "{outcomes:?}");
    let e = outcomes[0].error.clone().expect("a broken shader must report an error");
    assert!(
        e.contains(&format!("{composite}:{broken_line}")),
        "the error names {composite} line {broken_line}: {e}"
    );
    assert_eq!(r.shader_errors().len(), 1);
    let kept = frame(&gpu, &mut r);
    assert_eq!(builds(&mut r)["composite"], after["composite"], "the last good pipeline stays");
    assert_eq!(kept.dimensions(), first.dimensions());
    assert!(
        kept.pixels().any(|p| p.0[..3] != [0, 0, 0]),
        "the frame still renders with the last good pipeline"
    );

    // 3. Valid WGSL that binds a resource its stage does not offer: naga accepts it, the
    // reload names the resource and keeps the last good pipeline.
    let header = "fn main(@builtin(global_invocation_id) gid: vec3u) {";
    assert!(good.contains(header));
    let unbound = format!(
        "{}\nvar<uniform> not_in_layout: vec4f;\n",
        good.replacen(header, &format!("{header}\n    if not_in_layout.x > 1e30 {{ return; }}"), 1)
    );
    hush_engine::shader::compose_with("probe", "", &["realtime/composite.wgsl"], |_| {
        Ok(unbound.clone().into())
    })
    .unwrap();
    std::fs::write(&path, &unbound).unwrap();
    let (changed, _) = gpu.shaders.refresh(&[composite]);
    let outcomes = r.reload_shaders(&gpu, &changed);
    let e = outcomes[0].error.clone().expect("a pipeline the layout rejects must report an error");
    assert!(
        e.contains("composite binds not_in_layout, which the stage does not offer"),
        "the reload names the resource: {e}"
    );
    println!("unoffered resource: {e}");
    assert_eq!(builds(&mut r)["composite"], after["composite"]);
    frame(&gpu, &mut r);

    // 4. Fixing the file clears the error and builds the pipeline again.
    std::fs::write(&path, &good).unwrap();
    let (changed, _) = gpu.shaders.refresh(&[composite]);
    let outcomes = r.reload_shaders(&gpu, &changed);
    assert!(outcomes.iter().all(|o| o.error.is_none()), "{outcomes:?}");
    assert!(r.shader_errors().is_empty());
    assert_eq!(builds(&mut r)["composite"], after["composite"] + 1);
    frame(&gpu, &mut r);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The viewer's pass times: copied into a ring and picked up frames later without waiting.
/// Every frame that found a free slot is delivered once, oldest first, with the passes the
/// blocking readback reports.
#[test]
fn pass_times_arrive_without_waiting() {
    let scene = hush_engine::scene::builtin_scene("reflections").unwrap();
    let (gpu, mut r) = Renderer::headless(scene, BvhKind::DEFAULT, SIZE).unwrap();
    if !gpu.timestamps {
        eprintln!("adapter has no timestamp queries; nothing to check");
        return;
    }
    r.set_async_timings(true);
    let s = FrameSettings { denoiser: Denoiser::MARA, ..Default::default() };
    let camera = r.scene.camera_or_default();
    let mut got = vec![];
    for k in 0..6 {
        r.render(&gpu, &FrameInput { camera, time: k as f64 / 60.0, shutter: None }, &s, None)
            .unwrap();
        got.extend(r.poll_pass_spans(&gpu));
    }
    let blocking: Vec<&str> = r.pass_spans(&gpu).unwrap().iter().map(|s| s.label).collect();
    gpu.wait().unwrap();
    while let Some(spans) = r.poll_pass_spans(&gpu) {
        got.push(spans);
    }
    // Three slots: at least the last three frames come back, more if the GPU kept up.
    assert!(got.len() >= 3 && got.len() <= 6, "{} frames of times", got.len());
    for spans in &got {
        let labels: Vec<&str> = spans.iter().map(|s| s.label).collect();
        assert_eq!(labels, blocking);
        assert!(spans.iter().all(|s| s.ms > 0.0 && s.start_ms >= 0.0), "{spans:?}");
    }
}
