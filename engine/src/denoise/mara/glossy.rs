//! The glossy denoise chain: Mara et al. 2017 §3.4 stages 8-10 with the reflection reprojection
//! and neighbourhood clipping of Voorhuis §4, one compute pass per stage (shaders/glossy/*.wgsl):
//! `glossy/motion` (reflection motion vectors) -> `glossy/prefilter_h`, `glossy/prefilter_v`
//! (the clip's pre-blurred neighbourhood) -> `glossy/temporal` -> `glossy/bilateral_h`,
//! `glossy/bilateral_v`. The composite then remodulates the output with F(w_s).
//! Runs in scenes with a specular lobe when the denoiser is on; [`GlossySettings`] switches it.

use crate::gpu::{Bindings, Gpu, GpuMemory, Parity, PingPong, Recorder, Tex};
use crate::passes::chain::ChainStage;
use crate::passes::io::FrameIo;
use crate::settings::{GlossySettings, MAX_GLOSSY_SIGMA_PX, ReflectionMv, STILL_FRAMES_MAX};
use anyhow::Result;
use bytemuck::{Pod, Zeroable};

const RGBA16F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const RGBA32F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// Mirror of `GlossyParams` in shaders/glossy/common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GlossyParams {
    pub stages: u32,
    pub mode: u32,
    pub initial_step: u32,
    pub max_search_steps: u32,
    pub roughness_threshold: f32,
    pub mirror_roughness: f32,
    pub clip_roughness: f32,
    pub hysteresis: f32,
    pub d0_px: f32,
    pub d1_px: f32,
    pub sigma_scale: f32,
    pub sigma_exponent: f32,
    pub sigma_epsilon_px: f32,
    pub omega: f32,
    pub roughness_sigma: f32,
    pub far: f32,
    pub max_sigma_px: f32,
    pub representative_traced: u32,
    pub sigma_full_frames: f32,
    pub static_view: u32,
    /// Cosine of [`GlossySettings::reprojection_normal_degrees`].
    pub reprojection_min_cos: f32,
    /// [`GlossySettings::resampled_history_frames`].
    pub resampled_history_frames: f32,
    /// [`GlossySettings::still_frames`].
    pub still_frames: f32,
}

impl GlossyParams {
    /// `extent`: the scene's bounding-box diagonal (an escaped reflection stands at 4 extents).
    /// `static_view`: neither the camera nor an object moved since the previous frame.
    pub fn new(s: &GlossySettings, extent: f32, static_view: bool) -> GlossyParams {
        GlossyParams {
            stages: s.stage_bits(),
            mode: match s.reflection_mv {
                ReflectionMv::Primary => 0,
                ReflectionMv::Virtual => 1,
                ReflectionMv::Diamond => 2,
            },
            initial_step: s.initial_step.clamp(1, 64),
            max_search_steps: s.max_search_steps.clamp(1, 256),
            roughness_threshold: s.roughness_threshold,
            mirror_roughness: s.mirror_roughness,
            clip_roughness: s.clip_roughness,
            hysteresis: s.hysteresis.clamp(0.0, 1.0),
            d0_px: s.d0_px.max(0.0),
            d1_px: s.d1_px.max(s.d0_px + 1e-3),
            sigma_scale: s.sigma_scale.max(0.0),
            sigma_exponent: s.sigma_exponent,
            sigma_epsilon_px: s.sigma_epsilon_px.max(0.0),
            omega: s.ray_differential_omega.max(1e-3),
            roughness_sigma: s.roughness_sigma.max(1e-4),
            far: (4.0 * extent).max(1e-3),
            max_sigma_px: MAX_GLOSSY_SIGMA_PX,
            representative_traced: s.trace_representative_ray as u32,
            sigma_full_frames: s.sigma_full_frames,
            static_view: static_view as u32,
            reprojection_min_cos: crate::passes::io::normal_test_cos(s.reprojection_normal_degrees),
            resampled_history_frames: s.resampled_history_frames.clamp(0.0, 1024.0),
            still_frames: s.still_frames.clamp(0.0, STILL_FRAMES_MAX),
        }
    }
}

