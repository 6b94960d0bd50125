//! Helpers shared by the GPU integration tests: paths to `../shared`, rendering a scene with the
//! reference tracer, and a small glTF writer for synthetic scenes.

pub mod gltf_writer;

use anyhow::Result;
use hush_engine::accel::BvhKind;
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::passes::{Accumulation, ReferenceTracer, TraceView};
use hush_engine::scene::Scene;
use std::path::PathBuf;

/// `../shared` beside the checkout (CI has it there).
pub fn shared() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared")
}

pub fn oracle(scene: &str) -> PathBuf {
    shared().join("oracle").join(scene)
}

/// Render `scene` with the reference tracer: `spp` samples per pixel at `w` x `h`.
pub fn render(scene: &Scene, w: u32, h: u32, spp: u32, seed: u32) -> Result<Accumulation> {
    render_with(scene, w, h, spp, seed, BvhKind::DEFAULT)
}

pub fn render_with(scene: &Scene, w: u32, h: u32, spp: u32, seed: u32, kind: BvhKind) -> Result<Accumulation> {
    let prepared = PreparedScene::new(scene, kind)?;
    let gpu = Gpu::headless(&prepared.requirements(w as u64 * h as u64 * 32))?;
    let gscene = prepared.upload(&gpu);
    let view = TraceView { camera: scene.camera_or_default(), width: w, height: h, max_depth: scene.max_depth, seed };
    let mut tracer = ReferenceTracer::new(&gpu, &prepared, &gscene, &view)?;
    let mut done = 0;
    while done < spp {
        let n = (spp - done).min(16);
        tracer.dispatch(&gpu, n);
        gpu.wait()?;
        done += n;
    }
    tracer.readback(&gpu)
}
