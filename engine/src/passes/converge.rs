//! `converge`: the still-view mean after TAA (shaders/taa/converge*.wgsl). While the view stands
//! still it keeps each pixel's plain mean of its own samples (the trace's light remodulated, as
//! the accumulate mode sums it), and shows TAA's image moved towards that mean where the two
//! differ by more than the mean's noise. A denoiser's bias that outlives its noise (the
//! product of averaged material and light at a pixel whose jittered samples fall on two
//! surfaces) then fades as the samples grow, and a still image ends at the mean of every
//! sample. Its settings are [`crate::settings::TaaSettings::converge_sigmas`] and
//! `converge_min_samples`; its output, `converge/shown`, is then the image shown.
//!
//! Per pixel: 40 bytes of history (the mean and count, the mean square), allocated on the
//! stage's first frame at a size (never where it stays off). The image shown goes into the
//! composite's `composite/hdr`, which TAA has read and nothing reads after it in the frame;
//! only where the frame keeps the composite's image (`Renderer::keep`) does the stage write a
//! buffer of its own, `converge/shown` (16 bytes a pixel).

use super::chain::{ChainStage, made};
use super::io::FrameIo;
use crate::gpu::{Gpu, GpuMemory, Parity, PingPong, Recorder, Tex};
use anyhow::{Context, Result};

pub const MEAN: &str = "converge/mean";
pub const LABEL: &str = "converge";
/// The stage's own image, made only where the frame keeps the composite's.
pub const SHOWN: &str = "converge/shown";

/// Mirrors `ConvergeParams` (shaders/taa/converge_common.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ConvergeParams {
    /// 1 when the mean continues last frame's.
    pub continues: u32,
    pub bias_sigmas: f32,
    pub min_samples: f32,
    pub _pad: f32,
}

struct ConvergeTargets {
    /// Mean of the samples (rgb) and their count (a).
    mean: PingPong<Tex>,
    /// Mean of the samples' squared length.
    m2: PingPong<Tex>,
    /// The image shown where the frame keeps `composite/hdr`; else the stage writes that.
    shown: Option<wgpu::Buffer>,
}

impl ConvergeTargets {
    fn new(device: &wgpu::Device, mem: &mut GpuMemory, size: (u32, u32)) -> ConvergeTargets {
        let rw = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let mut pair = |l: &str, f| {
            PingPong::new(|i| mem.texture(device, &format!("converge/{l} {i}"), size, f, rw))
        };
        let mean = pair("mean", wgpu::TextureFormat::Rgba32Float);
        let m2 = pair("m2", wgpu::TextureFormat::R32Float);
        ConvergeTargets { mean, m2, shown: None }
    }

    /// Make or drop the stage's own image buffer; true if it changed.
    fn own_image(
        &mut self,
        device: &wgpu::Device,
        mem: &mut GpuMemory,
        size: (u32, u32),
        own: bool,
    ) -> bool {
        if self.shown.is_some() == own {
            return false;
        }
        mem.forget(SHOWN);
        let usage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        let bytes = size.0 as u64 * size.1 as u64 * 16;
        self.shown = own.then(|| mem.buffer(device, SHOWN, bytes, usage));
        true
    }
}

/// The stage's two passes, made on first use (they depend on whether the scene has glossy
/// light).
struct Programs {
    mean: ChainStage,
    shown: ChainStage,
}

pub struct ConvergeStage {
    params: wgpu::Buffer,
    targets: Option<(u64, ConvergeTargets)>,
    programs: Option<Programs>,
    /// Whether the last frame recorded ran the stage (its image is then the one shown).
    ran: bool,
}

impl ConvergeStage {
    pub fn new(gpu: &Gpu, memory: &mut GpuMemory) -> ConvergeStage {
        let u = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        let params =
            memory.buffer(&gpu.device, "converge/params", size_of::<ConvergeParams>() as u64, u);
        ConvergeStage { params, targets: None, programs: None, ran: false }
    }

    pub fn pipelines(&mut self) -> impl Iterator<Item = &mut dyn crate::shader::Reload> {
        self.programs.iter_mut().flat_map(|p| {
            [&mut p.mean.pipeline as &mut dyn crate::shader::Reload, &mut p.shown.pipeline]
        })
    }

