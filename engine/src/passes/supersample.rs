//! Supersampling with guide rays (Voorhuis §5; shaders/supersample/*.wgsl), for k =
//! `FrameSettings::samples_per_pixel` > 1: `supersample/samples` traces k - 1 extra samples per
//! pixel beside the raster's guide, `supersample/assign` gives each the most similar of its
//! four nearest guides, `supersample/mix` averages them into their guides' light (eq. 7), which
//! the denoiser and the composite then read in place of the trace's (`FrameIo::mixed`); after
//! the composite, `supersample/resolve` makes each pixel the mean of its samples' guides.
//!
//! Per pixel: 56 bytes per extra sample, 16 for the guides' features, 16 or 24 for the mixed
//! light and 16 for the resolved image (k = 4 in a glossy scene: 224 bytes).

use super::chain::ChainStage;
use super::io::{FrameIo, MixedLight};
use crate::gpu::{BindCache, Bindings, GpuMemory, GpuScene, Recorder, set_compute_groups};
use crate::passes::trace::TraceInputs;
use crate::shader::compute_pipeline;
use crate::shader::{Reload, Reloadable};
use anyhow::Result;

pub const SAMPLES: &str = "supersample/samples";
const RECORD_BYTES: u64 = 56;

pub struct SupersampleTargets {
    /// Samples per pixel these were made for, and the frame targets' epoch.
    pub k: u32,
    pub epoch: u64,
    samples: wgpu::Buffer,
    guides: wgpu::Buffer,
    pub mixed: MixedLight,
    resolved: wgpu::Buffer,
}

impl SupersampleTargets {
    /// Labels of everything it allocates start with this.
    pub const PREFIX: &str = "supersample/";

    pub fn new(
        d: &wgpu::Device,
        mem: &mut GpuMemory,
        size: (u32, u32),
        k: u32,
        glossy: bool,
        epoch: u64,
    ) -> SupersampleTargets {
        let pixels = size.0 as u64 * size.1 as u64;
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let rw = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let f = super::trace::MATTE_FORMAT;
        let mut t = |label: &str| mem.texture(d, label, size, f, rw);
        let mixed = MixedLight {
            matte: t("supersample/matte"),
            direct: t("supersample/direct"),
            glossy: glossy.then(|| t("supersample/glossy")),
        };
        SupersampleTargets {
            k,
            epoch,
            samples: mem.buffer(
                d,
                "supersample/samples",
                pixels * (k.max(2) - 1) as u64 * RECORD_BYTES,
                storage,
            ),
            guides: mem.buffer(d, "supersample/guides", pixels * 16, storage),
            mixed,
            resolved: mem.buffer(d, "supersample/resolved", pixels * 16, storage),
        }
    }
}

/// The modules of the mix, assign and resolve programs.
pub fn modules(stage: &'static str, glossy: bool) -> Vec<&'static str> {
    let mut m = vec!["common/math.wgsl", "realtime/frame.wgsl", "realtime/gbuffer_in.wgsl"];
    m.push(if glossy { "realtime/glossy_in.wgsl" } else { "realtime/glossy_in_none.wgsl" });
    m.push("supersample/common.wgsl");
    if stage == "supersample/mix.wgsl" {
        m.push(if glossy {
            "supersample/mix_glossy.wgsl"
        } else {
            "supersample/mix_glossy_none.wgsl"
        });
    }
    m.push(stage);
    m
}

/// The samples program: the trace's (it shades as the trace does) and the supersampling's.
/// `reflections`: the trace writes the glossy path's reflection data this frame.
pub fn sample_modules(scene: &GpuScene, reflections: bool) -> Vec<&'static str> {
    let mut m = scene.shading_modules();
    m.push("realtime/frame.wgsl");
    m.push("realtime/lens.wgsl");
    m.push("realtime/area_light.wgsl");
    m.push(super::trace::glossy_module(scene.features.glossy, reflections));
    // Its samples trace frame.paths: the uncovered pixels' extra paths are the guide's.
    m.extend([
        "realtime/uncovered_none.wgsl",
        "realtime/reservoir_none.wgsl",
        "realtime/trace.wgsl",
        "supersample/common.wgsl",
        "supersample/samples.wgsl",
    ]);
    m
}

