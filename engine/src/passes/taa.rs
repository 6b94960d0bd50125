//! `taa`: temporal anti-aliasing of the composited image (shaders/taa/taa.wgsl), a stage of its
//! own after any denoiser's composite. Where the denoiser offers the light it accumulates
//! ([`TaaFollow`]), a settled pixel follows that light instead of averaging it again
//! (`TaaSettings::current_light`, `current_glossy`); otherwise it is a plain TAA. Its settings
//! are [`crate::settings::TaaSettings`]; its output, `taa/final`, is the image shown.

use super::chain::ChainStage;
use super::io::FrameIo;
use crate::gpu::{Bindings, Gpu, GpuMemory, Parity, PingPong, Recorder, Tex};
use crate::settings::TaaSettings;
use anyhow::{Context, Result};
use bytemuck::{Pod, Zeroable};

pub const LABEL: &str = "taa";
const RGBA32F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
const RGBA16F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// What a denoiser offers TAA to follow (all this frame's, parity resolved).
#[derive(Clone, Copy, Default)]
pub struct TaaFollow<'a> {
    /// The matte light to follow and its state.
    pub matte: Option<MatteFollow<'a>>,
    pub glossy: Option<GlossyFollow<'a>>,
}

/// The matte light TAA may follow.
#[derive(Clone, Copy)]
pub struct MatteFollow<'a> {
    /// The light TAA follows, before the matte factor: Mara's matte temporal output (before
    /// its spatial stages), SVGF's and the progressive filter's shown light.
    pub light: &'a wgpu::TextureView,
    /// Whether the pixel's history continues, and its length, in the form `form` names.
    pub state: &'a wgpu::TextureView,
    pub form: MatteState,
}

/// The form of a followed matte light's state texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MatteState {
    /// `matte/reason`'s: REASON_* flags in the low 8 bits, the history length above
    /// (taa/matte.wgsl).
    Reason,
    /// The progressive filter's moments texel, the frames since the history restarted in w
    /// (taa/matte_moments.wgsl).
    Moments,
}

/// The glossy light TAA may follow (taa/glossy.wgsl).
#[derive(Clone, Copy)]
pub struct GlossyFollow<'a> {
    /// The glossy light the composite used (remodulated), and the temporal's output this frame
    /// and last frame (divided by the mirror demodulation).
    pub denoised: &'a wgpu::TextureView,
    pub temporal: &'a wgpu::TextureView,
    pub previous: &'a wgpu::TextureView,
    /// Continuity and history length (info.z, info.w of shaders/glossy/temporal.wgsl).
    pub info: &'a wgpu::TextureView,
    /// `GlossyParams`, for the demodulation.
    pub params: &'a wgpu::Buffer,
}

/// TAA's per-pixel textures: its history (with its length), the averaged matte and glossy
/// factors and residual it follows the chains with, the glossy term its history holds, and the
/// image shown. 152 bytes per pixel.
struct TaaTargets {
    history: PingPong<Tex>,
    material: PingPong<Tex>,
    residual: PingPong<Tex>,
    glossy: PingPong<Tex>,
    /// Three floats a pixel in storage buffers: a fifth storage texture would pass WebGPU's
    /// default limit of four per stage, and unpacking half floats needs a shader capability.
    glossy_term: PingPong<wgpu::Buffer>,
    final_image: wgpu::Buffer,
}

impl TaaTargets {
    fn new(device: &wgpu::Device, mem: &mut GpuMemory, size: (u32, u32)) -> TaaTargets {
        let rw = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let mut pair = |l: &str, f| {
            PingPong::new(|i| mem.texture(device, &format!("taa/{l} {i}"), size, f, rw))
        };
        // The glossy factor's average in half floats (FLIP against 32-bit at most 0.0011); the
        // material and the residual reach the image directly and stay 32-bit (docs/decisions.md).
        let (history, material, residual, glossy) = (
            pair("history", RGBA32F),
            pair("material", RGBA32F),
            pair("residual", RGBA32F),
            pair("glossy", RGBA16F),
        );
        let usage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        let pixels = size.0 as u64 * size.1 as u64;
        let glossy_term = PingPong::new(|i| {
            mem.buffer(device, &format!("taa/glossy term {i}"), pixels * 12, usage)
        });
        let final_image = mem.buffer(device, "taa/final", pixels * 16, usage);
        TaaTargets { history, material, residual, glossy, glossy_term, final_image }
    }
}

