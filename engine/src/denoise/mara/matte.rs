//! The matte denoise chain of Mara et al. 2017 (§3.4, Figure 2 stages 3-7), one compute pass per
//! stage (shaders/matte/*.wgsl): `matte/temporal` -> `matte/history_bilateral` (into the history
//! only) -> `matte/disocclusion_h`, `matte/disocclusion_v` -> `matte/firefly` -> `matte/bilateral`.
//! Each stage can be switched off at run time ([`MatteSettings`]); it then passes its input on.

use crate::gpu::{Bindings, Gpu, GpuMemory, Parity, PingPong, Recorder, Tex};
use crate::passes::chain::ChainStage;
use crate::passes::io::FrameIo;
use crate::settings::{MatteSettings, STILL_FRAMES_MAX};
use anyhow::Result;
use bytemuck::{Pod, Zeroable};

const RGBA16F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Histories: a blend that weighs the new frame 1 / 64 cannot move a half float by less than
/// 32 of its steps (1.5% of the value), so a 16-bit history stalls once it is close.
const RGBA32F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
const R32F: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
const R32U: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// Mirror of `MatteParams` in shaders/matte/common.wgsl: Mara's matte chain's uniform (the
/// glossy chain reads its bilateral weights). What every temporal stage shares (the cameras,
/// the reprojection's thresholds, history validity) is the frame's ([`crate::frame::FrameParams`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MatteParams {
    pub stages: u32,
    pub taps: u32,
    pub max_radius_px: f32,
    pub hysteresis: f32,
    pub clamp_sigma: f32,
    pub history_radius_px: f32,
    pub disocclusion_radius_px: f32,
    pub low_confidence_multiplier: f32,
    pub normal_power: f32,
    pub plane_sigma_px: f32,
    pub rotation: f32,
    /// [`MatteSettings::history_full_frames`].
    pub history_full_frames: f32,
    /// [`MatteSettings::min_radius_fraction`] in pixels.
    pub min_radius_px: f32,
    /// [`MatteSettings::edge_stop_sigmas`].
    pub edge_stop_sigmas: f32,
    /// Cosine of [`MatteSettings::reprojection_normal_degrees`].
    pub reprojection_min_cos: f32,
    /// [`MatteSettings::resampled_history_frames`].
    pub resampled_history_frames: f32,
    /// [`MatteSettings::still_frames`].
    pub still_frames: f32,
    /// [`MatteSettings::edge_stop_full_frames`].
    pub edge_stop_full_frames: f32,
    /// [`MatteSettings::still_normal_degrees`] as a cosine (-2: off).
    pub still_normal_min_cos: f32,
    /// [`MatteSettings::tap_sigma_fraction`].
    pub tap_sigma: f32,
}

impl MatteParams {
    /// The matte chain's parameters at a frame `width` pixels wide, frame `frame`.
    pub fn new(s: &MatteSettings, width: u32, frame: u32) -> MatteParams {
        let w = width as f32;
        MatteParams {
            stages: s.stage_bits(),
            taps: s.taps.clamp(1, 256),
            max_radius_px: (s.max_radius_fraction * w).max(0.0),
            hysteresis: s.hysteresis.clamp(0.0, 1.0),
            clamp_sigma: s.clamp_sigma.max(0.0),
            history_radius_px: (s.history_diameter_fraction * w * 0.5).max(0.0),
            disocclusion_radius_px: (s.disocclusion_fraction * w).clamp(1.0, 512.0),
            low_confidence_multiplier: s.low_confidence_multiplier.max(0.0),
            normal_power: s.normal_power.max(0.0),
            plane_sigma_px: s.plane_sigma_px.max(1e-3),
            // Golden-ratio steps: consecutive frames' tap patterns interleave.
            rotation: (frame as f32 * 2.399_963).rem_euclid(std::f32::consts::TAU),
            history_full_frames: s.history_full_frames.max(0.0),
            min_radius_px: (s.min_radius_fraction * w)
                .clamp(0.0, (s.max_radius_fraction * w).max(0.0)),
            edge_stop_sigmas: s.edge_stop_sigmas.max(0.0),
            reprojection_min_cos: crate::passes::io::normal_test_cos(s.reprojection_normal_degrees),
            resampled_history_frames: s.resampled_history_frames.clamp(0.0, 1024.0),
            still_frames: s.still_frames.clamp(0.0, STILL_FRAMES_MAX),
            edge_stop_full_frames: s.edge_stop_full_frames.clamp(0.0, STILL_FRAMES_MAX),
            still_normal_min_cos: crate::passes::io::normal_test_cos(s.still_normal_degrees),
            tap_sigma: s.tap_sigma_fraction.clamp(0.0, 4.0),
        }
    }
}

