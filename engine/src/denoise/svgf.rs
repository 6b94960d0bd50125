//! SVGF: spatiotemporal variance-guided filtering (Schied et al. 2017) with the extensions of
//! Voorhuis (§4 reflections, §6 robustness), as a denoiser behind the frame's contract.
//!
//! Two signals, the matte and the glossy light (Hush's punctual direct light carries no noise
//! and bypasses every denoiser), each through its own passes (shaders/svgf/*.wgsl):
//! `svgf/temporal` (reprojection, moments, features, what TAA follows) -> `svgf/variance` (and
//! the spike cut) -> `svgf/atrous 0..4` (level 0 also writes the next frame's history) ->
//! `svgf/spread_h`/`_v` (the cut light over its surface) -> `svgf/regression` (the settled
//! light's fit) -> `svgf/final` (firefly median on the matte light, remodulation behind
//! mirrors). In scenes with a specular lobe the glossy signal first
//! runs the Mara glossy chain's `glossy/motion` (reflection motion vectors by diamond search)
//! and, for the clip, `glossy/prefilter_h`/`_v`, on SVGF's own textures. The composite and TAA
//! follow as for every denoiser. [`SvgfSettings`] switches each stage and each of Voorhuis's
//! changes.

use super::{Denoised, Denoiser, DenoiserScene, FrameContext};
use crate::gpu::{Bindings, Gpu, GpuMemory, Parity, PingPong, Recorder, Tex};
use crate::passes::chain::{ChainStage, made_for};
use crate::passes::glossy::{GlossyParams, MotionProgram};
use crate::passes::io::FrameIo;
use crate::passes::matte::DenoiseParams;
use crate::passes::taa::{MatteFollow, MatteState, TaaFollow};
use crate::settings::{FrameSettings, SvgfSettings, svgf::STILL_FRAMES_MAX};
use anyhow::{Context, Result};
use bytemuck::{Pod, Zeroable};

const RGBA16F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const RGBA32F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
const RG32F: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Float;
const LEVELS: usize = crate::settings::SVGF_MAX_LEVELS as usize;

/// The label of the glossy signal's output (what the composite reads).
pub const GLOSSY_OUTPUT: &str = "svgf/glossy out";
/// The start of the glossy signal's labels (its reflection motion's `motion`, `search`, ...).
pub const GLOSSY_PREFIX: &str = "svgf/glossy ";

/// The label of a signal's (`matte`, `glossy`) luminance moments and history length in history
/// slot 0 or 1.
pub fn moments_label(signal: &str, slot: usize) -> String {
    format!("svgf/{signal} moments {slot}")
}

/// Mirror of `SvgfParams` in shaders/svgf/common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SvgfParams {
    pub bits: u32,
    pub alpha: f32,
    pub alpha_moments: f32,
    pub sigma_l: f32,
    pub sigma_n: f32,
    pub sigma_z: f32,
    pub still_frames: f32,
    pub settled_samples: f32,
    pub settled_levels: u32,
    pub regression_radius: f32,
    pub regression_k: f32,
    pub regression_samples: f32,
    pub regression_order: f32,
    pub regression_full_samples: f32,
    pub spike_ratio: f32,
    pub _pad: u32,
}

impl SvgfParams {
    pub fn new(s: &SvgfSettings) -> SvgfParams {
        SvgfParams {
            bits: s.bits(),
            alpha: s.alpha.clamp(1e-3, 1.0),
            alpha_moments: s.alpha_moments.clamp(1e-3, 1.0),
            sigma_l: s.sigma_l.max(0.0),
            sigma_n: s.sigma_n.max(0.0),
            sigma_z: s.sigma_z.max(1e-3),
            still_frames: s.still_frames.clamp(0.0, STILL_FRAMES_MAX),
            settled_samples: s.settled_samples.max(0.0),
            settled_levels: s.settled_levels,
            regression_radius: s.regression_radius as f32,
            regression_k: s.regression_k.max(0.1),
            regression_samples: s.regression_samples.max(1.0),
            regression_order: s.regression_order.min(2) as f32,
            regression_full_samples: s.regression_full_samples.clamp(0.0, STILL_FRAMES_MAX),
            spike_ratio: s.spike_ratio.max(0.0),
            _pad: 0,
        }
    }
}