/// What TAA reads of the denoiser's glossy light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum GlossyInput {
    /// None shown (a scene without glossy buffers): the glossy term is zero.
    None,
    /// The light the composite showed, for the glossy term (`TaaSettings::moving_glossy`).
    Shown,
    /// That and the chain's temporal light to follow ([`GlossyFollow`]).
    Follow,
}

/// Mirror of `TaaParams` in shaders/taa/taa.wgsl: TAA's own uniform (the cameras and the
/// reprojection test are the frame's).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TaaParams {
    /// [`TaaSettings::enabled`]: 0 passes the composite on.
    pub enabled: u32,
    pub alpha: f32,
    /// [`TaaSettings::still_frames`] (0: the still view blends at `alpha` too).
    pub still_frames: f32,
    pub resampled_frames: f32,
    pub display_ratio: f32,
    pub current_light: f32,
    pub current_glossy: f32,
    pub moving_glossy: u32,
}

impl TaaParams {
    pub fn new(s: &TaaSettings) -> TaaParams {
        TaaParams {
            enabled: s.enabled as u32,
            alpha: s.alpha.clamp(0.01, 1.0),
            still_frames: s.still_frames.clamp(0.0, 1024.0),
            resampled_frames: s.resampled_frames.clamp(0.0, 1024.0),
            display_ratio: s.display_ratio.clamp(0.0, 1024.0),
            current_light: s.current_light.clamp(0.0, 1.0),
            current_glossy: s.current_glossy.clamp(0.0, 1.0),
            moving_glossy: s.moving_glossy as u32,
        }
    }
}

pub struct TaaStage {
    params: wgpu::Buffer,
    targets: Option<(u64, TaaTargets)>,
    /// One program per (the matte state's form where it follows the matte light, what it reads
    /// of the glossy light), made on first use.
    programs: Vec<((Option<MatteState>, GlossyInput), ChainStage)>,
    motion: crate::gpu::Motion,
}

impl TaaStage {
    pub fn new(gpu: &Gpu, memory: &mut GpuMemory, motion: crate::gpu::Motion) -> TaaStage {
        let u = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        let params = memory.buffer(&gpu.device, "taa/params", size_of::<TaaParams>() as u64, u);
        TaaStage { params, targets: None, programs: vec![], motion }
    }

    pub fn pipelines(&mut self) -> impl Iterator<Item = &mut dyn crate::shader::Reload> {
        self.programs.iter_mut().map(|(_, s)| &mut s.pipeline as &mut dyn crate::shader::Reload)
    }

    /// Make the textures for the frame targets of `epoch` (once per size); true if it did.
    pub fn allocate(
        &mut self,
        gpu: &Gpu,
        memory: &mut GpuMemory,
        size: (u32, u32),
        epoch: u64,
    ) -> bool {
        let make = || TaaTargets::new(&gpu.device, memory, size);
        super::chain::made_for_epoch(&mut self.targets, epoch, make)
    }

    /// Drop the textures (the upscaler runs in TAA's place); `memory` forgets them where they
    /// are the frame targets' of `epoch`. True if there were any.
    pub fn release(&mut self, memory: &mut GpuMemory, epoch: u64) -> bool {
        let Some((e, _)) = self.targets.take() else { return false };
        if e == epoch {
            memory.forget("taa/");
        }
        true
    }

    /// The image after TAA (once it ran).
    pub fn output(&self) -> Option<&wgpu::Buffer> {
        self.targets.as_ref().map(|(_, t)| &t.final_image)
    }