/// What the reflection-motion program (shaders/glossy/motion.wgsl) is made for: two settings
/// that are constants of its program (its prelude) rather than uniforms, and a frame whose
/// settings want another makes the stage again. On lavapipe the stage paid for both switched-off
/// bodies as uniforms: eq. (5)'s distance behind an early return in each of the search's taps, and
/// the brute-force search. The level at 640x360 (SVGF, 8 still frames, two interleaved runs
/// each): the stage took 121 and 124 ms with them as uniforms, 43 and 48 ms as constants. Images
/// are the same to the bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MotionProgram {
    /// [`GlossySettings::trace_representative_ray`]: the search measures every lobe's distance by
    /// eq. (1) between traced hits; off, glossy lobes by eq. (5).
    pub traced_hits: bool,
    /// [`GlossySettings::reference_search_radius`] (at most 256; 0: no brute-force search).
    pub reference_radius: u32,
}

impl MotionProgram {
    pub fn of(s: &GlossySettings) -> MotionProgram {
        MotionProgram {
            traced_hits: s.trace_representative_ray,
            reference_radius: s.reference_search_radius.min(256),
        }
    }

    /// The constants glossy/motion.wgsl reads.
    pub fn prelude(self) -> String {
        format!(
            "const TRACED_HITS: bool = {};\nconst REFERENCE_RADIUS: i32 = {};\n",
            self.traced_hits, self.reference_radius
        )
    }
}

/// Per-pixel textures of the glossy chain (made with the denoiser's other targets), 120 bytes.
pub struct GlossyChainTargets {
    /// Representative hits (eq. 4) of this frame and the previous one, by parity.
    pub hit: PingPong<Tex>,
    pub motion: (wgpu::Texture, wgpu::TextureView),
    pub search: (wgpu::Texture, wgpu::TextureView),
    /// The pre-blurred neighbourhood the temporal clips to.
    pub neighbourhood: (wgpu::Texture, wgpu::TextureView),
    /// The prefilter's and the bilateral's horizontal pass (its alpha: sigma).
    pub scratch: (wgpu::Texture, wgpu::TextureView),
    pub history: PingPong<Tex>,
    pub info: (wgpu::Texture, wgpu::TextureView),
    /// The chain's output: remodulated glossy light for the composite.
    pub denoised: (wgpu::Texture, wgpu::TextureView),
}

impl GlossyChainTargets {
    pub fn new(d: &wgpu::Device, mem: &mut GpuMemory, size: (u32, u32)) -> GlossyChainTargets {
        let rw = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let mut t = |label: &str, f| mem.texture(d, label, size, f, rw);
        GlossyChainTargets {
            hit: PingPong::new(|i| t(&format!("glossy/hit {i}"), RGBA32F)),
            motion: t("glossy/motion", RGBA32F),
            search: t("glossy/search", RGBA16F),
            neighbourhood: t("glossy/neighbourhood", RGBA16F),
            scratch: t("glossy/scratch", RGBA16F),
            history: PingPong::new(|i| t(&format!("glossy/history {i}"), RGBA32F)),
            info: t("glossy/info", RGBA16F),
            denoised: t("glossy/denoised", RGBA16F),
        }
    }
}

/// Everything a glossy stage may bind.
pub struct GlossyInputs<'a> {
    /// The frame's I/O, with the previous G-buffer (the chain asks for it).
    pub io: FrameIo<'a>,
    /// Mara's matte uniform ([`super::matte::MatteParams`]): the bilateral weights.
    pub matte: &'a wgpu::Buffer,
    pub params: &'a wgpu::Buffer,
    pub glossy: &'a GlossyChainTargets,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Motion,
    PrefilterH,
    PrefilterV,
    Temporal,
    BilateralH,
    BilateralV,
}

const STAGES: [(Kind, &str, &str, &str); 6] = [
    (Kind::Motion, "glossy/motion", "glossy/motion.wgsl", "main"),
    (Kind::PrefilterH, "glossy/prefilter_h", "glossy/prefilter.wgsl", "pre_h"),
    (Kind::PrefilterV, "glossy/prefilter_v", "glossy/prefilter.wgsl", "pre_v"),
    (Kind::Temporal, "glossy/temporal", "glossy/temporal.wgsl", "main"),
    (Kind::BilateralH, "glossy/bilateral_h", "glossy/bilateral.wgsl", "bilateral_h"),
    (Kind::BilateralV, "glossy/bilateral_v", "glossy/bilateral.wgsl", "bilateral_v"),
];

