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

mod targets;
#[cfg(test)]
mod tests;

pub use targets::{SvgfTargets, moments_label};

/// SVGF's frame graph for a scene with (`glossy`) or without a specular lobe: its passes, its
/// textures and what the frame reads after it ([`crate::gpu::FrameGraph::describe`] draws it).
pub fn frame_graph(glossy: bool) -> crate::gpu::FrameGraph {
    targets::graph(glossy, &[])
}

use super::{Denoised, Denoiser, DenoiserScene, FrameContext, Outputs};
use crate::gpu::{Bindings, Gpu, GpuMemory, Parity, Recorder};
use crate::passes::chain::{ChainStage, made_for};

/// An SVGF stage: its bind groups by the history parity and the pass they bind (a-trous level,
/// the regression's input).
type Stage = ChainStage<(Parity, Pass)>;
use crate::denoise::mara::glossy::{GlossyParams, MotionProgram};
use crate::passes::io::FrameIo;
use crate::passes::taa::{MatteFollow, MatteState, TaaFollow};
use crate::settings::{FrameSettings, SvgfSettings, svgf::STILL_FRAMES_MAX};
use anyhow::{Context, Result};
use bytemuck::{Pod, Zeroable};

use targets::{Chain, LEVELS, Pass, Resolved};

/// The label of the glossy signal's output (what the composite reads).
pub const GLOSSY_OUTPUT: &str = "svgf/glossy out";
/// The start of the glossy signal's labels (its reflection motion's `motion`, `search`, ...).
pub const GLOSSY_PREFIX: &str = "svgf/glossy ";

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
    /// Cosine of the temporal stages' normal test (25 degrees).
    pub normal_min_cos: f32,
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
            normal_min_cos: crate::passes::io::normal_test_cos(NORMAL_TEST_DEGREES),
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
    let res = Resources { sv, gp, levels, targets: None };
    Ok(Box::new(Svgf { scene: *scene, res, matte: None, glossy: None, motion: None }))
}

/// The modules of an SVGF program: the frame's inputs, the matte (and for the glossy signal,
/// the glossy) chain's helpers, SVGF's common code, the signal's features (stages after the
/// temporal) and the stage.
pub fn modules(stage: &'static str, glossy: bool, motion: crate::gpu::Motion) -> Vec<&'static str> {
    let mut m = vec!["common/math.wgsl", "realtime/frame.wgsl", "realtime/gbuffer_in.wgsl"];
    if glossy {
        m.push("realtime/glossy_in.wgsl");
    }
    m.extend(["common/bilinear.wgsl", "realtime/reproject.wgsl"]);
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

/// The modules of the program of SVGF stage `file` (`svgf/*.wgsl`) for `variant`.
fn program(
    file: &'static str,
    glossy: bool,
    motion: crate::gpu::Motion,
    variant: Variant,
) -> Vec<&'static str> {
    let mut m = modules(file, glossy, motion);
    if file == "svgf/atrous.wgsl" {
        m.insert(m.len() - 1, kernel_module(variant.kernel_5x5));
    }
    // The glossy light's reach (svgf/features_glossy.wgsl) takes the circle of confusion where
    // the pre-filter measured one, and the regressions weigh the features against their
    // variances.
    if reads_uncertainty(file, glossy) {
        m.insert(m.len() - 1, crate::passes::io::uncertainty_module(variant.uncertain));
    }
    // The matte history restarts from the radiance cache's prior where there is one.
    if file == "svgf/temporal_matte.wgsl" {
        m.push(if variant.prior { "cache/prior.wgsl" } else { "cache/prior_none.wgsl" });
    }
    m
}

/// What a signal's programs are made for; a frame that wants another variant makes them again.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
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
    temporal: Stage,
    variance: Stage,
    atrous: Stage,
    spread_h: Stage,
    spread_v: Stage,
    regression: Stage,
    last: Stage,
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
        let stage_at = |label, file, entry: &str, b: &Bindings| {
            ChainStage::new(gpu, label, &program(file, glossy, motion, variant), entry, b)
        };
        let stage = |label, file, b: &Bindings| stage_at(label, file, "main", b);
        Ok(SignalStages {
            variant,
            temporal: stage(labels[0], temporal, offered)?,
            variance: stage(labels[1], "svgf/variance.wgsl", offered)?,
            atrous: stage(labels[2], "svgf/atrous.wgsl", offered)?,
            spread_h: stage_at(labels[3], "svgf/spread.wgsl", "spread_h", offered)?,
            spread_v: stage_at(labels[4], "svgf/spread.wgsl", "spread_v", offered)?,
            regression: stage(labels[5], "svgf/regression.wgsl", offered)?,
            last: stage(labels[6], "svgf/final.wgsl", offered)?,
        })
    }

    fn stages(&mut self) -> impl Iterator<Item = &mut Stage> {
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
    }
}