/// Pixels whose matte history the temporal stage rejected this frame (disoccluded, or a
/// confidence under h / 2: the low two flag bits of a `matte/reason` texel, as
/// shaders/matte/temporal.wgsl writes them; the history length sits above the 8 flag bits),
/// from that texture's bytes as `Renderer::read_texture` returns them.
pub fn history_rejected(reason: &[u8]) -> Vec<bool> {
    reason.chunks_exact(4).map(|t| u32::from_le_bytes([t[0], t[1], t[2], t[3]]) & 3 != 0).collect()
}

/// Per-pixel textures of the chain, 76 bytes per pixel.
pub struct MatteTargets {
    pub history: PingPong<Tex>,
    pub temporal: (wgpu::Texture, wgpu::TextureView),
    pub reason: (wgpu::Texture, wgpu::TextureView),
    pub min: (wgpu::Texture, wgpu::TextureView),
    pub radius: (wgpu::Texture, wgpu::TextureView),
    pub median: (wgpu::Texture, wgpu::TextureView),
    pub denoised: (wgpu::Texture, wgpu::TextureView),
}

impl MatteTargets {
    pub fn new(device: &wgpu::Device, mem: &mut GpuMemory, size: (u32, u32)) -> MatteTargets {
        let rw = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let mut t = |label: &str, f| mem.texture(device, label, size, f, rw);
        let history = PingPong::new(|i| t(&format!("matte/history {i}"), RGBA32F));
        let temporal = t("matte/temporal", RGBA32F);
        let reason = t("matte/reason", R32U);
        let min = t("matte/disocclusion min", R32F);
        let radius = t("matte/radius", R32F);
        let median = t("matte/firefly", RGBA16F);
        let denoised = t("matte/bilateral", RGBA16F);
        MatteTargets { history, temporal, reason, min, radius, median, denoised }
    }
}

/// Everything a stage may bind: the frame's I/O, the chain's `MatteParams` and textures.
pub struct ChainInputs<'a> {
    pub io: FrameIo<'a>,
    pub params: &'a wgpu::Buffer,
    pub matte: &'a MatteTargets,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Temporal,
    HistoryBilateral,
    MinH,
    MinV,
    Firefly,
    Bilateral,
}

const STAGES: [(Kind, &str); 6] = [
    (Kind::Temporal, "matte/temporal"),
    (Kind::HistoryBilateral, "matte/history_bilateral"),
    (Kind::MinH, "matte/disocclusion_h"),
    (Kind::MinV, "matte/disocclusion_v"),
    (Kind::Firefly, "matte/firefly"),
    (Kind::Bilateral, "matte/bilateral"),
];

fn bindings<'a>(kind: Kind, i: &ChainInputs<'a>, parity: Parity) -> Bindings<'a> {
    let m = i.matte;
    let b = i.io.bindings().buffer("mp", i.params);
    match kind {
        Kind::Temporal => b
            .texture("history", &m.history.history(parity).1)
            .texture("out_temporal", &m.temporal.1)
            .texture("out_reason", &m.reason.1)
            // c alone, for the disocclusion minimum, in the radius texture that stage
            // rewrites after reading it.
            .texture("out_confidence", &m.radius.1),
        Kind::HistoryBilateral => b
            .texture("filter_in", &m.temporal.1)
            .texture("reason_in", &m.reason.1)
            .texture("out_history", &m.history.output(parity).1),
        Kind::MinH => b
            .texture("filter_in", &m.temporal.1)
            .texture("min_in", &m.radius.1)
            .texture("out_min", &m.min.1),
        Kind::MinV => b
            .texture("filter_in", &m.temporal.1)
            .texture("min_in", &m.min.1)
            .texture("out_min", &m.radius.1),
        Kind::Firefly => b.texture("filter_in", &m.temporal.1).texture("out_median", &m.median.1),
        Kind::Bilateral => b
            .texture("filter_in", &m.median.1)
            .texture("radius_in", &m.radius.1)
            .texture("reason_in", &m.reason.1)
            .texture("out_matte", &m.denoised.1),
    }
}