fn bindings<'a>(kind: Kind, i: &GlossyInputs<'a>, parity: Parity) -> Bindings<'a> {
    let g = i.glossy;
    let b = i.io.bindings().buffer("mp", i.matte).buffer("gp", i.params);
    match kind {
        Kind::Motion => b
            .texture("prev_hit", &g.hit.history(parity).1)
            .texture("out_motion", &g.motion.1)
            .texture("out_search", &g.search.1)
            .texture("out_hit", &g.hit.output(parity).1),
        Kind::PrefilterH => b.texture("src", &g.neighbourhood.1).texture("dst", &g.scratch.1),
        Kind::PrefilterV => b.texture("src", &g.scratch.1).texture("dst", &g.neighbourhood.1),
        Kind::Temporal => b
            .texture("history", &g.history.history(parity).1)
            .texture("prev_hit", &g.hit.history(parity).1)
            .texture("neighbourhood", &g.neighbourhood.1)
            .texture("dst", &g.history.output(parity).1)
            .texture("motion", &g.motion.1)
            .texture("out_info", &g.info.1),
        Kind::BilateralH => {
            b.texture("src", &g.history.output(parity).1).texture("dst", &g.scratch.1)
        }
        Kind::BilateralV => b.texture("src", &g.scratch.1).texture("dst", &g.denoised.1),
    }
}

/// The modules of a glossy stage's program.
pub fn modules(stage: &'static str, motion: crate::gpu::Motion) -> Vec<&'static str> {
    let mut m = vec![
        "common/math.wgsl",
        "realtime/frame.wgsl",
        "realtime/gbuffer_in.wgsl",
        "realtime/glossy_in.wgsl",
        "common/bilinear.wgsl",
        "realtime/reproject.wgsl",
        "matte/common.wgsl",
        "glossy/common.wgsl",
    ];
    m.push(motion.module());
    if stage == "glossy/motion.wgsl" {
        m.push("glossy/diamond.wgsl");
    }
    if stage == "glossy/temporal.wgsl" {
        m.push("glossy/reproject.wgsl");
    }
    m.push(stage);
    m
}

pub struct GlossyChain {
    stages: Vec<(Kind, ChainStage)>,
    /// What the motion stage's program was made for.
    pub motion_program: MotionProgram,
    /// The bilateral reads the pre-filter's feature uncertainty (made for a frame that offers
    /// it).
    pub uncertain: bool,
}

impl GlossyChain {
    /// The stages' pipelines, for hot reload.
    pub fn pipelines(&mut self) -> impl Iterator<Item = &mut dyn crate::shader::Reload> {
        self.stages.iter_mut().map(|(_, s)| &mut s.pipeline as &mut dyn crate::shader::Reload)
    }

    /// Drop the stages' bind groups: the textures they bind were released.
    pub fn release_groups(&mut self) {
        self.stages.iter_mut().for_each(|(_, s)| s.release_groups());
    }

    pub fn new(
        gpu: &Gpu,
        i: &GlossyInputs,
        motion: crate::gpu::Motion,
        motion_program: MotionProgram,
    ) -> Result<GlossyChain> {
        let mut stages = vec![];
        for (kind, label, file, entry) in STAGES {
            let mut m = modules(file, motion);
            // The bilateral's sigma takes the circle of confusion where the pre-filter measured
            // one (glossy/bilateral.wgsl: sigma_at).
            if matches!(kind, Kind::BilateralH | Kind::BilateralV) {
                m.insert(m.len() - 1, i.io.uncertainty_module());
            }
            let prelude = match kind {
                Kind::Motion => motion_program.prelude(),
                _ => String::new(),
            };
            let offered = bindings(kind, i, Parity::default());
            stages
                .push((kind, ChainStage::with_prelude(gpu, label, &prelude, &m, entry, &offered)?));
        }
        Ok(GlossyChain { stages, motion_program, uncertain: i.io.feature_uncertainty.is_some() })
    }

    /// Record the chain. The prefilter runs only when the clip uses it.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        i: &GlossyInputs,
        parity: Parity,
        settings: &GlossySettings,
    ) -> Result<()> {
        let size = i.io.size;
        let clip = settings.temporal && settings.clipping;
        for (kind, s) in self
            .stages
            .iter_mut()
            .filter(|(k, _)| clip || !matches!(k, Kind::PrefilterH | Kind::PrefilterV))
        {
            s.record(rec, key, parity, size, |p| bindings(*kind, i, p))?;
        }
        Ok(())
    }
}
