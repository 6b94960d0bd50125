//! The progressive filter of Dundr et al. ("Progressive spatiotemporal variance-guided
//! filtering", §4-5) as a denoiser behind the frame's contract: the one that takes sample
//! fractions below 1 (`--spp 1/N`), and runs at one sample per pixel too.
//!
//! Three signals, each through its own passes (shaders/progressive/*.wgsl): the matte light,
//! the glossy light (scenes with a specular lobe) and the direct light (punctual lights and the
//! environment the camera sees), since below one sample per pixel a pixel not traced would
//! otherwise show its last direct light wherever the camera moved. `progressive/features`
//! (depth and its gradient) -> per signal `temporal` (r = max(a, 1/age); an untraced pixel keeps
//! light, age and moments) -> `variance` (3x3-blurred m2 - m1^2) -> `atrous` (3x3 kernel, large
//! scale first, missing samples skipped and filled; the direct light only fills; in a still
//! view a level's reach ends as the pixel's samples grow, `reach_samples`). The history is
//! the accumulated light before the spatial filter, except for a pixel's first samples
//! (`feedback_samples`): then the step-1 level runs first and its output becomes the history of
//! the pixels traced this frame (Dundr §4.4-5; docs/decisions.md). The composite and TAA
//! (Dundr's §4.5 blend with a clamped history) follow as for every denoiser.

use super::{Denoised, Denoiser, DenoiserScene, FrameContext, Outputs};
use crate::gpu::{Bindings, Gpu, GpuMemory, Parity, PingPong, Recorder, Tex};
use crate::passes::chain::ChainStage;
use crate::passes::io::FrameIo;
use crate::passes::taa::{MatteFollow, MatteState, TaaFollow};
use crate::settings::{
    FrameSettings, PROGRESSIVE_MAX_LEVELS, ProgressiveSettings, STILL_FRAMES_MAX,
};
use anyhow::{Context, Result, bail};
use bytemuck::{Pod, Zeroable};

const RGBA16F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const RGBA32F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
const LEVELS: usize = PROGRESSIVE_MAX_LEVELS as usize;

/// Mirror of `ProgressiveParams` in shaders/progressive/common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ProgressiveParams {
    pub alpha: f32,
    pub still_samples: f32,
    pub sigma_n: f32,
    pub sigma_d: f32,
    pub sigma_l: f32,
    pub epsilon_l: f32,
    pub temporal: u32,
    pub epsilon_full_samples: f32,
    pub feedback_samples: f32,
    pub symmetric_luminance: u32,
    pub reach_samples: f32,
    pub variance_cap: f32,
    /// Cosine of the temporal stage's normal test (25 degrees, as SVGF's).
    pub normal_min_cos: f32,
    pub _pad: [f32; 3],
}

impl ProgressiveParams {
    pub fn new(s: &ProgressiveSettings) -> ProgressiveParams {
        ProgressiveParams {
            alpha: s.alpha.clamp(1e-3, 1.0),
            still_samples: s.still_samples.clamp(0.0, STILL_FRAMES_MAX),
            sigma_n: s.sigma_n.max(0.0),
            sigma_d: s.sigma_d.max(1e-3),
            sigma_l: s.sigma_l.max(0.0),
            epsilon_l: s.epsilon_l.max(1e-6),
            temporal: s.temporal as u32,
            epsilon_full_samples: s.epsilon_full_samples.clamp(0.0, STILL_FRAMES_MAX),
            feedback_samples: s.feedback_samples.clamp(0.0, STILL_FRAMES_MAX),
            symmetric_luminance: s.symmetric_luminance as u32,
            reach_samples: s.reach_samples.clamp(0.0, STILL_FRAMES_MAX),
            variance_cap: s.variance_cap.clamp(0.0, STILL_FRAMES_MAX),
            normal_min_cos: crate::passes::io::normal_test_cos(NORMAL_TEST_DEGREES),
            _pad: [0.0; 3],
        }
    }
}

/// Mirror of `Level` in shaders/progressive/common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Level {
    step: i32,
    fill_only: u32,
    feedback: u32,
    _pad: u32,
}

/// The reprojection's normal test, as SVGF's.
const NORMAL_TEST_DEGREES: f32 = 25.0;

/// The light a set of the filter's passes works on.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Signal {
    Matte,
    Glossy,
    Direct,
}