    /// Make the textures for the frame targets of `epoch` (once per size), and an image buffer
    /// of its own where `keep_composite` (the frame reads `composite/hdr` after it); true if it
    /// made or dropped anything.
    pub fn allocate(
        &mut self,
        gpu: &Gpu,
        memory: &mut GpuMemory,
        (size, epoch): ((u32, u32), u64),
        keep_composite: bool,
    ) -> bool {
        let make = || ConvergeTargets::new(&gpu.device, memory, size);
        let made = super::chain::made_for_epoch(&mut self.targets, epoch, make);
        let Some((_, t)) = self.targets.as_mut() else { return made };
        t.own_image(&gpu.device, memory, size, keep_composite) || made
    }

    /// The image shown after this stage, if the last frame ran it: `hdr` (the composite's
    /// buffer) or the stage's own.
    pub fn output<'a>(&'a self, hdr: &'a wgpu::Buffer) -> Option<&'a wgpu::Buffer> {
        let (_, t) = self.targets.as_ref().filter(|_| self.ran)?;
        Some(t.shown.as_ref().unwrap_or(hdr))
    }

    /// Drop the textures (the upscaler keeps its own still-view mean); `memory` forgets them
    /// where they are the frame targets' of `epoch`. True if there were any.
    pub fn release(&mut self, memory: &mut GpuMemory, epoch: u64) -> bool {
        self.ran = false;
        let Some((e, _)) = self.targets.take() else { return false };
        if e == epoch {
            memory.forget("converge/");
        }
        true
    }

    /// Note that this frame does not run the stage (TAA's image is shown).
    pub fn skip(&mut self) {
        self.ran = false;
    }

    /// Record the mean's update and the image shown, from `taa_image` (TAA's output).
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        io: &FrameIo,
        taa_image: &wgpu::Buffer,
        params: &ConvergeParams,
        parity: Parity,
    ) -> Result<()> {
        self.ran = false;
        let gpu = rec.gpu;
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        let (_, t) = self
            .targets
            .as_ref()
            .context("the still-view mean records before its textures exist")?;
        let cv = &self.params;
        let mean_bindings = |p: Parity| {
            io.bindings()
                .buffer("cv", cv)
                .texture("mean_history", &t.mean.history(p).1)
                .texture("m2_history", &t.m2.history(p).1)
                .texture("out_mean", &t.mean.output(p).1)
                .texture("out_m2", &t.m2.output(p).1)
        };
        let shown_bindings = |p: Parity| {
            io.bindings()
                .buffer("cv", cv)
                .texture("mean", &t.mean.output(p).1)
                .texture("m2", &t.m2.output(p).1)
                .buffer("taa_image", taa_image)
                .buffer("shown", t.shown.as_ref().unwrap_or(io.hdr))
        };
        let programs = made(&mut self.programs, || {
            let glossy = io.trace.glossy.is_some();
            let offered = mean_bindings(Parity::default());
            let mean = ChainStage::new(gpu, MEAN, &modules(glossy, true), "main", &offered)?;
            let offered = shown_bindings(Parity::default());
            let shown = ChainStage::new(gpu, LABEL, &modules(glossy, false), "main", &offered)?;
            Ok(Programs { mean, shown })
        })?;
        programs.mean.record(rec, key, parity, io.size, mean_bindings)?;
        programs.shown.record(rec, key, parity, io.size, shown_bindings)?;
        self.ran = true;
        Ok(())
    }
}

/// The modules of the mean's pass (`mean`) or of the image shown, with the scene's glossy light
/// or without.
pub fn modules(glossy: bool, mean: bool) -> Vec<&'static str> {
    const MEAN_PASS: [&str; 3] =
        ["taa/converge_common.wgsl", super::composite::REMODULATE, "taa/converge_mean.wgsl"];
    const SHOWN_PASS: [&str; 2] = ["taa/converge_common.wgsl", "taa/converge.wgsl"];
    super::composite::modules(glossy, if mean { &MEAN_PASS } else { &SHOWN_PASS })
}