struct MotionStages {
    /// What the motion stage's program was made for.
    program: MotionProgram,
    motion: Stage,
    prefilter_h: Stage,
    prefilter_v: Stage,
}

/// SVGF's parameter buffers and per-pixel textures: what its stages bind.
struct Resources {
    sv: wgpu::Buffer,
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

impl Resources {
    /// Everything every SVGF program may bind, plus what `pass` of signal `c` reads and writes
    /// at history parity `parity` ([`targets::textures`]).
    fn bindings<'a>(
        &'a self,
        io: &FrameIo<'a>,
        t: &'a SvgfTargets,
        c: Chain,
        pass: Pass,
        parity: Parity,
    ) -> Bindings<'a> {
        let mut b = io.bindings().buffer("sv", &self.sv);
        if c == Chain::Glossy {
            b = b.buffer("gp", &self.gp);
        }
        if let Pass::Atrous(level) = pass {
            b = b.buffer("level", &self.levels[level]);
        }
        for (name, r) in t.bound(c, pass, parity) {
            b = match r {
                Resolved::Own(tex) => b.texture(name, &tex.1),
                Resolved::Frame(from) => b.alias(name, from),
            };
        }
        b
    }

    fn write_params(&self, gpu: &Gpu, cx: &FrameContext, extent: f32) {
        let s: &FrameSettings = cx.settings;
        let sv = &s.svgf;
        gpu.queue.write_buffer(&self.sv, 0, bytemuck::bytes_of(&SvgfParams::new(sv)));
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
    fn offered<'a>(&'a self, io: &FrameIo<'a>, t: &'a SvgfTargets, c: Chain) -> Bindings<'a> {
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
        .fold(self.bindings(io, t, c, Pass::Temporal, p), |b, pass| {
            b.with(&self.bindings(io, t, c, pass, p))
        })
    }

    fn record_stages(
        &self,
        rec: &mut Recorder,
        io: &FrameIo,
        cx: &FrameContext,
        c: Chain,
        st: &mut SignalStages,
    ) -> Result<()> {
        let t = self.targets.as_ref().context("SVGF records before its textures exist")?;
        let (key, parity, size) = (cx.key, cx.parity, io.size);
        let b = |(p, pass)| self.bindings(io, t, c, pass, p);
        st.temporal.record(rec, key, (parity, Pass::Temporal), size, b)?;
        st.variance.record(rec, key, (parity, Pass::Variance), size, b)?;
        let levels = cx.settings.svgf.atrous_levels() as usize;
        for level in 0..levels {
            st.atrous.record(rec, key, (parity, Pass::Atrous(level)), size, b)?;
        }
        if levels == 0 || !cx.settings.svgf.filtered_history {
            // No level wrote the history: it is the integrated light.
            let extent = wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 };
            let copy = t.bound(c, Pass::HistoryCopy, parity);
            if let [(_, Resolved::Own(src)), (_, Resolved::Own(dst))] = copy {
                rec.enc.copy_texture_to_texture(
                    src.0.as_image_copy(),
                    dst.0.as_image_copy(),
                    extent,
                );
            }
        }
        let sv = &cx.settings.svgf;
        if sv.regression && sv.spike_ratio > 0.0 {
            st.spread_h.record(rec, key, (parity, Pass::Spread(false)), size, b)?;
            st.spread_v.record(rec, key, (parity, Pass::Spread(true)), size, b)?;
        }
        // The last level wrote pong when its index was even.
        let last = if levels == 0 { 0 } else { 1 + (levels % 2) };
        st.regression.record(rec, key, (parity, Pass::Regression(last)), size, b)?;
        st.last.record(rec, key, (parity, Pass::Final), size, b)
    }

    fn record_motion(
        &self,
        rec: &mut Recorder,
        io: &FrameIo,
        cx: &FrameContext,
        st: &mut MotionStages,
    ) -> Result<()> {
        let t = self.targets.as_ref().context("SVGF records before its textures exist")?;
        let (key, parity, size) = (cx.key, cx.parity, io.size);
        let sv = &cx.settings.svgf;
        let b = |(p, pass)| self.bindings(io, t, Chain::Glossy, pass, p);
        st.motion.record(rec, key, (parity, Pass::Motion), size, b)?;
        if sv.clipping && sv.temporal {
            st.prefilter_h.record(rec, key, (parity, Pass::Prefilter(false)), size, b)?;
            st.prefilter_v.record(rec, key, (parity, Pass::Prefilter(true)), size, b)?;
        }
        Ok(())
    }
}