impl Signal {
    fn name(self) -> &'static str {
        match self {
            Signal::Matte => "matte",
            Signal::Glossy => "glossy",
            Signal::Direct => "direct",
        }
    }

    fn module(self) -> &'static str {
        match self {
            Signal::Matte => "progressive/signal_matte.wgsl",
            Signal::Glossy => "progressive/signal_glossy.wgsl",
            Signal::Direct => "progressive/signal_direct.wgsl",
        }
    }

    /// Labels are 'static: the profiler and the pass timings key on them.
    fn labels(self) -> [&'static str; 3] {
        match self {
            Signal::Matte => [
                "progressive/temporal_matte",
                "progressive/variance_matte",
                "progressive/atrous_matte",
            ],
            Signal::Glossy => [
                "progressive/temporal_glossy",
                "progressive/variance_glossy",
                "progressive/atrous_glossy",
            ],
            Signal::Direct => [
                "progressive/temporal_direct",
                "progressive/variance_direct",
                "progressive/atrous_direct",
            ],
        }
    }
}

pub fn make(gpu: &Gpu, scene: &DenoiserScene) -> Result<Box<dyn Denoiser>> {
    let mut memory = GpuMemory::default();
    let u = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
    let d = &gpu.device;
    let pp = memory.buffer(d, "progressive/params", size_of::<ProgressiveParams>() as u64, u);
    let mut level = |label: &str, step: i32, fill_only: bool, feedback: bool| {
        let b = memory.buffer(d, label, size_of::<Level>() as u64, u);
        let l = Level { step, fill_only: fill_only as u32, feedback: feedback as u32, _pad: 0 };
        gpu.queue.write_buffer(&b, 0, bytemuck::bytes_of(&l));
        b
    };
    let levels = [false, true].map(|fill_only| {
        std::array::from_fn(|i| level(&format!("progressive/level {i}"), 1 << i, fill_only, false))
    });
    let feedback = level("progressive/feedback level", 1, false, true);
    let mut signals = vec![Signal::Matte, Signal::Direct];
    if scene.glossy {
        signals.insert(1, Signal::Glossy);
    }
    let res = Resources { pp, levels, feedback, targets: None };
    Ok(Box::new(Progressive { scene: *scene, res, stages: None, signals }))
}

/// One signal's textures: 96 bytes per pixel with one texture each; 56 where the variance
/// stage's output and the levels' scratch are shared ([`Placement`]).
pub struct SignalTargets {
    /// The accumulated light (rgb) by parity: this frame's is next frame's history.
    pub history: PingPong<Tex>,
    /// Luminance moments and the samples accumulated (m1, m2, age), by parity.
    pub moments: PingPong<Tex>,
    /// The variance stage's output (rgb, variance; -1: no sample), then the levels' ping-pong.
    pub variance: Tex,
    pub ping: Tex,
    pub pong: Tex,
}

/// Where the filter's per-frame textures live for a level count. Each signal's last level is
/// what the composite (and TAA) reads, so it is the signal's own; with one level or more the
/// variance stage's output and the other texture of the ping-pong are dead once the signal's
/// levels ran, and the signals, recorded one after another, share one of each (48 bytes a pixel
/// less with three signals). With no level the variance stage's output is what the composite
/// reads, and nothing is shared. A texture the frame keeps (a view, a readback) is its own.
/// A change of placement (no level to some, or the last level's parity) makes the textures
/// again, and the histories restart from nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Placement {
    levels: usize,
}

impl Placement {
    fn of(s: &FrameSettings) -> Placement {
        Placement { levels: levels_of(s).count }
    }

    /// What the placement depends on: no level, or the parity of the last one.
    fn key(self) -> u64 {
        match self.levels {
            0 => 0,
            l => 1 + (l % 2) as u64,
        }
    }
}

/// This frame's levels from the settings.
fn levels_of(s: &FrameSettings) -> Levels {
    let p = &s.progressive;
    Levels {
        count: p.levels.min(PROGRESSIVE_MAX_LEVELS) as usize,
        feedback: p.feedback_samples > 0.0 && p.levels > 0,
    }
}

/// The shared textures of a [`Placement`], made by the first signal that needs them.
#[derive(Default)]
struct Shared {
    variance: Option<Tex>,
    scratch: Option<Tex>,
}

