//! `upscale`: the temporal upscaler (shaders/taa/upscale.wgsl). Where the frame is traced below
//! the size it is shown at ([`crate::frame::Renderer::show_at`]) and a denoiser runs, it takes
//! TAA's place after the composite: each shown pixel accumulates the composite's jittered
//! samples that land near it, so a still view converges to the shown resolution's detail where
//! a stretch keeps the render pixels' blocks. At the render size itself TAA runs as before.
//!
//! Its history lives at the shown size and outlives a change of render scale (the governor's),
//! which the render-size histories cross only by resampling (passes/rescale.rs). Per shown
//! pixel: 196 bytes (pairs of the light's mean and weight, 32, of the raw samples' for the
//! still view, 32 and 16, of the materials' and the emission's means, 8 each, the image shown,
//! 16, and the raster's G-buffer at the shown size, 36), held only while it runs. Its settings are `TaaSettings::upscale`, `upscale_sigma` and
//! `upscale_moving_frames`.

use super::chain::ChainStage;
use super::gbuffer::{Channel, GBufferPass, GBufferTargets};
use super::io::FrameIo;
use crate::frame::FrameParams;
use crate::gpu::{Gpu, GpuMemory, GpuScene, Parity, PingPong, Recorder, Tex};
use crate::settings::TaaSettings;
use anyhow::{Context, Result};
use bytemuck::{Pod, Zeroable};

pub const LABEL: &str = "upscale";
/// Its second pass: the image shown.
pub const SHOWN: &str = "upscale/shown";
/// Its first pass, at the render size, and what it writes.
pub const SAMPLES: &str = "upscale/samples";
const RAW_SAMPLES: &str = "upscale/raw samples";
/// The raster at the shown size before them.
pub const RASTER: &str = "upscale/gbuffer";
/// Labels of what it allocates start with this.
pub const PREFIX: &str = "upscale/";

/// Mirror of `UpscaleParams` in shaders/taa/upscale.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct UpscaleParams {
    pub out_size: [u32; 2],
    pub sigma: f32,
    pub moving_weight: f32,
    pub fill_weight: f32,
    pub continues: u32,
    pub raw_continues: u32,
    pub bias_sigmas: f32,
    pub min_samples: f32,
    pub moving_frames: f32,
    pub materials: u32,
    pub _pad: u32,
}

impl UpscaleParams {
    /// For rendering at `render` to show at `shown`; `raw` continues the raw samples' mean
    /// (the still-view mean's parameters, passes/converge.rs; None: no raw mean). The weights
    /// are in units of the kernel weight one frame's samples bring a shown pixel on average:
    /// 2 pi sigma^2 times the samples per shown pixel.
    pub fn new(
        s: &TaaSettings,
        (render, shown): ((u32, u32), (u32, u32)),
        continues: bool,
        raw: Option<&super::converge::ConvergeParams>,
    ) -> Self {
        let sigma = s.upscale_sigma.clamp(0.2, 2.0);
        let moving_frames = s.upscale_moving_frames.clamp(1.0, 1024.0);
        let per_frame = Self::frame_weight(s, (render, shown));
        UpscaleParams {
            out_size: [shown.0, shown.1],
            sigma,
            moving_weight: moving_frames * per_frame,
            fill_weight: 0.25 * per_frame,
            continues: continues as u32,
            raw_continues: raw.is_some_and(|c| c.continues != 0) as u32,
            bias_sigmas: raw.map_or(0.0, |c| c.bias_sigmas),
            min_samples: raw.map_or(2.0, |c| c.min_samples),
            moving_frames,
            materials: s.upscale_materials as u32,
            _pad: 0,
        }
    }

    /// The kernel weight one frame's samples bring a shown pixel on average, rendering at
    /// `render` to show at `shown`: 2 pi sigma^2 times the samples per shown pixel. The
    /// history's weight over it is its length in frames (the `upscale/history frames` view).
    pub fn frame_weight(s: &TaaSettings, (render, shown): ((u32, u32), (u32, u32))) -> f32 {
        let sigma = s.upscale_sigma.clamp(0.2, 2.0);
        let density =
            (render.0 as f32 / shown.0.max(1) as f32) * (render.1 as f32 / shown.1.max(1) as f32);
        std::f32::consts::TAU * sigma * sigma * density
    }
}

struct UpscaleTargets {
    size: (u32, u32),
    /// The raster's G-buffer at the shown size: the materials the light is modulated by.
    gbuffer: GBufferTargets,
    /// The shown raster's demodulation albedo averaged over its jitter (rgb) and its count (a),
    /// and its emission's average.
    albedo: PingPong<Tex>,
    emission: PingPong<Tex>,
    /// Kernel-weighted mean of the samples (rgb) and their weight (a).
    history: PingPong<Tex>,
    /// The same of the raw samples, and their mean squared length (r) and sum of squared
    /// weights (g).
    raw: PingPong<Tex>,
    raw_m2: PingPong<Tex>,
    /// The image shown, row-major at `size`.
    image: wgpu::Buffer,
}

