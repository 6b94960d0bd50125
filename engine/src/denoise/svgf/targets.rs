//! SVGF's textures, as the frame graph ([`crate::gpu::graph`]) places them: every pass's
//! textures are listed once ([`textures`]), by the WGSL name that binds them (`dst` and `out_*`
//! are written, the rest read), and both the graph and the bind groups are made from that list.
//! The histories (integrated light, moments, the reflection's hit) outlive the frame; the rest
//! live from their writer to their last reader, in a pool shared by textures whose lives do not
//! overlap (the glossy signal's passes reuse the matte signal's memory).

use crate::gpu::{FrameGraph, GpuMemory, GraphError, Parity, Tex, TransientPool};
use std::collections::HashMap;

const RGBA16F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Histories: a still view's mean of 1 / h steps would stall in 16-bit halves after about a
/// thousand frames. The integrated light is 32-bit as the history it is copied to.
const RGBA32F: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub(super) const LEVELS: usize = crate::settings::SVGF_MAX_LEVELS as usize;

/// One of SVGF's two signals.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum Chain {
    Matte,
    Glossy,
}

impl Chain {
    pub fn name(self) -> &'static str {
        match self {
            Chain::Matte => "matte",
            Chain::Glossy => "glossy",
        }
    }
}

/// Which textures a stage binds, by stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum Pass {
    Temporal,
    /// The variance stage and the spike cut: the a-trous levels' input, taps and excess light.
    Variance,
    /// Level i: reads the variance stage's output (level 0), then pong and ping in turn; level 0
    /// also writes the next frame's history.
    Atrous(usize),
    /// The integrated light copied into the history where no level wrote it (a texture copy).
    HistoryCopy,
    /// The spike cut's spread: the rows' sums of the cut light (false), then their columns'
    /// mean (true).
    Spread(bool),
    /// Reads the last level's output: 0 the variance stage's (no level ran), 1 ping, 2 pong.
    Regression(usize),
    /// Reads the regression's output.
    Final,
    /// The glossy signal's reflection motion (Mara's `glossy/motion` on SVGF's textures).
    Motion,
    /// The clip's neighbourhood, blurred in rows (false) then columns (true).
    Prefilter(bool),
}

/// What a stage binds under one of its WGSL names.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Bound {
    /// One of SVGF's textures, by label.
    Own(String),
    /// What the frame offers under this name (the trace's light, for a read the program never
    /// makes at run time).
    Frame(&'static str),
}

/// Whether the WGSL name `name` is written by its pass (`dst`, `out_*`).
pub(super) fn writes(name: &str) -> bool {
    name == "dst" || name.starts_with("out_")
}

fn label(c: Chain, what: &str) -> String {
    format!("svgf/{} {what}", c.name())
}

/// The label of a signal's (`matte`, `glossy`) luminance moments and history length in history
/// slot 0 or 1.
pub fn moments_label(signal: &str, slot: usize) -> String {
    format!("svgf/{signal} moments {slot}")
}

const FEATURES: &str = "svgf/features";

