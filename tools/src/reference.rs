//! The converged images the quality tools score against (the real-time frame accumulated over
//! many frames, cached on disk), and the renderer they are made with.

use crate::cli::bvh_kind;
use anyhow::{Context, Result, bail};
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::quality::Image;
use hush_engine::scene::Scene;
use hush_engine::settings::FrameSettings;
use std::path::Path;

/// A real-time frame of `scene` on an open device (the default BVH layout).
pub fn new_renderer(gpu: &Gpu, scene: &Scene, size: (u32, u32)) -> Result<Renderer> {
    let prepared = PreparedScene::new(scene, bvh_kind(&None)?)?;
    Renderer::new(gpu, scene.clone(), prepared, size)
}

/// What a reference depends on, hashed with FNV-1a: the standard library's hasher may change
/// between Rust releases, and a cache key has to outlive the build that wrote it.
pub fn reference_cache_key(
    scene: &str,
    size: (u32, u32),
    input: &FrameInput,
    frames: u32,
    acc: &FrameSettings,
) -> u64 {
    // A scene file's size and modification time stand for its content. `default` and `level`
    // are built in: their key changes with Hush's version only, so clear the cache after
    // editing them.
    let stamp = match std::fs::metadata(scene) {
        Ok(m) => format!("{} {:?}", m.len(), m.modified().ok()),
        Err(_) => format!("built-in {}", env!("CARGO_PKG_VERSION")),
    };
    let key =
        format!("{scene} {stamp} {size:?} {input:?} {frames} {} {:?}", acc.seed, acc.max_depth);
    key.bytes()
        .fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

/// The real-time frame of `input` accumulated over `frames` frames with `acc` (the converged
/// image every stream is scored against), from `cache` when it holds it, else rendered and
/// kept there.
pub fn reference(
    gpu: &Gpu,
    r: &mut Renderer,
    scene: &str,
    input: &FrameInput,
    frames: u32,
    acc: &FrameSettings,
    cache: Option<&Path>,
) -> Result<Image> {
    let size = r.size();
    let cached = cache.map(|dir| {
        dir.join(format!(
            "reference_{:016x}.exr",
            reference_cache_key(scene, size, input, frames, acc)
        ))
    });
    if let Some(path) = cached.as_ref().filter(|p| p.exists()) {
        let img = Image::load(path)
            .with_context(|| format!("reading the cached reference {}", path.display()))?;
        if (img.width, img.height) != size {
            bail!(
                "cached reference {} is {}x{}, not {}x{}",
                path.display(),
                img.width,
                img.height,
                size.0,
                size.1
            );
        }
        return Ok(img);
    }
    if let Some(path) = &cached {
        eprintln!("rendering the reference into {}", path.display());
    }
    for _ in 0..frames {
        r.render(gpu, input, acc, None)?;
    }
    let img = r.read_hdr(gpu)?;
    if let Some(path) = &cached {
        std::fs::create_dir_all(path.parent().unwrap_or(Path::new(".")))
            .with_context(|| format!("creating the folder of {}", path.display()))?;
        img.save(path)?;
    }
    Ok(img)
}