pub struct UpscaleStage {
    params: wgpu::Buffer,
    /// The frame's uniform at the shown size, for its raster.
    frame: wgpu::Buffer,
    raster: Option<GBufferPass>,
    /// What its shown-size targets cost (apart from the render-size targets: they outlive them).
    pub memory: GpuMemory,
    targets: Option<UpscaleTargets>,
    /// The accumulation and the image shown, made on first use (they depend on whether the
    /// scene has glossy light).
    programs: Option<[ChainStage; 3]>,
    /// Each render pixel's demodulated light (and depth) and raw sample, at the render size.
    samples: Option<((u32, u32), Tex, Tex)>,
    motion: crate::gpu::Motion,
    /// Whether the last frame recorded ran it (its image is then the one shown).
    ran: bool,
}

impl UpscaleStage {
    pub fn new(gpu: &Gpu, memory: &mut GpuMemory, motion: crate::gpu::Motion) -> UpscaleStage {
        let u = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        let bytes = size_of::<UpscaleParams>() as u64;
        let params = memory.buffer(&gpu.device, "upscale/params", bytes, u);
        let bytes = size_of::<FrameParams>() as u64;
        let frame = memory.buffer(&gpu.device, "upscale/frame", bytes, u);
        let memory = GpuMemory::default();
        let (targets, programs, raster) = (None, None, None);
        let samples = None;
        UpscaleStage {
            params,
            frame,
            raster,
            memory,
            targets,
            programs,
            samples,
            motion,
            ran: false,
        }
    }

    /// Write the frame's uniform at the shown size (its raster's camera and jitter).
    pub fn write_frame(&self, gpu: &Gpu, frame: &FrameParams) {
        gpu.queue.write_buffer(&self.frame, 0, bytemuck::bytes_of(frame));
    }

    pub fn pipelines(&mut self) -> impl Iterator<Item = &mut dyn crate::shader::Reload> {
        let raster =
            self.raster.iter_mut().map(|r| &mut r.pipeline as &mut dyn crate::shader::Reload);
        self.programs
            .iter_mut()
            .flatten()
            .map(|s| &mut s.pipeline as &mut dyn crate::shader::Reload)
            .chain(raster)
    }

    /// Make the targets for showing at `size` (None: drop them); true if anything changed.
    pub fn allocate(&mut self, gpu: &Gpu, size: Option<(u32, u32)>) -> bool {
        if self.targets.as_ref().map(|t| t.size) == size {
            return false;
        }
        self.memory.forget(PREFIX);
        self.samples = None;
        self.targets = size.map(|size| {
            let (d, mem) = (&gpu.device, &mut self.memory);
            let rw = wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC;
            let mut pair = |l: &str, f| {
                PingPong::new(|i| mem.texture(d, &format!("upscale/{l} {i}"), size, f, rw))
            };
            let history = pair("history", wgpu::TextureFormat::Rgba32Float);
            let raw = pair("raw", wgpu::TextureFormat::Rgba32Float);
            let raw_m2 = pair("raw m2", wgpu::TextureFormat::Rg32Float);
            let albedo = pair("albedo", wgpu::TextureFormat::Rgba16Float);
            let emission = pair("emission", wgpu::TextureFormat::Rgba16Float);
            let gbuffer = GBufferTargets::labelled(gpu, mem, size, PREFIX);
            let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
            let bytes = size.0 as u64 * size.1 as u64 * 16;
            let image = mem.buffer(d, "upscale/image", bytes, usage);
            UpscaleTargets { size, gbuffer, albedo, emission, history, raw, raw_m2, image }
        });
        true
    }

    /// The image shown and its size, if the last frame ran the stage.
    pub fn output(&self) -> Option<(&wgpu::Buffer, (u32, u32))> {
        self.targets.as_ref().filter(|_| self.ran).map(|t| (&t.image, t.size))
    }

    /// Note that this frame does not run the stage.
    pub fn skip(&mut self) {
        self.ran = false;
    }