fn motion_stages(
    gpu: &Gpu,
    res: &Resources,
    io: &FrameIo,
    t: &SvgfTargets,
    motion: crate::gpu::Motion,
    program: MotionProgram,
) -> Result<MotionStages> {
    use crate::denoise::mara::glossy::modules;
    let p = Parity::default();
    let stage = |label, file, entry, pass, prelude: &str| {
        let offered = res.bindings(io, t, Chain::Glossy, pass, p);
        ChainStage::with_prelude(gpu, label, prelude, &modules(file, motion), entry, &offered)
    };
    let search = program.prelude();
    let (h, v) = (Pass::Prefilter(false), Pass::Prefilter(true));
    Ok(MotionStages {
        program,
        motion: stage("svgf/motion", "glossy/motion.wgsl", "main", Pass::Motion, &search)?,
        prefilter_h: stage("svgf/prefilter_h", "glossy/prefilter.wgsl", "pre_h", h, "")?,
        prefilter_v: stage("svgf/prefilter_v", "glossy/prefilter.wgsl", "pre_v", v, "")?,
    })
}

impl Denoiser for Svgf {
    fn needs_previous_gbuffer(&self) -> bool {
        true
    }

    /// The glossy signal's reflection motion and features read them.
    fn reads_reflections(&self) -> bool {
        true
    }

    fn allocate(
        &mut self,
        gpu: &Gpu,
        memory: &mut GpuMemory,
        size: (u32, u32),
        kept: &[String],
        _settings: &FrameSettings,
    ) -> Result<()> {
        let glossy = self.scene.glossy;
        let t = SvgfTargets::new(&gpu.device, memory, size, glossy, kept)
            .context("planning SVGF's textures")?;
        self.res.targets = Some(t);
        Ok(())
    }

    fn record<'s>(
        &'s mut self,
        rec: &mut Recorder,
        io: &FrameIo,
        cx: &FrameContext,
    ) -> Result<Outputs<'s>> {
        let gpu = rec.gpu;
        let Svgf { scene, res, matte, glossy, motion } = self;
        let t = res.targets.as_ref().context("SVGF records before its textures exist")?;
        res.write_params(gpu, cx, scene.extent);
        let wanted = |c| Variant::wanted(c == Chain::Glossy, io, &cx.settings.svgf);
        let stages = |c: Chain| {
            let offered = res.offered(io, t, c);
            SignalStages::new(gpu, c == Chain::Glossy, scene.motion, &offered, wanted(c))
                .context("creating SVGF's stages")
        };
        // Made again when the radiance cache's prior, the pre-filter's statistics or the kernel
        // come or go, and the motion search when its program's constants change.
        let fits = |c| move |st: &SignalStages| st.variant == wanted(c);
        let st = made_for(matte, fits(Chain::Matte), || stages(Chain::Matte))?;
        res.record_stages(rec, io, cx, Chain::Matte, st)?;
        if scene.glossy {
            let program = MotionProgram::of(&cx.settings.glossy);
            let st = made_for(
                motion,
                |st| st.program == program,
                || motion_stages(gpu, res, io, t, scene.motion, program),
            )?;
            res.record_motion(rec, io, cx, st)?;
            let st = made_for(glossy, fits(Chain::Glossy), || stages(Chain::Glossy))?;
            res.record_stages(rec, io, cx, Chain::Glossy, st)?;
        }
        Ok(outputs(t))
    }

    fn release(&mut self) {
        self.res.targets = None;
        self.stages().for_each(Stage::release_groups);
    }

    fn pipelines(&mut self) -> Vec<&mut dyn crate::shader::Reload> {
        self.stages().map(|s| &mut s.pipeline as &mut dyn crate::shader::Reload).collect()
    }
}

/// The composite's light, and what TAA follows: the matte light SVGF shows (the composite's),
/// so that a still view shows the latest converged light under TAA's averaged material rather
/// than TAA's mean of every frame SVGF showed (whose first frames are the least converged).
fn outputs(t: &SvgfTargets) -> Outputs<'_> {
    let light = Denoised {
        matte: t.out(Chain::Matte).map(|o| &o.1),
        glossy: t.out(Chain::Glossy).map(|o| &o.1),
        direct: None,
    };
    let matte = match (t.out(Chain::Matte), t.state(Chain::Matte)) {
        (Some(light), Some(state)) => {
            Some(MatteFollow { light: &light.1, state: &state.1, form: MatteState::Reason })
        }
        _ => None,
    };
    Outputs::same(light, TaaFollow { matte, glossy: None })
}

impl Svgf {
    /// Every stage it made.
    fn stages(&mut self) -> impl Iterator<Item = &mut Stage> {
        let signals = self.matte.iter_mut().chain(self.glossy.iter_mut()).flat_map(|s| s.stages());
        let motion = self
            .motion
            .iter_mut()
            .flat_map(|m| [&mut m.motion, &mut m.prefilter_h, &mut m.prefilter_v]);
        signals.chain(motion)
    }
}