/// What `pass` of `c` binds at history parity `p`, by WGSL name (what `sv`, `dn`, `gp` and the
/// frame's I/O offer aside).
pub(super) fn textures(c: Chain, pass: Pass, p: Parity) -> Vec<(&'static str, Bound)> {
    let own = |what: &str| Bound::Own(label(c, what));
    let (now, next) = (p.index(), 1 - p.index());
    let history = |slot: usize| own(&format!("history {slot}"));
    let moments = |slot: usize| Bound::Own(moments_label(c.name(), slot));
    let hit = |slot: usize| Bound::Own(label(Chain::Glossy, &format!("hit {slot}")));
    let glossy = |what: &str| Bound::Own(label(Chain::Glossy, what));
    let features = ("features", Bound::Own(FEATURES.into()));
    let mut v = match pass {
        Pass::Temporal => {
            let mut v = vec![
                ("history", history(now)),
                ("moments", moments(now)),
                ("out_integrated", own("integrated")),
                ("out_moments", moments(next)),
                ("out_state", own("state")),
            ];
            match c {
                Chain::Matte => v.push(("out_features", Bound::Own(FEATURES.into()))),
                Chain::Glossy => v.extend([
                    ("prev_hit", hit(now)),
                    ("motion", glossy("motion")),
                    ("neighbourhood", glossy("neighbourhood")),
                ]),
            }
            return v;
        }
        Pass::Variance => vec![
            ("integrated", own("integrated")),
            ("moments", moments(next)),
            ("dst", own("variance")),
            ("out_taps", own("taps")),
            ("out_excess", own("excess")),
        ],
        Pass::Atrous(level) => {
            let src = match level {
                0 => "variance",
                l if l % 2 == 1 => "pong",
                _ => "ping",
            };
            vec![
                ("src", own(src)),
                ("dst", own(if level % 2 == 0 { "pong" } else { "ping" })),
                ("taps", own("taps")),
                ("moments", moments(next)),
                ("out_history", history(next)),
            ]
        }
        Pass::HistoryCopy => return vec![("src", own("integrated")), ("dst", history(next))],
        Pass::Spread(columns) => {
            let (src, dst) =
                if columns { ("spread rows", "spread") } else { ("excess", "spread rows") };
            vec![
                ("src", own(src)),
                ("dst", own(dst)),
                ("taps", own("taps")),
                ("moments", moments(next)),
            ]
        }
        Pass::Regression(last) => vec![
            ("src", own(["variance", "ping", "pong"][last])),
            ("light", own("variance")),
            ("excess", own("excess")),
            ("taps", own("taps")),
            ("moments", moments(next)),
            ("spread", own("spread")),
            ("dst", own("regressed")),
        ],
        Pass::Final => {
            vec![("src", own("regressed")), ("moments", moments(next)), ("dst", own("out"))]
        }
        Pass::Motion => {
            return vec![
                ("prev_hit", hit(now)),
                ("out_motion", glossy("motion")),
                ("out_search", glossy("search")),
                ("out_hit", hit(next)),
            ];
        }
        // The rows' pass blurs the trace's light: its `src` is declared by the program the two
        // passes share but never read.
        Pass::Prefilter(false) => {
            return vec![("src", Bound::Frame("tr_glossy")), ("dst", glossy("scratch"))];
        }
        Pass::Prefilter(true) => {
            return vec![("src", glossy("scratch")), ("dst", glossy("neighbourhood"))];
        }
    };
    v.push(features);
    v
}

/// The name the profiler knows a pass by (with its level for the a-trous levels).
fn pass_name(c: Chain, p: Pass) -> String {
    let stage = match p {
        Pass::Temporal => "temporal",
        Pass::Variance => "variance",
        Pass::Atrous(l) => return format!("svgf/atrous_{} {l}", c.name()),
        Pass::HistoryCopy => "history_copy",
        Pass::Spread(false) => "spread_h",
        Pass::Spread(true) => "spread_v",
        Pass::Regression(_) => "regression",
        Pass::Final => "final",
        Pass::Motion => return "svgf/motion".into(),
        Pass::Prefilter(false) => return "svgf/prefilter_h".into(),
        Pass::Prefilter(true) => return "svgf/prefilter_v".into(),
    };
    format!("svgf/{stage}_{}", c.name())
}

/// Every pass SVGF may record, in the order it records them, with the name the graph knows it
/// by: a setting that skips a pass only shortens lives, so one plan holds for every setting.
pub(super) fn passes(glossy: bool) -> Vec<(String, Chain, Vec<Pass>)> {
    let chain = |c: Chain| {
        let mut v = vec![Pass::Temporal, Pass::Variance];
        v.extend((0..LEVELS).map(Pass::Atrous));
        v.extend([Pass::HistoryCopy, Pass::Spread(false), Pass::Spread(true)]);
        v.push(Pass::Regression(0));
        v.push(Pass::Final);
        v.into_iter().map(move |p| {
            // A regression is recorded in one of three variants: the graph sees all three.
            let variants = match p {
                Pass::Regression(_) => (0..3).map(Pass::Regression).collect(),
                p => vec![p],
            };
            (pass_name(c, p), c, variants)
        })
    };
    let mut v: Vec<_> = chain(Chain::Matte).collect();
    if glossy {
        for p in [Pass::Motion, Pass::Prefilter(false), Pass::Prefilter(true)] {
            v.push((pass_name(Chain::Glossy, p), Chain::Glossy, vec![p]));
        }
        v.extend(chain(Chain::Glossy));
    }
    v
}