impl SignalTargets {
    fn new(
        d: &wgpu::Device,
        mem: &mut GpuMemory,
        size: (u32, u32),
        name: &str,
        (placement, shared, kept): (Placement, &mut Shared, &[String]),
    ) -> SignalTargets {
        let rw = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let label = |what: &str| format!("progressive/{name} {what}");
        let share = |what: &str| {
            let l = label(what);
            placement.levels > 0 && !crate::gpu::graph::is_kept(kept, &l)
        };
        let mut t = |label: &str, f| mem.texture(d, label, size, f, rw);
        // 32-bit: a half float stalls a 1 / age mean after about a thousand samples.
        let history = PingPong::new(|i| t(&label(&format!("history {i}")), RGBA32F));
        let moments = PingPong::new(|i| t(&label(&format!("moments {i}")), RGBA32F));
        // 32-bit: with feedback, the first level writes it back into the history.
        let variance = match share("variance") {
            true => {
                shared.variance.get_or_insert_with(|| t("progressive/variance", RGBA32F)).clone()
            }
            false => t(&label("variance"), RGBA32F),
        };
        // Level i of n writes pong for even i, ping for odd: the last is pong for odd n.
        let (last, other) =
            if placement.levels % 2 == 1 { ("pong", "ping") } else { ("ping", "pong") };
        let last_tex = t(&label(last), RGBA16F);
        let other_tex = match share(other) {
            true => shared.scratch.get_or_insert_with(|| t("progressive/scratch", RGBA16F)).clone(),
            false => t(&label(other), RGBA16F),
        };
        let (ping, pong) =
            if last == "ping" { (last_tex, other_tex) } else { (other_tex, last_tex) };
        SignalTargets { history, moments, variance, ping, pong }
    }

    /// What the last of `levels` levels wrote (the variance stage's output when none ran).
    fn output(&self, levels: usize) -> &Tex {
        match levels {
            0 => &self.variance,
            l if l % 2 == 1 => &self.pong,
            _ => &self.ping,
        }
    }
}

/// Each signal's last level, for the composite, and with `follow`
/// (`ProgressiveSettings::taa_follow`) the matte light the filter shows for TAA to follow, so
/// that a still view shows the latest accumulated and filtered light under TAA's averaged
/// material rather than TAA's mean of every frame shown, whose first frames (below one sample
/// per pixel, mostly filled in by the a-trous levels) are the blurriest.
fn outputs(t: &Targets, follow: bool) -> Outputs<'_> {
    let levels = t.levels.count;
    let out =
        |s: Signal| t.signals.iter().find(|(g, _)| *g == s).map(|(_, st)| &st.output(levels).1);
    let light = Denoised {
        matte: out(Signal::Matte),
        glossy: out(Signal::Glossy),
        direct: out(Signal::Direct),
    };
    let matte = t.signals.iter().find(|(g, _)| *g == Signal::Matte).filter(|_| follow);
    let follow = Parity::BOTH.map(|parity| TaaFollow {
        matte: matte.map(|(_, s)| MatteFollow {
            light: &s.output(levels).1,
            state: &s.moments.output(parity).1,
            form: MatteState::Moments,
        }),
        glossy: None,
    });
    Outputs { light: [light; 2], follow }
}

struct Targets {
    /// Linear depth, its gradient and the octahedral normal (16 bytes per pixel): one load per
    /// a-trous tap where three were.
    features: Tex,
    signals: Vec<(Signal, SignalTargets)>,
    levels: Levels,
    /// The level count the textures were placed for.
    placement: Placement,
}

/// This frame's a-trous levels: how many, and whether the first feeds the history (both pick
/// each level's step and uniform, so the bind groups are made for them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
struct Levels {
    count: usize,
    feedback: bool,
}

/// A stage of the filter: its bind groups by the history parity, the pass they bind and the
/// levels.
type Stage = ChainStage<(Parity, Pass, Levels)>;

struct SignalStages {
    temporal: Stage,
    variance: Stage,
    atrous: Stage,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Pass {
    Features,
    Temporal,
    Variance,
    /// Level i reads the variance stage's output (i = 0), then pong and ping in turn.
    Atrous(usize),
}

/// The filter's parameter buffers and per-pixel textures: what its stages bind.
struct Resources {
    pp: wgpu::Buffer,
    /// Per level, for filtering signals and for the direct light (fill only).
    levels: [[wgpu::Buffer; LEVELS]; 2],
    /// The feedback level's: step 1, its output also the history.
    feedback: wgpu::Buffer,
    targets: Option<Targets>,
}

/// The features stage and each signal's stages, made on the first frame.
struct Stages {
    features: Stage,
    signals: Vec<SignalStages>,
}

struct Progressive {
    scene: DenoiserScene,
    res: Resources,
    stages: Option<Stages>,
    signals: Vec<Signal>,
}

/// Whether TAA follows the filter's matte light this frame (`ProgressiveSettings::taa_follow`,
/// and `taa_follow_fractions` where a frame traces one pixel in N > 1).
fn follows_light(s: &FrameSettings) -> bool {
    let p = &s.progressive;
    p.taa_follow || (p.taa_follow_fractions && s.sample_period() > 1)
}

/// The modules of a program of `signal`'s `stage`.
pub fn modules(
    stage: &'static str,
    signal: Signal,
    glossy: bool,
    motion: crate::gpu::Motion,
) -> Vec<&'static str> {
    let mut m = vec!["common/math.wgsl", "realtime/frame.wgsl", "realtime/gbuffer_in.wgsl"];
    if glossy {
        m.push("realtime/glossy_in.wgsl");
    }
    m.extend(["common/bilinear.wgsl", "realtime/reproject.wgsl"]);
    m.push(motion.module());
    m.extend(["progressive/common.wgsl", signal.module(), stage]);
    m
}