pub struct Supersample {
    /// The samples program, and whether it writes the reflection data.
    samples: Option<(Reloadable<wgpu::ComputePipeline>, BindCache, bool)>,
    stages: Option<[ChainStage<()>; 3]>,
}

impl Supersample {
    pub fn new() -> Supersample {
        Supersample { samples: None, stages: None }
    }

    /// Its pipelines, for hot reload.
    pub fn pipelines(&mut self) -> Vec<&mut dyn Reload> {
        let mut v: Vec<&mut dyn Reload> = vec![];
        if let Some((p, _, _)) = self.samples.as_mut() {
            v.push(p);
        }
        if let Some(s) = self.stages.as_mut() {
            v.extend(s.iter_mut().map(|s| &mut s.pipeline as &mut dyn Reload));
        }
        v
    }

    fn own<'a>(t: &'a SupersampleTargets, b: Bindings<'a>) -> Bindings<'a> {
        let b = b
            .buffer("ss_samples", &t.samples)
            .buffer("ss_guides", &t.guides)
            .texture("out_matte", &t.mixed.matte.1)
            .texture("out_direct", &t.mixed.direct.1)
            .buffer("resolved", &t.resolved);
        match &t.mixed.glossy {
            Some(g) => b.texture("out_glossy", &g.1),
            None => b,
        }
    }

    /// Trace the extra samples, assign and mix them (before the denoiser). `io`: the frame's
    /// I/O with the trace's own light.
    pub fn record_mix(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        trace: &TraceInputs,
        io: &FrameIo,
        t: &SupersampleTargets,
    ) -> Result<()> {
        let (gpu, scene, size) = (rec.gpu, trace.scene.scene, io.size);
        let sample_bindings = Self::own(t, trace.bindings());
        let reflections = trace.t.has_reflections();
        if self.samples.as_ref().is_some_and(|s| s.2 != reflections) {
            self.samples = None;
        }
        let (p, cache, _) = super::chain::made(&mut self.samples, || {
            let p = Reloadable::new(
                gpu,
                SAMPLES,
                &scene.prelude(),
                &sample_modules(scene, reflections),
                wgpu::ShaderStages::COMPUTE,
                &sample_bindings,
                |d, m, l| compute_pipeline(d, SAMPLES, m, l, "samples"),
            )?;
            Ok((p, BindCache::default(), reflections))
        })?;
        let groups =
            cache.get(key, p.builds(), (), |_| p.bind_groups(&gpu.device, &sample_bindings))?;
        {
            let _scope = crate::profile::scope(SAMPLES);
            let mut pass = rec.compute_pass(SAMPLES);
            pass.set_pipeline(p.get());
            set_compute_groups(&mut pass, groups);
            pass.dispatch_workgroups(size.0.div_ceil(8), size.1.div_ceil(8), 1);
        }
        let offered = Self::own(t, io.bindings().buffer("hdr", io.hdr));
        let [assign, mix, _] = super::chain::made(&mut self.stages, || {
            let glossy = t.mixed.glossy.is_some();
            let stage =
                |label, file| ChainStage::new(gpu, label, &modules(file, glossy), "main", &offered);
            Ok([
                stage("supersample/assign", "supersample/assign.wgsl")?,
                stage("supersample/mix", "supersample/mix.wgsl")?,
                stage("supersample/resolve", "supersample/resolve.wgsl")?,
            ])
        })?;
        assign.record(rec, key, (), size, |_| offered.clone())?;
        mix.record(rec, key, (), size, |_| offered.clone())
    }

    /// After the composite: each pixel the mean of its samples' guides, copied back into the
    /// composite's image for TAA and the display.
    pub fn record_resolve(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        io: &FrameIo,
        t: &SupersampleTargets,
    ) -> Result<()> {
        let offered = Self::own(t, io.bindings().buffer("hdr", io.hdr));
        let Some([_, _, resolve]) = self.stages.as_mut() else {
            anyhow::bail!("the supersampling resolves before it mixed")
        };
        resolve.record(rec, key, (), io.size, |_| offered.clone())?;
        rec.enc.copy_buffer_to_buffer(
            &t.resolved,
            0,
            io.hdr,
            0,
            io.size.0 as u64 * io.size.1 as u64 * 16,
        );
        Ok(())
    }
}

impl Default for Supersample {
    fn default() -> Self {
        Supersample::new()
    }
}
