//! Traced primaries, for a camera with a thin lens (depth of field): `gbuffer/primaries` traces
//! k lens rays per pixel (shaders/realtime/primaries.wgsl) and keeps the mean of their features
//! and the statistics of their world positions (Moon et al. 2017 §4.2, appendix B);
//! `gbuffer/resolve` writes those features into the G-buffer's targets and depth (the normal
//! and depth pre-filtered where the pre-filter runs, passes/prefilter.rs), so that the trace,
//! the denoisers and TAA read the G-buffer they always read. Without a lens the raster draws the G-buffer and none of this exists.
//!
//! Per pixel: 80 bytes of features and 64 of position moments (144 bytes).

use crate::gpu::{BindCache, Bindings, GpuMemory, Recorder, set_compute_groups, set_render_groups};
use crate::passes::gbuffer::{GBufferTargets, render_pipeline};
use crate::passes::scene::SceneInputs;
use crate::shader::compute_pipeline;
use crate::shader::{Reload, Reloadable};
use anyhow::Result;

pub const LABEL: &str = "gbuffer/primaries";
pub const RESOLVE: &str = "gbuffer/resolve";
/// Words (vec4<u32>) per pixel of the features and of the moments (primaries.wgsl's layout).
pub const FEATURE_WORDS: u64 = 5;
pub const MOMENT_WORDS: u64 = 4;

/// The traced primaries' per-pixel buffers.
pub struct PrimaryTargets {
    /// The frame targets' epoch these were made for.
    pub epoch: u64,
    pub features: wgpu::Buffer,
    pub moments: wgpu::Buffer,
}

impl PrimaryTargets {
    pub const PREFIX: &str = "primaries/";

    pub fn new(
        d: &wgpu::Device,
        mem: &mut GpuMemory,
        size: (u32, u32),
        epoch: u64,
    ) -> PrimaryTargets {
        let pixels = size.0 as u64 * size.1 as u64;
        let usage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        PrimaryTargets {
            epoch,
            features: mem.buffer(d, "primaries/features", pixels * FEATURE_WORDS * 16, usage),
            moments: mem.buffer(d, "primaries/moments", pixels * MOMENT_WORDS * 16, usage),
        }
    }
}

/// The trace and resolve programs, made on first use.
#[derive(Default)]
pub struct Primaries {
    /// Without and with objects moving during the shutter.
    trace: [Option<(Reloadable<wgpu::ComputePipeline>, BindCache)>; 2],
    resolve: Option<(Reloadable<wgpu::RenderPipeline>, BindCache<bool>)>,
}

fn trace_bindings<'a>(scene: SceneInputs<'a>, t: &'a PrimaryTargets) -> Bindings<'a> {
    scene.bindings().buffer("pr_features", &t.features).buffer("pr_moments", &t.moments)
}

impl Primaries {
    pub fn pipelines(&mut self) -> Vec<&mut dyn Reload> {
        let mut v: Vec<&mut dyn Reload> = vec![];
        for (p, _) in self.trace.iter_mut().flatten() {
            v.push(p);
        }
        if let Some((p, _)) = self.resolve.as_mut() {
            v.push(p);
        }
        v
    }

    /// Trace frame.primary_samples lens rays per pixel into `t`.
    pub fn record_trace(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        inputs: SceneInputs,
        t: &PrimaryTargets,
        size: (u32, u32),
    ) -> Result<()> {
        let (gpu, scene, moving) = (rec.gpu, inputs.scene, inputs.moving);
        let offered = trace_bindings(inputs, t);
        let (p, cache) = super::chain::made(&mut self.trace[moving as usize], || {
            let mut modules = scene.shading_modules_for(moving);
            modules.push("realtime/frame.wgsl");
            modules.push(scene.features.motion().module());
            modules.extend(["realtime/lens.wgsl", "realtime/primaries.wgsl"]);
            let p = Reloadable::new(
                gpu,
                LABEL,
                &scene.prelude(),
                &modules,
                wgpu::ShaderStages::COMPUTE,
                &offered,
                |d, m, l| compute_pipeline(d, LABEL, m, l, "main"),
            )?;
            Ok((p, BindCache::default()))
        })?;
        let groups = cache.get(key, p.builds(), (), |_| p.bind_groups(&gpu.device, &offered))?;
        let _scope = crate::profile::scope(LABEL);
        let mut pass = rec.compute_pass(LABEL);
        pass.set_pipeline(p.get());
        set_compute_groups(&mut pass, groups);
        pass.dispatch_workgroups(size.0.div_ceil(8), size.1.div_ceil(8), 1);
        Ok(())
    }

    /// Write the raw features of `t` into the G-buffer targets, the normal and depth from
    /// `edges` where given (the pre-filter's, in the same layout).
    pub fn record_resolve(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        frame: &wgpu::Buffer,
        (t, edges): (&PrimaryTargets, Option<&wgpu::Buffer>),
        g: &GBufferTargets,
    ) -> Result<()> {
        let gpu = rec.gpu;
        let filtered = edges.is_some();
        let offered = Bindings::new()
            .buffer("frame", frame)
            .buffer("features", &t.features)
            .buffer("edges", edges.unwrap_or(&t.features));
        let (p, caches) = super::chain::made(&mut self.resolve, || {
            let modules = [
                "common/math.wgsl",
                "common/rng.wgsl",
                "realtime/frame.wgsl",
                "realtime/gbuffer_dither.wgsl",
                "realtime/primaries_resolve.wgsl",
            ];
            // Every pixel is written: the depth is the resolved one, not a nearest surface.
            let p = Reloadable::new(
                gpu,
                RESOLVE,
                "",
                &modules,
                wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
                &offered,
                |d, module, pl| {
                    render_pipeline(d, RESOLVE, module, pl, wgpu::CompareFunction::Always)
                },
            )?;
            Ok((p, Default::default()))
        })?;
        // Bound with the pre-filter's edges (filtered) or without.
        let groups =
            caches.get(key, p.builds(), filtered, |_| p.bind_groups(&gpu.device, &offered))?;
        let _scope = crate::profile::scope(RESOLVE);
        let mut pass = g.begin_pass(rec, RESOLVE);
        pass.set_pipeline(p.get());
        set_render_groups(&mut pass, groups);
        pass.draw(0..3, 0..1);
        Ok(())
    }
}