impl Resources {
    fn bindings<'a>(
        &'a self,
        io: &FrameIo<'a>,
        t: &'a Targets,
        (signal, s): (Signal, &'a SignalTargets),
        pass: Pass,
        parity: Parity,
        levels: Levels,
    ) -> Bindings<'a> {
        let b = io.bindings().buffer("pp", &self.pp).texture("features", &t.features.1);
        match pass {
            Pass::Features => b.texture("out_features", &t.features.1),
            Pass::Temporal => b
                .texture("history", &s.history.history(parity).1)
                .texture("moments", &s.moments.history(parity).1)
                .texture("out_integrated", &s.history.output(parity).1)
                .texture("out_moments", &s.moments.output(parity).1),
            Pass::Variance => b
                .texture("integrated", &s.history.output(parity).1)
                .texture("moments", &s.moments.output(parity).1)
                .texture("dst", &s.variance.1),
            Pass::Atrous(i) => {
                let src = if i == 0 { &s.variance } else { s.output(i) };
                let dst = s.output(i + 1);
                let (n, direct) = (levels.count, signal == Signal::Direct);
                // Large scale first: level i of n steps 2^(n - 1 - i) pixels. With feedback
                // the step-1 level runs first (its output is the history, Dundr §4.4), then
                // the others from the largest: level i >= 1 steps 2^(n - i).
                let level = match (levels.feedback && !direct, i) {
                    (true, 0) => &self.feedback,
                    (true, _) => &self.levels[0][n.saturating_sub(i).min(LEVELS - 1)],
                    (false, _) => {
                        &self.levels[direct as usize][n.saturating_sub(1 + i).min(LEVELS - 1)]
                    }
                };
                b.texture("src", &src.1)
                    .texture("moments", &s.moments.output(parity).1)
                    .texture("dst", &dst.1)
                    .texture("out_history", &s.history.output(parity).1)
                    .buffer("level", level)
            }
        }
    }

    fn write_params(&self, gpu: &Gpu, cx: &FrameContext) {
        let s: &FrameSettings = cx.settings;
        gpu.queue.write_buffer(
            &self.pp,
            0,
            bytemuck::bytes_of(&ProgressiveParams::new(&s.progressive)),
        );
    }

    /// Every stage's programs, checked against what the frame and the filter offer.
    fn make_stages(
        &self,
        gpu: &Gpu,
        io: &FrameIo,
        t: &Targets,
        scene: &DenoiserScene,
    ) -> Result<Stages> {
        let (g, a) = (scene.glossy, scene.motion);
        let p = Parity::default();
        let matte = t.signals.first().map(|(g, s)| (*g, s)).context("no signal to filter")?;
        let m = modules("progressive/features.wgsl", Signal::Matte, g, a);
        let one = Levels { count: 1, feedback: false };
        let offered = self.bindings(io, t, matte, Pass::Features, p, one);
        let features = ChainStage::new(gpu, "progressive/features", &m, "main", &offered)?;
        let mut signals = vec![];
        for (signal, s) in &t.signals {
            let offered = [Pass::Temporal, Pass::Variance, Pass::Atrous(0)]
                .into_iter()
                .fold(self.bindings(io, t, (*signal, s), Pass::Features, p, one), |b, pass| {
                    b.with(&self.bindings(io, t, (*signal, s), pass, p, one))
                });
            let [lt, lv, la] = signal.labels();
            let stage = |label, file| {
                ChainStage::new(gpu, label, &modules(file, *signal, g, a), "main", &offered)
            };
            signals.push(SignalStages {
                temporal: stage(lt, "progressive/temporal.wgsl")?,
                variance: stage(lv, "progressive/variance.wgsl")?,
                atrous: stage(la, "progressive/atrous.wgsl")?,
            });
        }
        Ok(Stages { features, signals })
    }
}

impl Denoiser for Progressive {
    fn needs_previous_gbuffer(&self) -> bool {
        true
    }