/// Mirror of `Level` in shaders/svgf/common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Level {
    step: i32,
    write_history: u32,
    index: u32,
    _pad: u32,
}

/// The previous frame's surfaces must point the same way within this angle for its light to be
/// reprojected (SVGF's normal consistency test).
const NORMAL_TEST_DEGREES: f32 = 25.0;

pub fn make(gpu: &Gpu, scene: &DenoiserScene) -> Result<Box<dyn Denoiser>> {
    let mut memory = GpuMemory::default();
    let u = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
    let d = &gpu.device;
    let sv = memory.buffer(d, "svgf/params", size_of::<SvgfParams>() as u64, u);
    let dn = memory.buffer(d, "svgf/denoise params", size_of::<DenoiseParams>() as u64, u);
    let gp = memory.buffer(d, "svgf/glossy params", size_of::<GlossyParams>() as u64, u);
    let levels = std::array::from_fn(|i| {
        let b = memory.buffer(d, &format!("svgf/level {i}"), size_of::<Level>() as u64, u);
        gpu.queue.write_buffer(
            &b,
            0,
            bytemuck::bytes_of(&Level {
                step: 1 << i,
                write_history: (i == 0) as u32,
                index: i as u32,
                _pad: 0,
            }),
        );
        b
    });
    let res = Resources { sv, dn, gp, levels, targets: None };
    Ok(Box::new(Svgf { scene: *scene, res, matte: None, glossy: None, motion: None }))
}

/// One signal's textures: 164 bytes per pixel.
pub struct SignalTargets {
    /// What the next frame reprojects, by parity: the integrated light, or the first a-trous
    /// level's output (`filtered_history`). 32-bit floats: a still view's mean of 1 / h steps
    /// would stall in 16-bit halves after about a thousand frames.
    pub history: PingPong<Tex>,
    /// Luminance moments and history length (m1, m2, h), by parity.
    pub moments: PingPong<Tex>,
    /// This frame's temporally integrated light (rgb, raw luminance), 32-bit as the history it
    /// is copied to.
    pub integrated: Tex,
    /// The variance stage's output (rgb, variance): the first a-trous level's input.
    pub variance: Tex,
    /// The light the regression's spike cut takes off each pixel (`SvgfSettings::spike_ratio`).
    pub excess: Tex,
    /// The signal's edge-stopping features packed by the variance stage for the a-trous levels
    /// (z, dz, oct normal, reach: 16 bytes per pixel; one load per tap instead of four to
    /// seven). A texture rather than a storage buffer: on lavapipe a texel load is one load per
    /// lane, a storage-buffer read at per-lane addresses a loop over the lanes.
    pub taps: Tex,
    /// The a-trous levels' ping-pong (rgb, variance).
    pub ping: Tex,
    pub pong: Tex,
    /// The final regression's output (settled light fitted, the rest the a-trous output).
    pub regressed: Tex,
    /// The spike cut's light spread over each pixel's surface (svgf/spread.wgsl): the rows'
    /// weighted sums (rgb, weight), then the mean the regression adds to its fit.
    pub spread_rows: Tex,
    pub spread: Tex,
    /// The light for the composite.
    pub out: Tex,
    /// What TAA follows of the light (matte/reason's format: flags, history length).
    pub state: Tex,
}