/// `uncertainty`: the module that gives stage 7's edge-stops the features' variances
/// (realtime/uncertainty.wgsl where the frame offers the pre-filter's, else
/// realtime/uncertainty_none.wgsl); stage 4, in the history loop, takes none.
fn modules(
    kind: Kind,
    motion: crate::gpu::Motion,
    prior: &'static str,
    uncertainty: &'static str,
) -> Vec<&'static str> {
    let mut m = vec![
        "common/math.wgsl",
        "realtime/frame.wgsl",
        "realtime/gbuffer_in.wgsl",
        "common/bilinear.wgsl",
        "realtime/reproject.wgsl",
        "matte/common.wgsl",
    ];
    m.push(motion.module());
    m.extend(match kind {
        Kind::Temporal => vec![prior, "matte/temporal.wgsl"],
        Kind::HistoryBilateral => vec![
            "realtime/uncertainty_none.wgsl",
            "common/feature_weight.wgsl",
            "matte/sparse_bilateral.wgsl",
            "matte/history_bilateral.wgsl",
        ],
        Kind::MinH | Kind::MinV => vec!["matte/disocclusion.wgsl"],
        Kind::Firefly => vec!["matte/firefly.wgsl"],
        Kind::Bilateral => vec![
            uncertainty,
            "common/feature_weight.wgsl",
            "matte/sparse_bilateral.wgsl",
            "matte/bilateral.wgsl",
        ],
    });
    m
}

pub struct MatteChain {
    stages: Vec<(Kind, ChainStage)>,
    /// The temporal stage reads the radiance cache's prior (made for a frame that offers one).
    pub prior: bool,
    /// Stage 7 weighs the features against the pre-filter's variances (made for a frame that
    /// offers them).
    pub uncertain: bool,
}

impl MatteChain {
    /// The stages' pipelines, for hot reload.
    pub fn pipelines(&mut self) -> impl Iterator<Item = &mut dyn crate::shader::Reload> {
        self.stages.iter_mut().map(|(_, s)| &mut s.pipeline as &mut dyn crate::shader::Reload)
    }

    /// Drop the stages' bind groups: the textures they bind were released.
    pub fn release_groups(&mut self) {
        self.stages.iter_mut().for_each(|(_, s)| s.release_groups());
    }

    pub fn new(gpu: &Gpu, i: &ChainInputs, motion: crate::gpu::Motion) -> Result<MatteChain> {
        let mut stages = vec![];
        let prior = crate::passes::cache::prior_module(&i.io);
        for (kind, label) in STAGES {
            let entry = match kind {
                Kind::MinH => "min_h",
                Kind::MinV => "min_v",
                _ => "main",
            };
            stages.push((
                kind,
                ChainStage::new(
                    gpu,
                    label,
                    &modules(kind, motion, prior, i.io.uncertainty_module()),
                    entry,
                    &bindings(kind, i, Parity::default()),
                )?,
            ));
        }
        Ok(MatteChain {
            stages,
            prior: i.io.cache_prior.is_some(),
            uncertain: i.io.feature_uncertainty.is_some(),
        })
    }

    /// Record stages 3-7.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        i: &ChainInputs,
        parity: Parity,
    ) -> Result<()> {
        for (kind, s) in self.stages.iter_mut() {
            s.record(rec, key, parity, i.io.size, |p| bindings(*kind, i, p))?;
        }
        Ok(())
    }
}