    /// Record TAA of `io.hdr` with `params`.
    /// `key` changes whenever a bound resource may have (scene, targets, denoiser).
    /// `follow(p)`: what TAA follows at history parity p, and the glossy light the composite
    /// showed.
    pub fn record<'a>(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        io: &FrameIo<'a>,
        follow: impl Fn(Parity) -> (TaaFollow<'a>, Option<&'a wgpu::TextureView>),
        params: &TaaParams,
        parity: Parity,
    ) -> Result<()> {
        let gpu = rec.gpu;
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        let (_, t) = self.targets.as_ref().context("TAA records before its textures exist")?;
        let (f, shown) = follow(parity);
        let glossy = match (f.glossy.is_some(), shown.is_some()) {
            (true, _) => GlossyInput::Follow,
            (false, true) => GlossyInput::Shown,
            (false, false) => GlossyInput::None,
        };
        let variant = (f.matte.map(|m| m.form), glossy);
        let bindings = |p: Parity| {
            let (f, shown) = follow(p);
            taa_bindings(io, t, &self.params, &f, shown, p)
        };
        let i = match self.programs.iter().position(|(v, _)| *v == variant) {
            Some(i) => i,
            None => {
                let modules = modules(variant, self.motion);
                let offered = bindings(Parity::default());
                let stage = ChainStage::new(gpu, LABEL, &modules, "main", &offered)?;
                self.programs.push((variant, stage));
                self.programs.len() - 1
            }
        };
        let stage = &mut self.programs[i].1;
        stage.record(rec, key, parity, io.size, bindings)
    }
}

fn taa_bindings<'a>(
    io: &FrameIo<'a>,
    t: &'a TaaTargets,
    params: &'a wgpu::Buffer,
    follow: &TaaFollow<'a>,
    shown_glossy: Option<&'a wgpu::TextureView>,
    parity: Parity,
) -> Bindings<'a> {
    let mut b = io
        .bindings()
        .buffer("taa_params", params)
        .buffer("hdr", io.hdr)
        .buffer("final_image", &t.final_image)
        .texture("history", &t.history.history(parity).1)
        .texture("out_history", &t.history.output(parity).1)
        .texture("material_history", &t.material.history(parity).1)
        .texture("out_material", &t.material.output(parity).1)
        .texture("residual_history", &t.residual.history(parity).1)
        .texture("out_residual", &t.residual.output(parity).1)
        .texture("glossy_factor_history", &t.glossy.history(parity).1)
        .texture("out_glossy_factor", &t.glossy.output(parity).1)
        .buffer("glossy_term_history", t.glossy_term.history(parity))
        .buffer("out_glossy_term", t.glossy_term.output(parity));
    if let Some(m) = follow.matte {
        let state = match m.form {
            MatteState::Reason => "matte_reason",
            MatteState::Moments => "matte_moments",
        };
        b = b.texture("matte_temporal", m.light).texture(state, m.state);
    }
    if let Some(g) = follow.glossy {
        b = b
            .texture("tr_glossy", g.denoised)
            .texture("glossy_temporal", g.temporal)
            .texture("glossy_previous", g.previous)
            .texture("glossy_info", g.info)
            .buffer("gp", g.params);
    } else if let Some(shown) = shown_glossy {
        b = b.texture("tr_glossy", shown);
    }
    b
}

fn modules(
    (matte, glossy): (Option<MatteState>, GlossyInput),
    motion: crate::gpu::Motion,
) -> Vec<&'static str> {
    let mut m = vec![
        "common/math.wgsl",
        "realtime/frame.wgsl",
        "realtime/gbuffer_in.wgsl",
        "common/bilinear.wgsl",
        "realtime/reproject.wgsl",
    ];
    m.push(motion.module());
    m.extend(match glossy {
        GlossyInput::Follow => {
            ["realtime/glossy_in.wgsl", "glossy/common.wgsl", "taa/glossy.wgsl"].as_slice()
        }
        GlossyInput::Shown => ["realtime/glossy_in.wgsl", "taa/glossy_none.wgsl"].as_slice(),
        GlossyInput::None => ["realtime/glossy_in_none.wgsl", "taa/glossy_none.wgsl"].as_slice(),
    });
    m.push("taa/glossy_term.wgsl");
    m.push(match matte {
        Some(MatteState::Reason) => "taa/matte.wgsl",
        Some(MatteState::Moments) => "taa/matte_moments.wgsl",
        None => "taa/matte_none.wgsl",
    });
    m.push("taa/history_test.wgsl");
    m.push("taa/taa.wgsl");
    m
}