impl SignalTargets {
    fn new(d: &wgpu::Device, mem: &mut GpuMemory, size: (u32, u32), name: &str) -> SignalTargets {
        let rw = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST;
        let mut t = |label: &str, f| mem.texture(d, &format!("svgf/{name} {label}"), size, f, rw);
        SignalTargets {
            taps: t("taps", wgpu::TextureFormat::Rgba32Uint),
            history: PingPong::new(|i| t(&format!("history {i}"), RGBA32F)),
            moments: PingPong::new(|i| t(&format!("moments {i}"), RGBA32F)),
            integrated: t("integrated", RGBA32F),
            variance: t("variance", RGBA16F),
            excess: t("excess", RGBA16F),
            ping: t("ping", RGBA16F),
            pong: t("pong", RGBA16F),
            regressed: t("regressed", RGBA16F),
            spread_rows: t("spread rows", RGBA16F),
            spread: t("spread", RGBA16F),
            out: t("out", RGBA16F),
            state: t("state", wgpu::TextureFormat::R32Uint),
        }
    }
}

/// What the reflection motion search and the clip's neighbourhood need (glossy scenes): 72
/// bytes per pixel.
pub struct MotionTargets {
    pub hit: PingPong<Tex>,
    pub motion: Tex,
    pub search: Tex,
    pub neighbourhood: Tex,
    pub scratch: Tex,
}

pub struct SvgfTargets {
    /// Linear depth and its gradient (8 bytes per pixel).
    pub features: Tex,
    pub matte: SignalTargets,
    pub glossy: Option<(SignalTargets, MotionTargets)>,
}

impl SvgfTargets {
    pub fn new(
        d: &wgpu::Device,
        mem: &mut GpuMemory,
        size: (u32, u32),
        glossy: bool,
    ) -> SvgfTargets {
        let rw = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let features = mem.texture(d, "svgf/features", size, RG32F, rw);
        let matte = SignalTargets::new(d, mem, size, "matte");
        let glossy = glossy.then(|| {
            let signal = SignalTargets::new(d, mem, size, "glossy");
            let mut t =
                |label: &str, f| mem.texture(d, &format!("svgf/glossy {label}"), size, f, rw);
            let motion = MotionTargets {
                hit: PingPong::new(|i| t(&format!("hit {i}"), RGBA32F)),
                motion: t("motion", RGBA32F),
                search: t("search", RGBA16F),
                neighbourhood: t("neighbourhood", RGBA16F),
                scratch: t("scratch", RGBA16F),
            };
            (signal, motion)
        });
        SvgfTargets { features, matte, glossy }
    }
}

/// The modules of an SVGF program: the frame's inputs, the matte (and for the glossy signal,
/// the glossy) chain's helpers, SVGF's common code, the signal's features (stages after the
/// temporal) and the stage.
pub fn modules(stage: &'static str, glossy: bool, motion: crate::gpu::Motion) -> Vec<&'static str> {
    let mut m = vec!["common/math.wgsl", "realtime/frame.wgsl", "realtime/gbuffer_in.wgsl"];
    if glossy {
        m.push("realtime/glossy_in.wgsl");
    }
    m.extend(["common/bilinear.wgsl", "matte/common.wgsl"]);
    if glossy {
        m.push("glossy/common.wgsl");
    }
    if stage == "svgf/temporal_glossy.wgsl" {
        m.push("glossy/reproject.wgsl");
    }
    m.push(motion.module());
    m.push("svgf/common.wgsl");
    if !stage.starts_with("svgf/temporal") {
        m.push(if glossy { "svgf/features_glossy.wgsl" } else { "svgf/features_matte.wgsl" });
    }
    if stage == "svgf/regression.wgsl" {
        m.push("svgf/fit.wgsl");
    }
    if stage == "svgf/regression.wgsl" || stage == "svgf/spread.wgsl" {
        m.extend(["common/feature_weight.wgsl", "svgf/tap_weight.wgsl"]);
    }
    m.push(stage);
    m
}

/// Whether a stage reads the pre-filter's feature uncertainty where the frame offers it (takes
/// realtime/uncertainty.wgsl or uncertainty_none.wgsl before its own module): every glossy
/// stage after the temporal one (the reach takes the circle of confusion) and both signals'
/// regressions and the spike cut's spread (their edge-stops weigh the features against their
/// variances).
pub fn reads_uncertainty(stage: &str, glossy: bool) -> bool {
    (glossy && !stage.starts_with("svgf/temporal"))
        || stage == "svgf/regression.wgsl"
        || stage == "svgf/spread.wgsl"
}

/// The module that gives the a-trous stage its kernel: the radius is a constant of the
/// program so that its taps' loop unrolls (svgf/kernel_3x3.wgsl says what that saves).
pub fn kernel_module(kernel_5x5: bool) -> &'static str {
    if kernel_5x5 { "svgf/kernel_5x5.wgsl" } else { "svgf/kernel_3x3.wgsl" }
}