    fn fills_untraced_pixels(&self) -> bool {
        true
    }

    /// Each signal's last level is what the composite reads, and which texture that is follows
    /// the level count ([`Placement`]); what the frame keeps is each signal's own.
    fn allocate(
        &mut self,
        gpu: &Gpu,
        memory: &mut GpuMemory,
        size: (u32, u32),
        kept: &[String],
        settings: &FrameSettings,
    ) -> Result<()> {
        let rw = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let features = memory.texture(&gpu.device, "progressive/features", size, RGBA32F, rw);
        let placement = Placement::of(settings);
        let mut shared = Shared::default();
        let signals = self
            .signals
            .iter()
            .map(|&s| {
                let how = (placement, &mut shared, kept);
                (s, SignalTargets::new(&gpu.device, memory, size, s.name(), how))
            })
            .collect();
        let levels = Levels::default();
        self.res.targets = Some(Targets { features, signals, levels, placement });
        Ok(())
    }

    fn layout(&self, settings: &FrameSettings) -> u64 {
        Placement::of(settings).key()
    }

    fn release(&mut self) {
        self.res.targets = None;
        let Some(st) = self.stages.as_mut() else { return };
        st.features.release_groups();
        for s in st.signals.iter_mut() {
            [&mut s.temporal, &mut s.variance, &mut s.atrous]
                .into_iter()
                .for_each(Stage::release_groups);
        }
    }

    fn record<'s>(
        &'s mut self,
        rec: &mut Recorder,
        io: &FrameIo,
        cx: &FrameContext,
    ) -> Result<Outputs<'s>> {
        let gpu = rec.gpu;
        let Progressive { scene, res, stages, .. } = self;
        let missing = "the progressive filter records before its textures exist";
        let t = res.targets.as_mut().context(missing)?;
        t.levels = levels_of(cx.settings);
        if t.placement.key() != Placement::of(cx.settings).key() {
            bail!("the progressive filter's textures were placed for another level count");
        }
        let t = res.targets.as_ref().context(missing)?;
        res.write_params(gpu, cx);
        let (key, parity, size, levels) = (cx.key, cx.parity, io.size, t.levels);
        let stages = crate::passes::chain::made(stages, || {
            res.make_stages(gpu, io, t, scene).context("creating the progressive filter's stages")
        })?;
        let matte = t.signals.first().map(|(g, s)| (*g, s)).context("no signal to filter")?;
        stages.features.record(
            rec,
            key,
            (parity, Pass::Features, levels),
            size,
            |(p, pass, l)| res.bindings(io, t, matte, pass, p, l),
        )?;
        for (st, (signal, s)) in stages.signals.iter_mut().zip(&t.signals) {
            let sig = (*signal, s);
            let b = |(p, pass, l)| res.bindings(io, t, sig, pass, p, l);
            st.temporal.record(rec, key, (parity, Pass::Temporal, levels), size, b)?;
            st.variance.record(rec, key, (parity, Pass::Variance, levels), size, b)?;
            for i in 0..levels.count {
                st.atrous.record(rec, key, (parity, Pass::Atrous(i), levels), size, b)?;
            }
        }
        Ok(outputs(t, follows_light(cx.settings)))
    }

    fn pipelines(&mut self) -> Vec<&mut dyn crate::shader::Reload> {
        let mut v: Vec<&mut dyn crate::shader::Reload> = vec![];
        let Some(stages) = self.stages.as_mut() else { return v };
        v.push(&mut stages.features.pipeline);
        for s in stages.signals.iter_mut() {
            v.extend(
                [&mut s.temporal, &mut s.variance, &mut s.atrous]
                    .into_iter()
                    .map(|s| &mut s.pipeline as &mut dyn crate::shader::Reload),
            );
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::SampleFraction;

    /// By default TAA follows the filter's light only where a frame traces one pixel in N > 1;
    /// `taa_follow` extends it to every fraction and `taa_follow_fractions` off takes it away.
    #[test]
    fn taa_follows_the_light_below_one_sample_per_pixel() {
        let at = |period: u32, follow: bool, fractions: bool| {
            let mut s = FrameSettings {
                sample_fraction: SampleFraction::one_in(period).unwrap(),
                ..Default::default()
            };
            s.progressive.taa_follow = follow;
            s.progressive.taa_follow_fractions = fractions;
            follows_light(&s)
        };
        let d = ProgressiveSettings::default();
        assert!(!at(1, d.taa_follow, d.taa_follow_fractions));
        assert!(at(16, d.taa_follow, d.taa_follow_fractions));
        assert!(!at(16, false, false));
        assert!(at(1, true, false));
    }
}
