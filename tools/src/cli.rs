//! What the commands share: how a scene is loaded, output and size checks, the camera and
//! `--spp` syntax, and the real-time settings the flags and presets give.

use anyhow::{Context, Result, bail};
use clap::Args;
use hush_engine::accel::BvhKind;
use hush_engine::scene::{Camera, LoadOptions, Scene};
use hush_engine::settings::{Denoiser, FrameSettings, ReflectionMv, disable_stage, stage_names};
use std::path::Path;

/// How a scene file is loaded: flags every command that loads one shares.
#[derive(Args, Clone, Debug)]
pub struct LoadArgs {
    /// Largest texture side kept on load (larger textures are halved until they fit).
    #[arg(long, default_value_t = hush_engine::scene::DEFAULT_MAX_TEXTURE_SIZE, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_texture_size: u32,
    /// Set a budget on what a scene file may make Hush read, decode and build, as NAME=VALUE
    /// (comma-separated or repeated). A file over one is refused with an error naming it.
    /// Budgets and defaults: file-bytes (any one file, 2 GiB), json-bytes (the glTF JSON,
    /// 64 MiB), image-pixels (one image, 8192x8192), decoded-bytes (all buffers and images, 4 GiB),
    /// nodes (1,000,000), hierarchy-depth (1024), triangles (after instancing, 16,777,215).
    #[arg(long, value_name = "NAME=VALUE")]
    pub limit: Vec<String>,
    /// Play only this one of the file's animations (its index in the file); without it every
    /// animation plays at once (a node several drive takes the last one's channel).
    #[arg(long, value_name = "INDEX")]
    pub animation: Option<usize>,
}

impl LoadArgs {
    pub fn options(&self) -> Result<LoadOptions> {
        let mut limits = hush_engine::limits::Limits::default();
        for l in &self.limit {
            limits.apply(l)?;
        }
        Ok(LoadOptions {
            max_texture_size: self.max_texture_size,
            limits,
            animation: self.animation,
        })
    }
}

/// Refuse an output file that could not be written, before any work: `what` names the flag.
pub fn check_output(path: &Path, extensions: &[&str], what: &str) -> Result<()> {
    let ext =
        path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    if !extensions.contains(&ext.as_str()) {
        bail!(
            "{what} {}: the file must end in {}",
            path.display(),
            extensions.iter().map(|e| format!(".{e}")).collect::<Vec<_>>().join(" or ")
        );
    }
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        bail!("{what} {}: the folder {} does not exist", path.display(), dir.display());
    }
    if path.is_dir() {
        bail!("{what} {} is a folder", path.display());
    }
    Ok(())
}

/// Refuse a --width or --height over `max_side` before any work (the other side may come from
/// the scene's aspect ratio, checked once the scene is loaded).
pub fn check_sides(
    width: Option<u32>,
    height: Option<u32>,
    max_side: u32,
    mode: &str,
) -> Result<()> {
    for (flag, v) in [("--width", width), ("--height", height)] {
        if let Some(v) = v.filter(|&v| v > max_side) {
            bail!("{flag} {v}: {mode} renders at most {max_side} pixels a side");
        }
    }
    Ok(())
}

/// Refuse an output folder that could not be made, before any work.
pub fn check_output_dir(dir: &Path, what: &str) -> Result<()> {
    match dir.ancestors().find(|a| a.exists()) {
        Some(a) if a.is_dir() => Ok(()),
        Some(a) => bail!("{what} {}: {} is not a folder", dir.display(), a.display()),
        None => Ok(()),
    }
}

pub fn parse_camera(s: &str) -> Result<Camera> {
    let mut eye = None;
    let mut target = None;
    let mut fov = 45.0f32;
    let (mut aperture, mut focus) = (None, None);
    for part in s.split(';').map(str::trim).filter(|p| !p.is_empty()) {
        let (k, v) = part
            .split_once('=')
            .with_context(|| format!("camera part {part:?} is not key=value"))?;
        let nums = || -> Result<glam::DVec3> {
            let n: Vec<f64> = v
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .with_context(|| format!("camera {k}={v:?}: expected x,y,z"))?;
            if n.len() != 3 || n.iter().any(|x| !x.is_finite()) {
                bail!("camera {k}={v:?}: expected three finite numbers");
            }
            Ok(glam::DVec3::new(n[0], n[1], n[2]))
        };
        match k.trim() {
            "eye" => eye = Some(nums()?),
            "target" => target = Some(nums()?),
            "fov" => {
                fov = v.trim().parse().with_context(|| format!("camera fov={v:?}"))?;
                if !(fov > 0.0 && fov < 180.0) {
                    bail!("camera fov must be in (0, 180) degrees, got {fov}");
                }
            }
            "aperture" => {
                aperture = Some(v.trim().parse::<f64>().with_context(|| {
                    format!("camera aperture={v:?}: the aperture radius in meters")
                })?)
            }
            "focus" => {
                focus =
                    Some(v.trim().parse::<f64>().with_context(|| {
                        format!("camera focus={v:?}: the focus distance in meters")
                    })?)
            }
            other => bail!("unknown camera key {other:?} (use eye, target, fov, aperture, focus)"),
        }
    }
    let lens = match (aperture, focus) {
        (None, None) => None,
        (Some(a), Some(f)) => Some(hush_engine::scene::ThinLens::new(a, f).context("--camera")?),
        _ => bail!("a thin-lens camera needs both aperture=R and focus=D (meters)"),
    };
    let (eye, target) =
        (eye.context("camera needs eye=x,y,z")?, target.context("camera needs target=x,y,z")?);
    if (eye - target).length() == 0.0 {
        bail!("camera eye and target coincide");
    }
    Ok(Camera { lens, ..Camera::look_at(eye, target, fov) })
}