/// What a signal's programs are made for; a frame that wants another variant makes them again.
#[derive(Clone, Copy, PartialEq, Eq)]
struct Variant {
    /// The matte temporal reads the radiance cache's prior (a frame that offers one).
    prior: bool,
    /// The glossy reach and the regressions read the pre-filter's feature uncertainty (a frame
    /// that offers it).
    uncertain: bool,
    /// The a-trous kernel is SVGF's 5x5 (`svgf.kernel_5x5`).
    kernel_5x5: bool,
}

impl Variant {
    /// The variant signal `glossy` wants this frame: each signal reads only its own inputs.
    fn wanted(glossy: bool, io: &FrameIo, s: &SvgfSettings) -> Variant {
        Variant {
            prior: !glossy && io.cache_prior.is_some(),
            uncertain: io.feature_uncertainty.is_some(),
            kernel_5x5: s.kernel_5x5,
        }
    }
}

/// One signal's passes.
struct SignalStages {
    variant: Variant,
    temporal: ChainStage,
    variance: ChainStage,
    atrous: ChainStage,
    spread_h: ChainStage,
    spread_v: ChainStage,
    regression: ChainStage,
    last: ChainStage,
}

impl SignalStages {
    fn new(
        gpu: &Gpu,
        glossy: bool,
        motion: crate::gpu::Motion,
        offered: &Bindings,
        variant: Variant,
    ) -> Result<SignalStages> {
        let temporal =
            if glossy { "svgf/temporal_glossy.wgsl" } else { "svgf/temporal_matte.wgsl" };
        // Labels are 'static: the profiler and the pass timings key on them.
        let labels: [&'static str; 7] = if glossy {
            [
                "svgf/temporal_glossy",
                "svgf/variance_glossy",
                "svgf/atrous_glossy",
                "svgf/spread_h_glossy",
                "svgf/spread_v_glossy",
                "svgf/regression_glossy",
                "svgf/final_glossy",
            ]
        } else {
            [
                "svgf/temporal_matte",
                "svgf/variance_matte",
                "svgf/atrous_matte",
                "svgf/spread_h_matte",
                "svgf/spread_v_matte",
                "svgf/regression_matte",
                "svgf/final_matte",
            ]
        };
        let entry_stage = |label, file, entry: &str, b: &Bindings| {
            let mut m = modules(file, glossy, motion);
            if file == "svgf/atrous.wgsl" {
                m.insert(m.len() - 1, kernel_module(variant.kernel_5x5));
            }
            // The glossy light's reach (svgf/features_glossy.wgsl) takes the circle of
            // confusion where the pre-filter measured one, and the regressions weigh the
            // features against their variances.
            if reads_uncertainty(file, glossy) {
                m.insert(m.len() - 1, crate::passes::io::uncertainty_module(variant.uncertain));
            }
            ChainStage::new(gpu, label, &m, entry, b)
        };
        let stage = |label, file, b: &Bindings| entry_stage(label, file, "main", b);
        // The matte history restarts from the radiance cache's prior where there is one.
        let mut temporal_modules = modules(temporal, glossy, motion);
        if !glossy {
            let prior = variant.prior;
            temporal_modules.push(if prior { "cache/prior.wgsl" } else { "cache/prior_none.wgsl" });
        }
        Ok(SignalStages {
            variant,
            temporal: ChainStage::new(gpu, labels[0], &temporal_modules, "main", offered)?,
            variance: stage(labels[1], "svgf/variance.wgsl", offered)?,
            atrous: stage(labels[2], "svgf/atrous.wgsl", offered)?,
            spread_h: entry_stage(labels[3], "svgf/spread.wgsl", "spread_h", offered)?,
            spread_v: entry_stage(labels[4], "svgf/spread.wgsl", "spread_v", offered)?,
            regression: stage(labels[5], "svgf/regression.wgsl", offered)?,
            last: stage(labels[6], "svgf/final.wgsl", offered)?,
        })
    }

