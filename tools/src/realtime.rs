//! `hush-cli render --mode realtime`: the hybrid frame, headless and deterministic.

use crate::render::{RenderArgs, bvh_kind, image_size, load_scene, parse_camera};
use anyhow::{Context, Result, bail};
use hush_engine::frame::{FrameInput, Renderer, View};
use hush_engine::scene::CameraPath;
use hush_engine::settings::{Denoiser, FrameSettings, ReflectionMv, disable_stage, stage_names};

pub fn parse_denoiser(s: &str) -> Result<Denoiser> {
    match s {
        "none" => Ok(Denoiser::None),
        "mara" => Ok(Denoiser::Mara),
        _ => bail!("--denoiser {s:?}: use none or mara"),
    }
}

/// `--denoiser`, `--disable` and `--reflection-mv` applied to default settings.
pub fn denoiser_settings(denoiser: &str, disable: &[String], reflection_mv: &str) -> Result<FrameSettings> {
    chain_settings(FrameSettings::default(), Some(denoiser), disable, Some(reflection_mv))
}

/// The settings of `--preset` (or the defaults) with `--denoiser`, `--disable` and
/// `--reflection-mv` applied where given.
pub fn preset_settings(preset: Option<&std::path::Path>, denoiser: Option<&str>, disable: &[String], reflection_mv: Option<&str>) -> Result<FrameSettings> {
    let base = preset.map(FrameSettings::load_preset).transpose()?.unwrap_or_default();
    chain_settings(base, denoiser, disable, reflection_mv)
}

/// The path length of a run: --max-depth, else the preset's if it names one, else the scene's
/// (a preset that leaves it out must not fall back to the default's, which is not the scene's
/// and not what its references are rendered with).
pub fn path_length(max_depth: Option<i32>, preset: Option<&std::path::Path>, scene_depth: i32) -> Result<i32> {
    if let Some(d) = max_depth {
        return Ok(d);
    }
    Ok(match preset {
        Some(p) => FrameSettings::preset_max_depth(p)?.unwrap_or(scene_depth),
        None => scene_depth,
    })
}

fn chain_settings(mut s: FrameSettings, denoiser: Option<&str>, disable: &[String], reflection_mv: Option<&str>) -> Result<FrameSettings> {
    if let Some(d) = denoiser {
        s.denoiser = parse_denoiser(d)?;
    }
    for stage in disable {
        if !disable_stage(&mut s, stage) {
            bail!("--disable {stage:?}: the stages are {}", stage_names().join(", "));
        }
    }
    if let Some(mv) = reflection_mv {
        s.glossy.reflection_mv = ReflectionMv::parse(mv).with_context(|| format!("--reflection-mv {mv:?}: use diamond, virtual or primary"))?;
    }
    Ok(s)
}

pub fn run(a: RenderArgs) -> Result<()> {
    let chains = preset_settings(a.preset.as_deref(), a.denoiser.as_deref(), &a.disable, a.reflection_mv.as_deref())?;
    if a.frames == 0 {
        bail!("--frames must be at least 1");
    }
    if a.out.is_none() && a.out_dir.is_none() {
        bail!("real-time mode needs --out FILE (last frame) or --out-dir DIR (every frame)");
    }
    if !(a.fps > 0.0 && a.fps.is_finite()) {
        bail!("--fps must be a positive number");
    }
    let scene = load_scene(&a.scene, a.max_texture_size)?;
    let size = image_size(&scene, a.width, a.height);
    let path = a.camera_path.as_deref().map(CameraPath::load).transpose()?;
    let camera = match &a.camera {
        Some(c) => parse_camera(c)?,
        None => scene.camera_or_default(),
    };
    if a.accumulate && path.is_some() {
        bail!("--accumulate needs a still camera; it cannot be combined with --camera-path");
    }
    let max_depth = path_length(a.max_depth, a.preset.as_deref(), scene.max_depth)?;
    let settings = FrameSettings { max_depth, seed: a.seed, accumulate: a.accumulate || chains.accumulate, ..chains };
    let name = scene.name.clone();
    let start = std::time::Instant::now();
    let (gpu, mut r) = Renderer::headless(scene, bvh_kind(&a.bvh)?, size)?;
    if let Some(dir) = &a.out_dir {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    for k in 0..a.frames {
        let input = match &path {
            Some(p) => {
                let key = p.frame(k as usize);
                FrameInput { camera: key.camera(), time: key.time }
            }
            // Accumulation needs a frozen clock; otherwise time advances at --fps.
            None => FrameInput { camera, time: if a.accumulate { 0.0 } else { k as f64 / a.fps } },
        };
        r.render(&gpu, &input, &settings, None)?;
        if let Some(dir) = &a.out_dir {
            r.read_hdr(&gpu)?.save(&dir.join(format!("frame_{k:05}.exr")))?;
        }
    }
    let img = r.read_hdr(&gpu)?;
    let secs = start.elapsed().as_secs_f64();
    match (&a.out, &a.view) {
        (Some(out), Some(name)) => {
            let view = View::ALL.into_iter().find(|v| v.name() == name).with_context(|| {
                format!("--view {name:?}: use one of {}", View::ALL.map(|v| v.name()).join(", "))
            })?;
            if view.needs_glossy() && !r.prepared.features.glossy {
                bail!("--view {name}: the scene has no glossy buffers");
            }
            if out.extension().is_none_or(|e| !e.eq_ignore_ascii_case("png")) {
                bail!("--view writes what the display shows: use a .png --out");
            }
            let shown = r.display_image(&gpu, &FrameSettings { view, ..settings })?;
            shown.save(out).with_context(|| format!("writing {}", out.display()))?;
        }
        (Some(out), None) => img.save(out)?,
        (None, Some(_)) => bail!("--view needs --out FILE.png"),
        (None, None) => {}
    }
    eprintln!(
        "{name}: {}x{} real-time, {} frames{} in {secs:.2} s on {}",
        size.0,
        size.1,
        a.frames,
        if a.accumulate { " accumulated" } else { "" },
        gpu.info.name
    );
    Ok(())
}
