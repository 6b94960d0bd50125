//! `hush-cli render --mode realtime`: the hybrid frame, headless and deterministic.

use crate::cli::{
    bvh_kind, check_output, check_output_dir, check_sides, image_size, load_scene, parse_camera,
    path_length, preset_settings,
};
use crate::render::RenderArgs;
use anyhow::{Context, Result, bail};
use hush_engine::frame::{FrameInput, Renderer, View};
use hush_engine::scene::CameraPath;
use hush_engine::settings::{FrameSettings, SampleFraction};

/// Frame `k`'s input: the camera path's key k (its time; the shutter a fraction of the interval
/// since the key before, or of 1 / fps where keys share a time, the camera at the open
/// interpolated along the path), or the still `camera` at `time` (the interval 1 / fps).
fn frame_input(
    path: Option<&CameraPath>,
    camera: hush_engine::scene::Camera,
    k: u32,
    time: f64,
    shutter: f64,
    fps: f64,
) -> FrameInput {
    match path {
        Some(p) => {
            let key = p.frame(k as usize);
            let spacing = if k > 0 && (k as usize) < p.keys.len() {
                key.time - p.frame(k as usize - 1).time
            } else {
                0.0
            };
            let dt = if spacing > 0.0 { spacing } else { 1.0 / fps };
            FrameInput::exposed(|t| p.camera_at(t), key.time, shutter, dt)
        }
        None => FrameInput::exposed(|_| camera, time, shutter, 1.0 / fps),
    }
}