    fn pipelines(&mut self) -> impl Iterator<Item = &mut dyn crate::shader::Reload> {
        [
            &mut self.temporal,
            &mut self.variance,
            &mut self.atrous,
            &mut self.spread_h,
            &mut self.spread_v,
            &mut self.regression,
            &mut self.last,
        ]
        .into_iter()
        .map(|s| &mut s.pipeline as &mut dyn crate::shader::Reload)
    }
}

struct MotionStages {
    /// What the motion stage's program was made for.
    program: MotionProgram,
    motion: ChainStage,
    prefilter_h: ChainStage,
    prefilter_v: ChainStage,
}

/// SVGF's parameter buffers and per-pixel textures: what its stages bind.
struct Resources {
    sv: wgpu::Buffer,
    dn: wgpu::Buffer,
    gp: wgpu::Buffer,
    levels: [wgpu::Buffer; LEVELS],
    targets: Option<SvgfTargets>,
}

struct Svgf {
    scene: DenoiserScene,
    res: Resources,
    /// Each signal's stages and the glossy motion search, made on the first frame they record
    /// (a stage is checked against the names the frame offers).
    matte: Option<SignalStages>,
    glossy: Option<SignalStages>,
    motion: Option<MotionStages>,
}

/// Which texture a stage reads and writes, by stage.
#[derive(Clone, Copy)]
enum Pass {
    Temporal,
    Variance,
    /// Level i: reads the variance stage's output (level 0), then pong and ping in turn.
    Atrous(usize),
    /// The spike cut's spread: the rows' sums of the cut light (false), then their columns' mean
    /// (true).
    Spread(bool),
    /// Reads the last level's output: 0 the variance stage's (no level ran), 1 ping, 2 pong.
    Regression(usize),
    /// Reads the regression's output.
    Final,
}

/// One signal's textures, and for the glossy signal the reflection motion's.
#[derive(Clone, Copy)]
struct Signal<'a> {
    targets: &'a SignalTargets,
    motion: Option<&'a MotionTargets>,
}

impl SvgfTargets {
    fn signal(&self, glossy: bool) -> Option<Signal<'_>> {
        match (glossy, &self.glossy) {
            (false, _) => Some(Signal { targets: &self.matte, motion: None }),
            (true, Some((targets, motion))) => Some(Signal { targets, motion: Some(motion) }),
            (true, None) => None,
        }
    }
}