    /// Record the raster at the shown size and the upscale of `io.hdr` (the composite's image)
    /// with `params`.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        (key, scene): (crate::gpu::BindKey, &GpuScene),
        io: &FrameIo,
        params: &UpscaleParams,
        parity: Parity,
    ) -> Result<()> {
        self.ran = false;
        let gpu = rec.gpu;
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        let t = self.targets.as_ref().context("the upscaler records before its targets exist")?;
        let frame = &self.frame;
        let raster = super::chain::made(&mut self.raster, || GBufferPass::new(gpu, scene, frame))
            .context("creating the upscaler's raster")?;
        if params.materials != 0 {
            let _pass = crate::profile::scope(RASTER);
            raster.record(rec, scene, frame, &t.gbuffer)?;
        }
        if self.samples.as_ref().is_none_or(|s| s.0 != io.size) {
            for l in [SAMPLES, RAW_SAMPLES] {
                self.memory.forget(l);
            }
            let rw = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING;
            let f = wgpu::TextureFormat::Rgba32Float;
            let mut make = |l| self.memory.texture(&gpu.device, l, io.size, f, rw);
            self.samples = Some((io.size, make(SAMPLES), make(RAW_SAMPLES)));
        }
        let (_, samples, raw_samples) = self.samples.as_ref().context("no samples")?;
        let g = |c| t.gbuffer.view(c);
        let up = &self.params;
        let write_samples = |_: Parity| {
            io.bindings()
                .buffer("up", up)
                .buffer("hdr", io.hdr)
                .texture("out_samples", &samples.1)
                .texture("out_raw_samples", &raw_samples.1)
        };
        let accumulate = |p: Parity| {
            io.bindings()
                .buffer("up", up)
                .texture("up_samples", &samples.1)
                .texture("up_raw_samples", &raw_samples.1)
                .texture("up_history", &t.history.history(p).1)
                .texture("out_up_history", &t.history.output(p).1)
                .texture("raw_history", &t.raw.history(p).1)
                .texture("out_raw", &t.raw.output(p).1)
                .texture("raw_m2_history", &t.raw_m2.history(p).1)
                .texture("out_raw_m2", &t.raw_m2.output(p).1)
                .texture("albedo_history", &t.albedo.history(p).1)
                .texture("out_albedo", &t.albedo.output(p).1)
                .texture("emission_history", &t.emission.history(p).1)
                .texture("out_emission", &t.emission.output(p).1)
                .texture("shown_base_color", g(Channel::BaseColor))
                .texture("shown_specular", g(Channel::Specular))
                .texture("shown_ids", g(Channel::Ids))
                .texture("shown_emission", g(Channel::Emission))
        };
        let shown = |p: Parity| {
            io.bindings()
                .buffer("up", up)
                .texture("up_samples", &samples.1)
                .texture("up_mean", &t.history.output(p).1)
                .texture("raw", &t.raw.output(p).1)
                .texture("raw_m2", &t.raw_m2.output(p).1)
                .texture("albedo", &t.albedo.output(p).1)
                .texture("emission", &t.emission.output(p).1)
                .buffer("upscaled", &t.image)
        };
        let (motion, glossy) = (self.motion, io.trace.glossy.is_some());
        let [s, a, b] = super::chain::made(&mut self.programs, || {
            let m = |pass| modules(motion, glossy, pass);
            let p = Parity::default();
            let s = ChainStage::new(gpu, SAMPLES, &m(Pass::Samples), "main", &write_samples(p))?;
            let a = ChainStage::new(gpu, LABEL, &m(Pass::Accumulate), "main", &accumulate(p))?;
            let b = ChainStage::new(gpu, SHOWN, &m(Pass::Shown), "main", &shown(p))?;
            Ok([s, a, b])
        })?;
        s.record(rec, key, parity, io.size, write_samples)?;
        a.record(rec, key, parity, t.size, accumulate)?;
        b.record(rec, key, parity, t.size, shown)?;
        self.ran = true;
        Ok(())
    }
}

/// The modules of one of its passes, for the scene's kind of motion, with the scene's glossy
/// light or without.
pub fn modules(motion: crate::gpu::Motion, glossy: bool, pass: Pass) -> Vec<&'static str> {
    let mut m = vec!["common/bilinear.wgsl", "realtime/reproject.wgsl", "taa/upscale_common.wgsl"];
    match pass {
        Pass::Samples => m.extend([super::composite::REMODULATE, "taa/upscale_samples.wgsl"]),
        Pass::Accumulate => m.extend([
            "taa/upscale_gather.wgsl",
            motion.module(),
            "taa/history_test.wgsl",
            "taa/upscale.wgsl",
        ]),
        Pass::Shown => m.extend(["taa/upscale_gather.wgsl", "taa/upscale_shown.wgsl"]),
    }
    super::composite::modules(glossy, &m)
}

/// The upscaler's three passes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    /// Each render pixel's demodulated light and raw sample, once.
    Samples,
    /// The shown pixels' means.
    Accumulate,
    /// The image shown.
    Shown,
}

impl Pass {
    pub const ALL: [Pass; 3] = [Pass::Samples, Pass::Accumulate, Pass::Shown];
}