/// SVGF's frame graph: its textures, its passes and what the frame reads after them (the
/// composite's light, what TAA follows, and every texture whose label starts with one of
/// `kept`: a debug view, a test's readback).
pub(super) fn graph(glossy: bool, kept: &[String]) -> FrameGraph {
    let mut g = FrameGraph::default();
    g.transient(FEATURES, wgpu::TextureFormat::Rg32Float);
    let chains: &[Chain] = if glossy { &[Chain::Matte, Chain::Glossy] } else { &[Chain::Matte] };
    for &c in chains {
        let l = |what: &str| label(c, what);
        for slot in 0..2 {
            g.history(&l(&format!("history {slot}")), RGBA32F);
            g.history(&moments_label(c.name(), slot), RGBA32F);
        }
        g.transient(&l("integrated"), RGBA32F);
        g.transient(&l("taps"), wgpu::TextureFormat::Rgba32Uint);
        g.transient(&l("state"), wgpu::TextureFormat::R32Uint);
        for what in ["variance", "excess", "ping", "pong", "regressed", "spread rows", "spread"] {
            g.transient(&l(what), RGBA16F);
        }
        g.transient(&l("out"), RGBA16F).output(&l("out"));
    }
    g.output(&label(Chain::Matte, "state"));
    if glossy {
        let l = |what: &str| label(Chain::Glossy, what);
        g.history(&l("hit 0"), RGBA32F).history(&l("hit 1"), RGBA32F);
        g.transient(&l("motion"), RGBA32F);
        for what in ["search", "neighbourhood", "scratch"] {
            g.transient(&l(what), RGBA16F);
        }
    }
    for (name, c, variants) in passes(glossy) {
        let (mut reads, mut written) = (vec![], vec![]);
        for pass in variants {
            for (wgsl, bound) in textures(c, pass, Parity::default()) {
                let Bound::Own(t) = bound else { continue };
                let to = if writes(wgsl) { &mut written } else { &mut reads };
                if !to.contains(&t) {
                    to.push(t);
                }
            }
        }
        let reads: Vec<&str> = reads.iter().map(String::as_str).collect();
        let written: Vec<&str> = written.iter().map(String::as_str).collect();
        g.pass(&name, &reads, &written);
    }
    let kept: Vec<String> = g
        .transients()
        .filter(|t| crate::gpu::graph::is_kept(kept, t))
        .map(str::to_string)
        .collect();
    for k in &kept {
        g.output(k);
    }
    g
}

/// SVGF's textures at one size: its histories, and its transients' pool.
pub struct SvgfTargets {
    histories: HashMap<String, Tex>,
    pool: TransientPool,
    /// Every stage's textures by WGSL name, resolved once.
    resolved: HashMap<(Chain, Pass, Parity), Vec<Binding>>,
}

/// A stage's texture under its WGSL name.
type Binding = (&'static str, Resolved);

/// A stage's texture, resolved from [`Bound`].
#[derive(Clone)]
pub(super) enum Resolved {
    Own(Tex),
    Frame(&'static str),
}

impl SvgfTargets {
    /// Place and make SVGF's textures for frames of `size`, `kept` living to the end of the
    /// frame (readable after it) besides the outputs.
    pub fn new(
        d: &wgpu::Device,
        mem: &mut GpuMemory,
        size: (u32, u32),
        glossy: bool,
        kept: &[String],
    ) -> Result<SvgfTargets, GraphError> {
        let g = graph(glossy, kept);
        let plan = g.plan()?;
        let usage = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST;
        let histories = g
            .histories()
            .map(|(name, f)| (name.to_string(), mem.texture(d, name, size, f, usage)))
            .collect();
        let pool = TransientPool::new(d, mem, "svgf/", plan, size, usage);
        let mut t = SvgfTargets { histories, pool, resolved: HashMap::new() };
        for (_, c, variants) in passes(glossy) {
            for pass in variants {
                for p in Parity::BOTH {
                    let bound = textures(c, pass, p)
                        .into_iter()
                        .map(|(wgsl, b)| {
                            let r = match b {
                                Bound::Own(name) => Resolved::Own(t.tex(&name)?.clone()),
                                Bound::Frame(n) => Resolved::Frame(n),
                            };
                            Ok((wgsl, r))
                        })
                        .collect::<Result<_, GraphError>>()?;
                    t.resolved.insert((c, pass, p), bound);
                }
            }
        }
        Ok(t)
    }

    fn tex(&self, name: &str) -> Result<&Tex, GraphError> {
        let undeclared = || GraphError::Undeclared { pass: "svgf".into(), texture: name.into() };
        self.histories.get(name).or_else(|| self.pool.tex(name)).ok_or_else(undeclared)
    }

    /// What `pass` of `c` binds at parity `p`, by WGSL name.
    pub(super) fn bound(&self, c: Chain, pass: Pass, p: Parity) -> &[Binding] {
        self.resolved.get(&(c, pass, p)).map_or(&[], Vec::as_slice)
    }

    pub(super) fn out(&self, c: Chain) -> Option<&Tex> {
        self.tex(&label(c, "out")).ok()
    }

    pub(super) fn state(&self, c: Chain) -> Option<&Tex> {
        self.tex(&label(c, "state")).ok()
    }
}