impl Resources {
    /// Everything every SVGF program may bind, plus what `pass` of one signal reads and
    /// writes at history parity `parity`.
    fn bindings<'a>(
        &'a self,
        io: &FrameIo<'a>,
        t: &'a SvgfTargets,
        signal: Signal<'a>,
        pass: Pass,
        parity: Parity,
    ) -> Bindings<'a> {
        let mut b = io
            .bindings()
            .buffer("sv", &self.sv)
            .buffer("dn", &self.dn)
            .texture("features", &t.features.1);
        if let Some(m) = signal.motion {
            b = b
                .buffer("gp", &self.gp)
                .texture("prev_hit", &m.hit.history(parity).1)
                .texture("motion", &m.motion.1)
                .texture("neighbourhood", &m.neighbourhood.1);
        }
        let s = signal.targets;
        match pass {
            Pass::Temporal => b
                .texture("history", &s.history.history(parity).1)
                .texture("moments", &s.moments.history(parity).1)
                .texture("out_integrated", &s.integrated.1)
                .texture("out_moments", &s.moments.output(parity).1)
                .texture("out_features", &t.features.1)
                .texture("out_state", &s.state.1),
            Pass::Variance => b
                .texture("integrated", &s.integrated.1)
                .texture("moments", &s.moments.output(parity).1)
                .texture("dst", &s.variance.1)
                .texture("out_taps", &s.taps.1)
                .texture("out_excess", &s.excess.1),
            Pass::Atrous(level) => {
                let src = match level {
                    0 => &s.variance,
                    l if l % 2 == 1 => &s.pong,
                    _ => &s.ping,
                };
                let dst = if level % 2 == 0 { &s.pong } else { &s.ping };
                b.texture("src", &src.1)
                    .texture("dst", &dst.1)
                    .texture("taps", &s.taps.1)
                    .texture("moments", &s.moments.output(parity).1)
                    .texture("out_history", &s.history.output(parity).1)
                    .buffer("level", &self.levels[level])
            }
            Pass::Regression(last) => b
                .texture("src", &[&s.variance, &s.ping, &s.pong][last].1)
                .texture("light", &s.variance.1)
                .texture("excess", &s.excess.1)
                .texture("taps", &s.taps.1)
                .texture("moments", &s.moments.output(parity).1)
                .texture("spread", &s.spread.1)
                .texture("dst", &s.regressed.1),
            Pass::Spread(columns) => {
                let (src, dst) =
                    if columns { (&s.spread_rows, &s.spread) } else { (&s.excess, &s.spread_rows) };
                b.texture("src", &src.1)
                    .texture("dst", &dst.1)
                    .texture("taps", &s.taps.1)
                    .texture("moments", &s.moments.output(parity).1)
            }
            Pass::Final => b
                .texture("src", &s.regressed.1)
                .texture("moments", &s.moments.output(parity).1)
                .texture("dst", &s.out.1),
        }
    }

    /// The glossy chain's motion and prefilter stages on SVGF's textures.
    fn motion_bindings<'a>(
        &'a self,
        io: &FrameIo<'a>,
        m: &'a MotionTargets,
        prefilter: Option<bool>,
        parity: Parity,
    ) -> Bindings<'a> {
        let b = io.bindings().buffer("dn", &self.dn).buffer("gp", &self.gp);
        match prefilter {
            None => b
                .texture("prev_hit", &m.hit.history(parity).1)
                .texture("out_motion", &m.motion.1)
                .texture("out_search", &m.search.1)
                .texture("out_hit", &m.hit.output(parity).1),
            Some(false) => b.texture("src", &m.neighbourhood.1).texture("dst", &m.scratch.1),
            Some(true) => b.texture("src", &m.scratch.1).texture("dst", &m.neighbourhood.1),
        }
    }

    fn write_params(&self, gpu: &Gpu, io: &FrameIo, cx: &FrameContext, extent: f32) {
        let s: &FrameSettings = cx.settings;
        let sv = &s.svgf;
        gpu.queue.write_buffer(&self.sv, 0, bytemuck::bytes_of(&SvgfParams::new(sv)));
        let mut dp = DenoiseParams::new(&s.matte, &s.taa, io.size.0, cx.index, &cx.view);
        dp.reprojection_min_cos = crate::passes::matte::normal_test_cos(NORMAL_TEST_DEGREES);
        gpu.queue.write_buffer(&self.dn, 0, bytemuck::bytes_of(&dp));
        let mut gp = GlossyParams::new(&s.glossy, extent, cx.view.static_view);
        gp.roughness_threshold = sv.roughness_threshold;
        gp.clip_roughness = sv.clip_roughness;
        gp.mode = if sv.reflection_reprojection { 2 } else { 0 };
        if !sv.mirror_features {
            // No surface is a mirror: no demodulation by the reflected surface, no mirror search.
            gp.mirror_roughness = -1.0;
        }
        gpu.queue.write_buffer(&self.gp, 0, bytemuck::bytes_of(&gp));
    }

    /// Every resource any stage of a signal binds (only the names matter: each program's
    /// layout is checked against them).
    fn offered<'a>(&'a self, io: &FrameIo<'a>, t: &'a SvgfTargets, s: Signal<'a>) -> Bindings<'a> {
        let p = Parity::default();
        [
            Pass::Variance,
            Pass::Atrous(0),
            Pass::Spread(false),
            Pass::Spread(true),
            Pass::Regression(0),
            Pass::Final,
        ]
        .into_iter()
        .fold(self.bindings(io, t, s, Pass::Temporal, p), |b, pass| {
            b.with(&self.bindings(io, t, s, pass, p))
        })
    }

    fn record_stages(
        &self,
        rec: &mut Recorder,
        io: &FrameIo,
        cx: &FrameContext,
        signal: Signal,
        st: &mut SignalStages,
    ) -> Result<()> {
        let t = self.targets.as_ref().context("SVGF records before its textures exist")?;
        let (key, parity, size) = (cx.key, cx.parity, io.size);
        let b = |pass, p| self.bindings(io, t, signal, pass, p);
        st.temporal.record(rec, key, parity, size, |p| b(Pass::Temporal, p))?;
        st.variance.record(rec, key, parity, size, |p| b(Pass::Variance, p))?;
        let levels = cx.settings.svgf.atrous_levels() as usize;
        for level in 0..levels {
            // Bind groups by (parity, level).
            st.atrous.record_variant(
                rec,
                key,
                (2 * LEVELS, parity.index() * LEVELS + level),
                size,
                |v| b(Pass::Atrous(v % LEVELS), Parity::BOTH[v / LEVELS]),
            )?;
        }
        let s = signal.targets;
        if levels == 0 || !cx.settings.svgf.filtered_history {
            // No level wrote the history: it is the integrated light.
            let extent = wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 };
            rec.enc.copy_texture_to_texture(
                s.integrated.0.as_image_copy(),
                s.history.output(parity).0.as_image_copy(),
                extent,
            );
        }
        let sv = &cx.settings.svgf;
        if sv.regression && sv.spike_ratio > 0.0 {
            st.spread_h.record(rec, key, parity, size, |p| b(Pass::Spread(false), p))?;
            st.spread_v.record(rec, key, parity, size, |p| b(Pass::Spread(true), p))?;
        }
        // The last level wrote pong when its index was even; bind groups by (last, parity).
        let last = if levels == 0 { 0 } else { 1 + (levels % 2) };
        let variant = (6, 2 * last + parity.index());
        st.regression.record_variant(rec, key, variant, size, |v| {
            b(Pass::Regression(v / 2), Parity::BOTH[v % 2])
        })?;
        st.last.record(rec, key, parity, size, |p| b(Pass::Final, p))
    }

    fn record_motion(
        &self,
        rec: &mut Recorder,
        io: &FrameIo,
        cx: &FrameContext,
        m: &MotionTargets,
        st: &mut MotionStages,
    ) -> Result<()> {
        let (key, parity, size) = (cx.key, cx.parity, io.size);
        let sv = &cx.settings.svgf;
        let b = |prefilter, p| self.motion_bindings(io, m, prefilter, p);
        st.motion.record(rec, key, parity, size, |p| b(None, p))?;
        if sv.clipping && sv.temporal {
            st.prefilter_h.record(rec, key, parity, size, |p| b(Some(false), p))?;
            st.prefilter_v.record(rec, key, parity, size, |p| b(Some(true), p))?;
        }
        Ok(())
    }
}