/// [`Scene::open`], its warnings on standard error.
pub fn load_scene(path: &str, load: &LoadArgs) -> Result<Scene> {
    let scene = Scene::open(path, &load.options()?)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}

/// Width and height from the flags, keeping the scene's aspect ratio when one side is given.
pub fn image_size(scene: &Scene, width: Option<u32>, height: Option<u32>) -> (u32, u32) {
    let (dw, dh) = scene.resolution.unwrap_or((640, 360));
    match (width, height) {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, ((w as f64 * dh as f64 / dw as f64).round() as u32).max(1)),
        (None, Some(h)) => (((h as f64 * dw as f64 / dh as f64).round() as u32).max(1), h),
        (None, None) => (dw, dh),
    }
}

pub fn bvh_kind(s: &Option<String>) -> Result<BvhKind> {
    match s {
        Some(s) => BvhKind::parse(s).with_context(|| format!("--bvh {s:?}: use bvh2 or cwbvh")),
        None => Ok(BvhKind::DEFAULT),
    }
}

/// `--spp`: whole samples per pixel, or (real-time mode) a fraction of the pixels per frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Spp {
    Samples(u32),
    Fraction(hush_engine::settings::SampleFraction),
}

pub fn parse_spp(s: &str) -> Result<Spp> {
    if s.contains('/') {
        return Ok(Spp::Fraction(s.parse()?));
    }
    match s.trim().parse::<u32>() {
        Ok(n) if n >= 1 => Ok(Spp::Samples(n)),
        _ => bail!("{s:?}: samples per pixel are a whole number from 1, or a fraction 1/N"),
    }
}

pub fn parse_denoiser(s: &str) -> Result<Denoiser> {
    match hush_engine::denoise::find(s) {
        Ok(e) => Ok(Denoiser::named(e.info.name)),
        Err(e) => bail!("--denoiser {s:?}: {e}"),
    }
}

/// `--denoiser`, `--disable` and `--reflection-mv` applied to default settings.
pub fn denoiser_settings(
    denoiser: &str,
    disable: &[String],
    reflection_mv: &str,
) -> Result<FrameSettings> {
    chain_settings(FrameSettings::default(), Some(denoiser), disable, Some(reflection_mv))
}

/// The settings of `--preset` (or the defaults) with `--denoiser`, `--disable` and
/// `--reflection-mv` applied where given.
pub fn preset_settings(
    preset: Option<&std::path::Path>,
    denoiser: Option<&str>,
    disable: &[String],
    reflection_mv: Option<&str>,
) -> Result<FrameSettings> {
    let base = preset.map(FrameSettings::load_preset).transpose()?.unwrap_or_default();
    chain_settings(base, denoiser, disable, reflection_mv)
}

/// The path length of a run: --max-depth, else the preset's if it names one, else the scene's
/// (a preset that leaves it out must not fall back to the default's, which is not the scene's
/// and not what its references are rendered with).
pub fn path_length(
    max_depth: Option<i32>,
    preset: Option<&std::path::Path>,
    scene_depth: i32,
) -> Result<i32> {
    if let Some(d) = max_depth {
        return Ok(d);
    }
    Ok(match preset {
        Some(p) => FrameSettings::preset_max_depth(p)?.unwrap_or(scene_depth),
        None => scene_depth,
    })
}

fn chain_settings(
    mut s: FrameSettings,
    denoiser: Option<&str>,
    disable: &[String],
    reflection_mv: Option<&str>,
) -> Result<FrameSettings> {
    if let Some(d) = denoiser {
        s.denoiser = parse_denoiser(d)?;
    }
    for stage in disable {
        if !disable_stage(&mut s, stage) {
            bail!("--disable {stage:?}: the stages are {}", stage_names().join(", "));
        }
    }
    if let Some(mv) = reflection_mv {
        s.glossy.reflection_mv = ReflectionMv::parse(mv)
            .with_context(|| format!("--reflection-mv {mv:?}: use diamond, virtual or primary"))?;
    }
    Ok(s)
}