pub fn run(a: RenderArgs) -> Result<()> {
    // Without --denoiser or a preset, the denoiser that measures best in a still view
    // (docs/decisions.md, "Default denoiser").
    let default = hush_engine::settings::Denoiser::SVGF;
    let denoiser = match (&a.denoiser, &a.preset) {
        (None, None) => Some(default.name()),
        (d, _) => d.as_deref(),
    };
    let chains =
        preset_settings(a.preset.as_deref(), denoiser, &a.disable, a.reflection_mv.as_deref())?;
    let frames = a.frames.unwrap_or(1);
    if frames == 0 {
        bail!("--frames must be at least 1");
    }
    let max_spp = hush_engine::settings::MAX_SAMPLES_PER_PIXEL;
    if let Some(crate::cli::Spp::Samples(spp)) = a.spp
        && spp > max_spp
    {
        bail!(
            "--spp {spp}: real-time mode takes at most {max_spp} samples per pixel per frame; use --frames (or --accumulate) for more"
        );
    }
    let fps = crate::render::fps(&a)?;
    let shutter = crate::render::shutter(&a)?;
    if a.time.is_some() {
        bail!(
            "--time applies to reference mode; real-time mode's frames run at --fps (or the camera path's times)"
        );
    }
    match (&a.out, &a.view) {
        (None, None) if a.out_dir.is_none() => {
            bail!("real-time mode needs --out FILE (last frame) or --out-dir DIR (every frame)")
        }
        (None, Some(_)) => bail!("--view needs --out FILE.png"),
        (Some(out), Some(_)) => check_output(out, &["png"], "--out (what --view shows)")?,
        (Some(out), None) => check_output(out, &["exr", "png"], "--out")?,
        (None, None) => {}
    }
    let view = a
        .view
        .as_deref()
        .map(|name| {
            let v = View::named(name);
            if !v.is_final() && v.spec().is_none() {
                let names: Vec<&str> = std::iter::once(View::FINAL.name())
                    .chain(hush_engine::settings::all_views().iter().map(|v| v.name))
                    .collect();
                bail!("--view {name:?}: use one of {}", names.join(", "));
            }
            Ok(v)
        })
        .transpose()?;
    if let Some(dir) = &a.out_dir {
        check_output_dir(dir, "--out-dir")?;
    }
    check_sides(a.width, a.height, hush_engine::frame::MAX_SIDE, "real-time mode")?;
    if a.accumulate && a.camera_path.is_some() {
        bail!("--accumulate needs a still camera; it cannot be combined with --camera-path");
    }
    let path = a.camera_path.as_deref().map(CameraPath::load).transpose()?;
    let camera = a.camera.as_deref().map(parse_camera).transpose()?;
    let scene = load_scene(&a.scene, &a.load)?;
    let shown = image_size(&scene, a.width, a.height);
    let size = match a.scale {
        None => shown,
        Some(s) if (0.1..=1.0).contains(&s) => scaled(shown, s),
        Some(s) => bail!("--scale {s}: use 0.1 to 1"),
    };
    if a.scale.is_some() && a.target_ms.is_some() {
        bail!("--scale pins the resolution scale that --target-ms lets the governor choose");
    }
    let camera = camera.unwrap_or_else(|| scene.camera_or_default());
    if let Some(v) = &view
        && v.spec().is_some_and(|s| s.needs_glossy())
        && !hush_engine::gpu::PreparedScene::glossy_materials(&scene)
    {
        bail!("--view {}: the scene has no glossy buffers", v.name());
    }
    let max_depth = path_length(a.max_depth, a.preset.as_deref(), scene.max_depth)?;
    let (samples_per_pixel, sample_fraction) = match a.spp {
        None => (chains.samples_per_pixel, chains.sample_fraction),
        Some(crate::cli::Spp::Samples(n)) => (n, SampleFraction::ONE),
        Some(crate::cli::Spp::Fraction(f)) => (1, f),
    };
    let max_primary = hush_engine::settings::MAX_PRIMARY_SAMPLES;
    let primary_samples = a.primary_samples.unwrap_or(chains.primary_samples);
    if !(1..=max_primary).contains(&primary_samples) {
        bail!("--primary-samples {primary_samples}: use 1 to {max_primary}");
    }
    let prefilter = chains.prefilter && !a.no_prefilter;
    let settings = FrameSettings {
        max_depth,
        seed: a.seed,
        accumulate: a.accumulate || chains.accumulate,
        samples_per_pixel,
        sample_fraction,
        primary_samples,
        prefilter,
        ..chains
    };
    let name = scene.name.clone();
    let start = std::time::Instant::now();
    let (gpu, mut r) = Renderer::headless(scene, bvh_kind(&a.bvh)?, size)?;
    // The frames keep what --view shows readable after them (a denoiser's intermediate shares
    // its memory with later textures otherwise).
    if let Some(spec) = view.as_ref().and_then(|v| v.spec()) {
        r.keep(&[spec.texture]);
    }
    if a.cpu_posing {
        r.set_gpu_posing(&gpu, false)?;
    }
    r.show_at(Some(shown))?;
    if let Some(dir) = &a.out_dir {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    if let Some(target) = a.target_ms {
        let inputs = (0..frames)
            .map(|k| frame_input(path.as_ref(), camera, k, k as f64 / fps, shutter, fps));
        let pinned = a.spp.is_some().then_some(settings.sample_fraction);
        let rows = governed(
            &gpu,
            &mut r,
            &settings,
            inputs,
            target,
            a.min_scale.unwrap_or(0.25),
            pinned,
            size,
            a.out_dir.as_deref(),
        )?;
        let mut wall: Vec<f64> = rows.iter().map(|r| r.wall_ms).collect();
        wall.sort_by(f64::total_cmp);
        let pct = |q: f64| wall[((wall.len() - 1) as f64 * q).round() as usize];
        eprintln!(
            "{name}: {frames} frames governed to {target} ms: wall median {:.1} ms, 95th percentile {:.1} ms on {}",
            pct(0.5),
            pct(0.95),
            gpu.info.name
        );
        if let Some(out) = &a.out {
            r.read_hdr(&gpu)?.save(out)?;
        }
        return Ok(());
    }
    for k in 0..frames {
        // Accumulation needs a frozen clock; otherwise time advances at --fps.
        let input = frame_input(
            path.as_ref(),
            camera,
            k,
            if a.accumulate { 0.0 } else { k as f64 / fps },
            shutter,
            fps,
        );
        r.render(&gpu, &input, &settings, None)?;
        if let Some(dir) = &a.out_dir {
            r.read_hdr(&gpu)?.save(&dir.join(format!("frame_{k:05}.exr")))?;
        }
    }
    let secs = start.elapsed().as_secs_f64();
    match (&a.out, view) {
        (Some(out), Some(view)) => {
            let image = r.display_image(&gpu, &FrameSettings { view, ..settings })?;
            image.save(out).with_context(|| format!("writing {}", out.display()))?;
        }
        (Some(out), None) => r.read_hdr(&gpu)?.save(out)?,
        _ => {}
    }
    let traced = match size == shown {
        true => String::new(),
        false => format!(" (traced at {}x{})", size.0, size.1),
    };
    eprintln!(
        "{name}: {}x{}{traced} real-time, {frames} frames{} in {secs:.2} s on {}",
        shown.0,
        shown.1,
        if a.accumulate { " accumulated" } else { "" },
        gpu.info.name
    );
    Ok(())
}

/// One governed frame as frames.csv records it.
pub struct GovernedFrame {
    pub wall_ms: f64,
    pub gpu_ms: f64,
    pub spp: f64,
    pub size: (u32, u32),
    /// The denoiser's a-trous levels the frame ran (the governor may turn them down), where it
    /// has them.
    pub levels: Option<u32>,
}

/// Render one frame at the governor's choice (its scale of `full`, its sample fraction) and
/// tell the governor what it cost: the frame's wall time (resize, render and its timings read
/// back, which waits for the device) and its trace time. `last_camera` tells it whether the
/// camera moved.
pub fn governed_frame(
    gpu: &hush_engine::gpu::Gpu,
    r: &mut Renderer,
    g: &mut hush_engine::governor::Governor,
    settings: &FrameSettings,
    input: &FrameInput,
    full: (u32, u32),
    last_camera: &mut Option<hush_engine::scene::Camera>,
) -> Result<GovernedFrame> {
    let c = g.choice();
    let size = scaled(full, c.scale);
    let mut s = FrameSettings { sample_fraction: c.fraction, ..settings.clone() };
    hush_engine::settings::cap_filter_levels(&mut s, c.levels);
    let start = std::time::Instant::now();
    r.resize(gpu, size)?;
    r.show_at(Some(full))?;
    r.render(gpu, input, &s, None)?;
    let passes = r.pass_times(gpu)?;
    let wall_ms = start.elapsed().as_secs_f64() * 1e3;
    let moving = last_camera.is_some_and(|l| l != input.camera);
    *last_camera = Some(input.camera);
    g.record(hush_engine::governor::FrameCost::from_passes(wall_ms, &passes, c, moving));
    Ok(GovernedFrame {
        wall_ms,
        gpu_ms: passes.iter().map(|p| p.1).sum(),
        spp: s.samples_per_pixel as f64 / c.fraction.period() as f64,
        size,
        levels: hush_engine::settings::filter_levels(&s),
    })
}

/// Render `inputs` with the governor holding `target_ms` (hush_engine::governor): before each
/// frame the renderer takes the governor's scale of `full` and its sample fraction; after it,
/// the frame's wall time (render and its timings read back) and trace time go back to it.
#[allow(clippy::too_many_arguments)]
fn governed(
    gpu: &hush_engine::gpu::Gpu,
    r: &mut Renderer,
    settings: &FrameSettings,
    inputs: impl Iterator<Item = FrameInput>,
    target_ms: f64,
    min_scale: f32,
    pinned: Option<SampleFraction>,
    full: (u32, u32),
    out_dir: Option<&std::path::Path>,
) -> Result<Vec<GovernedFrame>> {
    if !(target_ms > 0.0 && target_ms.is_finite()) {
        bail!("--target-ms must be a positive number of milliseconds");
    }
    if !(min_scale > 0.0 && min_scale <= 1.0) {
        bail!("--min-scale must be in (0, 1]");
    }
    let mut g = hush_engine::governor::Governor::new(target_ms);
    g.min_scale = min_scale;
    g.pinned_fraction = pinned;
    g.fractions_allowed = r.fills_untraced_pixels(gpu, settings)?;
    g.keeps_history = settings.resample_history_frames > 0.0;
    g.filter_levels = hush_engine::settings::filter_levels(settings).unwrap_or(0);
    let mut rows = vec![];
    let mut last_camera = None;
    for (k, input) in inputs.enumerate() {
        rows.push(governed_frame(gpu, r, &mut g, settings, &input, full, &mut last_camera)?);
        if let Some(dir) = out_dir {
            r.read_hdr(gpu)?.save(&dir.join(format!("frame_{k:05}.exr")))?;
        }
    }
    if let Some(dir) = out_dir {
        let mut csv = String::from("frame,wall_ms,gpu_ms,spp,width,height,levels\n");
        for (k, f) in rows.iter().enumerate() {
            let levels = f.levels.map_or(String::new(), |l| l.to_string());
            csv += &format!(
                "{k},{:.3},{:.3},{},{},{},{levels}\n",
                f.wall_ms, f.gpu_ms, f.spp, f.size.0, f.size.1
            );
        }
        let path = dir.join("frames.csv");
        std::fs::write(&path, csv).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(rows)
}

/// `full` at resolution scale `scale` per side (at least one pixel).
pub fn scaled(full: (u32, u32), scale: f32) -> (u32, u32) {
    let side = |v: u32| (v as f32 * scale).round().max(1.0) as u32;
    (side(full.0), side(full.1))
}