fn motion_stages(
    gpu: &Gpu,
    res: &Resources,
    io: &FrameIo,
    m: &MotionTargets,
    motion: crate::gpu::Motion,
    program: MotionProgram,
) -> Result<MotionStages> {
    use crate::passes::glossy::modules;
    let p = Parity::default();
    let stage = |label, file, entry, prefilter, prelude: &str| {
        let offered = res.motion_bindings(io, m, prefilter, p);
        ChainStage::with_prelude(gpu, label, prelude, &modules(file, motion), entry, &offered)
    };
    let search = program.prelude();
    Ok(MotionStages {
        program,
        motion: stage("svgf/motion", "glossy/motion.wgsl", "main", None, &search)?,
        prefilter_h: stage("svgf/prefilter_h", "glossy/prefilter.wgsl", "pre_h", Some(false), "")?,
        prefilter_v: stage("svgf/prefilter_v", "glossy/prefilter.wgsl", "pre_v", Some(true), "")?,
    })
}

impl Denoiser for Svgf {
    fn needs_previous_gbuffer(&self) -> bool {
        true
    }

    fn allocate(&mut self, gpu: &Gpu, memory: &mut GpuMemory, size: (u32, u32)) {
        self.res.targets = Some(SvgfTargets::new(&gpu.device, memory, size, self.scene.glossy));
    }

    fn record(&mut self, rec: &mut Recorder, io: &FrameIo, cx: &FrameContext) -> Result<()> {
        let gpu = rec.gpu;
        let Svgf { scene, res, matte, glossy, motion } = self;
        let t = res.targets.as_ref().context("SVGF records before its textures exist")?;
        res.write_params(gpu, io, cx, scene.extent);
        let signal = |g| t.signal(g).context("SVGF's glossy textures are missing");
        let wanted = |g| Variant::wanted(g, io, &cx.settings.svgf);
        let stages = |g, s| {
            let offered = res.offered(io, t, s);
            SignalStages::new(gpu, g, scene.motion, &offered, wanted(g))
                .context("creating SVGF's stages")
        };
        // Made again when the radiance cache's prior, the pre-filter's statistics or the kernel
        // come or go, and the motion search when its program's constants change.
        let fits = |g| move |st: &SignalStages| st.variant == wanted(g);
        let s = signal(false)?;
        let st = made_for(matte, fits(false), || stages(false, s))?;
        res.record_stages(rec, io, cx, s, st)?;
        if scene.glossy {
            let s = signal(true)?;
            let m = s.motion.context("SVGF's glossy motion textures are missing")?;
            let program = MotionProgram::of(&cx.settings.glossy);
            let st = made_for(
                motion,
                |st| st.program == program,
                || motion_stages(gpu, res, io, m, scene.motion, program),
            )?;
            res.record_motion(rec, io, cx, m, st)?;
            let st = made_for(glossy, fits(true), || stages(true, s))?;
            res.record_stages(rec, io, cx, s, st)?;
        }
        Ok(())
    }

    /// TAA follows the matte light SVGF shows (the composite's), so that a still view shows the
    /// latest converged light under TAA's averaged material rather than TAA's mean of every
    /// frame SVGF showed (whose first frames are the least converged).
    fn taa_follow(&self, _parity: Parity) -> TaaFollow<'_> {
        let Some(t) = &self.res.targets else { return TaaFollow::default() };
        let (light, state) = (&t.matte.out.1, &t.matte.state.1);
        TaaFollow {
            matte: Some(MatteFollow { light, state, form: MatteState::Reason }),
            glossy: None,
        }
    }

    fn output(&self, _parity: Parity) -> Denoised<'_> {
        let Some(t) = &self.res.targets else { return Denoised::default() };
        Denoised {
            matte: Some(&t.matte.out.1),
            glossy: t.glossy.as_ref().map(|(s, _)| &s.out.1),
            direct: None,
        }
    }

    fn pipelines(&mut self) -> Vec<&mut dyn crate::shader::Reload> {
        let mut v: Vec<&mut dyn crate::shader::Reload> = vec![];
        if let Some(s) = self.matte.as_mut() {
            v.extend(s.pipelines());
        }
        if let Some(s) = self.glossy.as_mut() {
            v.extend(s.pipelines());
        }
        if let Some(m) = self.motion.as_mut() {
            v.extend(
                [&mut m.motion, &mut m.prefilter_h, &mut m.prefilter_v]
                    .into_iter()
                    .map(|s| &mut s.pipeline as &mut dyn crate::shader::Reload),
            );
        }
        v
    }
}
