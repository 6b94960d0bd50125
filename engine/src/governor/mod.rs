//! A frame-time governor: picks the resolution scale and the sample fraction (Dundr et al. §5)
//! that hold a target frame time on whatever device runs, from the frames it has seen, and
//! where neither can, fewer of the denoiser's a-trous levels.
//!
//! Model: a frame at scale s (of each side), fraction f and L a-trous levels costs
//! `fixed + s^2 (rest + level L + trace f)` ms, where `trace` is the trace pass's time per
//! full-resolution frame at f = 1, `level` one a-trous level's, `rest` the other passes that run
//! at the frame's resolution (raster, the rest of the denoiser), and `fixed` what no choice
//! changes: the wall time outside those passes (the CPU's recording, the viewer's UI and
//! present) and the display pass, which draws at the window's size. All four are re-estimated after every frame from its wall time and its
//! passes' GPU times, and smoothed by the median of the last [`WINDOW`] frames: one slow frame
//! (a hitch, a shader compile) moves nothing, a load that lasts (another program) is followed
//! within three frames, and two frames in a row over [`OVER`] x the frame's limit (a cut to a
//! heavier view) within two.
//!
//! Moving: among the scales [`SCALES`] down to `min_scale` and the fractions the denoiser
//! accepts, the largest scale whose best fraction fits the target, then the largest fraction
//! that fits (a fraction below 1/4 costs a step of scale first: a moving camera wants fresh
//! samples). Where the fixed cost alone leaves less than [`SCALABLE_FLOOR`] of the target, the
//! scaled part still gets that much: the frame rate is then the fixed cost's whatever the
//! choice, and a smaller image would buy almost none of it back.
//!
//! Still (the camera has not moved for [`STILL_AFTER`] frames): the samples accumulate, so what
//! a person sees improving is the samples traced per pixel per second, f / frame time, not the
//! frame rate. At its scale the governor takes the fraction that traces the most of them within
//! `still_ratio` x the target, the slowest frame a still view's UI may take. Where the frame
//! resamples its histories across a change of size (`keeps_history`, the frame's
//! `resample_history_frames`), a still view rises a step of scale each time its pixels have
//! gathered [`STILL_RISE_SAMPLES`] samples at the current one, as long as the larger scale has a
//! fraction of at least 1/8 within that limit: it keeps what it has accumulated, and the
//! converged image it heads for is sharper. Without resampling, a change restarts every history,
//! so the scale rises only after [`RISE_FRAMES`] frames in a row predicted under 80% of the
//! target at the larger scale, and on a still view only within [`YOUNG_FRAMES`] frames of its
//! last change. It falls at once when the prediction is over the frame's limit: while the
//! camera moves to the choice that fits the target, in a still view to the largest scale, at
//! or below its own, that fits the still limit.
//!
//! Levels: where even the smallest scale and fraction it may take overruns the frame's limit
//! (a pinned scale, a device too slow for the smallest), it drops the filter's widest levels
//! until the frame fits, down to [`min_levels`], and runs all of them again once they fit.

use crate::settings::SampleFraction;

/// Resolution scales the governor chooses among (per side), largest first.
pub const SCALES: [f32; 7] = [1.0, 0.875, 0.75, 0.625, 0.5, 0.375, 0.25];
/// Frames whose costs the estimate takes the median of.
pub const WINDOW: usize = 5;
/// Consecutive frames with room to spare before the scale goes up.
pub const RISE_FRAMES: u32 = 8;
/// Frames at one scale during which a still view may still rise from it (its history is young).
pub const YOUNG_FRAMES: u32 = 16;
/// Samples per pixel a still view gathers at one scale before it rises a step (where the
/// histories are resampled): as many as a resampled history counts by default
/// (`resample_history_frames`). Fewer rise sooner onto blurrier carried histories, more hold
/// the smaller scale longer. Time to quality on the level at 320x180 and 100 ms, FLIP 2 / 5 s:
/// 0.135 / 0.105 after a stop and 0.169 / 0.110 after a cut (with the scale kept and histories
/// restarted, 0.142 / 0.120 and 0.199 / 0.128; docs/decisions.md measures 2, 8 and a jump to
/// the largest scale).
pub const STILL_RISE_SAMPLES: f64 = 4.0;

/// A frame over this multiple of its limit counts towards a lasting overload.
pub const OVER: f64 = 1.5;
/// Frames without camera motion after which a view counts as still: a person stepping with
/// the keys pauses for a frame or two between steps, and a still view's frames are slower.
pub const STILL_AFTER: u32 = 3;
/// The share of the target the scaled part of a frame keeps when the fixed cost takes more.
pub const SCALABLE_FLOOR: f64 = 0.25;
/// A still view's frames may take this multiple of the target (`Governor::still_ratio`): at the
/// viewer's 100 ms on a software rasterizer, a person who starts to move waits at most half a
/// second for the frame in flight. There the default level's still view (scale 0.25, about
/// 300 ms a frame of UI, present and display) goes from 1/128 to 1/8 spp, and its FLIP after
/// 90 s from 0.186 to 0.076 (docs/decisions.md, "Fixed cost and still views").
pub const STILL_RATIO: f64 = 5.0;

/// What the a-trous levels' pass labels hold (`svgf/atrous_matte`, `progressive/atrous_direct`).
pub const ATROUS: &str = "/atrous";

/// [`Choice::levels`] that leaves the denoiser's a-trous levels as its settings have them.
pub const ALL_LEVELS: u32 = u32::MAX;

/// What the governor runs the next frame at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Choice {
    pub scale: f32,
    pub fraction: SampleFraction,
    /// At most this many of the denoiser's a-trous levels ([`ALL_LEVELS`]: as many as its
    /// settings ask; [`crate::settings::cap_filter_levels`] applies it).
    pub levels: u32,
}

impl FrameCost {
    /// A frame rendered at `choice` that took `wall_ms`, from its passes' GPU times (label, ms;
    /// the trace's is the part a sample fraction scales, the display's draws at the window's
    /// size and is not scaled).
    pub fn from_passes(
        wall_ms: f64,
        passes: &[(&'static str, f64)],
        choice: Choice,
        moving: bool,
    ) -> FrameCost {
        let sum = |keep: &dyn Fn(&str) -> bool| -> f64 {
            passes.iter().filter(|(l, _)| keep(l)).map(|(_, ms)| ms).sum()
        };
        let trace = crate::passes::trace::LABEL;
        let display = crate::passes::composite::DISPLAY;
        FrameCost {
            wall_ms,
            trace_ms: sum(&|l| l == trace),
            scaled_ms: sum(&|l| l != display),
            filter_ms: sum(&|l| l.contains(ATROUS)),
            choice,
            moving,
        }
    }
}

/// One finished frame as the governor sees it.
#[derive(Clone, Copy, Debug)]
pub struct FrameCost {
    /// Wall time from the start of the frame to the start of the next (ms).
    pub wall_ms: f64,
    /// The trace pass's GPU time (ms); 0 when the device has no timestamps.
    pub trace_ms: f64,
    /// GPU time of the passes that run at the frame's resolution, the trace's included (ms);
    /// 0 when the device has no timestamps: then all of the frame is taken to scale with the
    /// pixels.
    pub scaled_ms: f64,
    /// GPU time of the denoiser's a-trous levels, part of `scaled_ms` (ms).
    pub filter_ms: f64,
    /// The choice the frame ran at.
    pub choice: Choice,
    /// The camera moved since the last frame.
    pub moving: bool,
}

/// One frame's costs in the model's terms (ms): fixed, rest and trace per full-resolution
/// frame at f = 1, and one a-trous level per full-resolution frame (part of rest where the
/// frame ran none).
#[derive(Clone, Copy, Debug)]
struct Costs {
    fixed: f64,
    rest: f64,
    trace: f64,
    level: f64,
}

#[derive(Clone, Debug)]
pub struct Governor {
    /// The frame time to hold while the camera moves (ms).
    pub target_ms: f64,
    /// A still view's frames may take up to this multiple of `target_ms`, to trace more samples
    /// per second. 1 holds the target in a still view too.
    pub still_ratio: f64,
    /// The smallest scale it may pick.
    pub min_scale: f32,
    /// Knobs the user pinned: the governor keeps them and turns the other.
    pub pinned_scale: Option<f32>,
    pub pinned_fraction: Option<SampleFraction>,
    /// Whether fractions below 1 are allowed (the denoiser fills untraced pixels).
    pub fractions_allowed: bool,
    /// Whether the frame keeps its histories across a change of scale (resampled): a still
    /// view may then rise without losing what it has accumulated.
    pub keeps_history: bool,
    /// The a-trous levels the denoiser's settings ask for (0: it has none to turn down,
    /// [`crate::settings::filter_levels`]). Where no scale and fraction fits the frame's limit,
    /// the governor runs fewer ([`Choice::levels`]), each level it drops taking the filter's
    /// widest reach.
    pub filter_levels: u32,
    /// Recent costs, oldest first.
    costs: Vec<Costs>,
    current: Choice,
    /// The frame time the current choice was picked to stay within (ms).
    limit_ms: f64,
    room_frames: u32,
    /// Consecutive frames over OVER x their limit.
    over_frames: u32,
    /// The scale the last frame ran at, and how many frames in a row ran at it.
    last_scale: Option<f32>,
    scale_frames: u32,
    /// Samples per pixel traced at the current scale (the sum of its frames' fractions).
    scale_samples: f64,
    /// Consecutive frames without camera motion.
    still_frames: u32,
}

impl Governor {
    pub fn new(target_ms: f64) -> Governor {
        Governor {
            target_ms,
            still_ratio: STILL_RATIO,
            min_scale: 0.25,
            pinned_scale: None,
            pinned_fraction: None,
            fractions_allowed: false,
            keeps_history: true,
            filter_levels: 0,
            costs: vec![],
            current: Choice { scale: 1.0, fraction: SampleFraction::ONE, levels: ALL_LEVELS },
            limit_ms: target_ms,
            room_frames: 0,
            over_frames: 0,
            last_scale: None,
            scale_frames: 0,
            scale_samples: 0.0,
            still_frames: 0,
        }
    }

    /// The choice for the next frame (before any frame: full scale, every pixel, or the pins).
    pub fn choice(&self) -> Choice {
        Choice {
            scale: self.pinned_scale.unwrap_or(self.current.scale),
            fraction: self.pinned_fraction.unwrap_or(self.current.fraction),
            levels: self.current.levels,
        }
    }

    /// Whether the last frames were of a still view (the governor then trades frame rate for
    /// samples per second).
    pub fn still(&self) -> bool {
        self.still_frames >= STILL_AFTER
    }

    /// Predicted frame time (ms) of `c` from the current estimate; None before any frame.
    pub fn predict(&self, c: Choice) -> Option<f64> {
        let e = self.estimate()?;
        let area = (c.scale * c.scale) as f64;
        let levels = self.levels_run(c) as f64;
        Some(e.fixed + area * (e.rest + e.level * levels + e.trace / c.fraction.period() as f64))
    }

    /// The a-trous levels a frame at `c` runs.
    fn levels_run(&self, c: Choice) -> u32 {
        c.levels.min(self.filter_levels)
    }

    /// Samples traced per pixel per second at `c` (its fraction over its predicted frame time).
    pub fn samples_per_second(&self, c: Choice) -> Option<f64> {
        let t = self.predict(c)?;
        Some(1e3 / (c.fraction.period() as f64 * t.max(1e-6)))
    }

    /// Take a finished frame into account and choose the next.
    pub fn record(&mut self, f: FrameCost) -> Choice {
        let area = (f.choice.scale * f.choice.scale).max(1e-6) as f64;
        let period = f.choice.fraction.period() as f64;
        let wall = finite_or(f.wall_ms, 0.0).max(0.0);
        let scaled = finite_or(f.scaled_ms, 0.0).clamp(0.0, wall);
        let trace = finite_or(f.trace_ms, 0.0).clamp(0.0, scaled);
        // Without timestamps nothing is known of the fixed part: all of it scales.
        let fixed = if scaled > 0.0 { wall - scaled } else { 0.0 };
        let levels = self.levels_run(f.choice);
        let filter =
            if levels > 0 { finite_or(f.filter_ms, 0.0).clamp(0.0, scaled - trace) } else { 0.0 };
        self.costs.push(Costs {
            fixed,
            rest: (wall - fixed - trace - filter) / area,
            trace: trace * period / area,
            level: filter / levels.max(1) as f64 / area,
        });
        if self.costs.len() > WINDOW {
            self.costs.remove(0);
        }
        // Two frames in a row far over their limit (a cut to a heavier view): the older costs
        // no longer apply, so the estimate follows these two at once rather than after the
        // window's median turns (three frames). One such frame alone stays a hitch.
        self.over_frames = if wall > OVER * self.limit_ms { self.over_frames + 1 } else { 0 };
        if self.over_frames >= 2 {
            let n = self.costs.len();
            self.costs.drain(..n.saturating_sub(2));
        }
        let same_scale = self.last_scale == Some(f.choice.scale);
        self.last_scale = Some(f.choice.scale);
        self.scale_frames = if same_scale { self.scale_frames.saturating_add(1) } else { 1 };
        self.scale_samples = (if same_scale { self.scale_samples } else { 0.0 }) + 1.0 / period;
        self.still_frames = if f.moving { 0 } else { self.still_frames.saturating_add(1) };
        let pick = self.pick(f.moving);
        self.current = self.levels_within(pick, self.limit_ms);
        self.choice()
    }

    /// Median of the window, per component.
    fn estimate(&self) -> Option<Costs> {
        if self.costs.is_empty() {
            return None;
        }
        let median = |get: fn(&Costs) -> f64| {
            let mut v: Vec<f64> = self.costs.iter().map(get).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        Some(Costs {
            fixed: median(|c| c.fixed),
            rest: median(|c| c.rest),
            trace: median(|c| c.trace),
            level: median(|c| c.level),
        })
    }

    /// `c` with all of the denoiser's a-trous levels, or where even the smallest image and
    /// fraction would take longer than `limit` (the filter alone overruns it: a pinned scale,
    /// a slow device), with the most levels that fit, down to [`min_levels`].
    fn levels_within(&self, c: Choice, limit: f64) -> Choice {
        let all = Choice { levels: ALL_LEVELS, ..c };
        let least = min_levels(c.fraction);
        if self.filter_levels <= least || self.predict(all).is_none_or(|t| t <= limit) {
            return all;
        }
        let fits = |&levels: &u32| self.predict(Choice { levels, ..c }).is_some_and(|t| t <= limit);
        let levels = (least..self.filter_levels).rev().find(fits).unwrap_or(least);
        Choice { levels, ..c }
    }

    /// The frame time a moving camera's choice must fit: the target, or the fixed cost plus
    /// SCALABLE_FLOOR of the target where the fixed cost leaves less.
    fn budget(&self) -> f64 {
        let fixed = self.estimate().map_or(0.0, |e| e.fixed);
        self.target_ms.max(fixed + SCALABLE_FLOOR * self.target_ms)
    }

    fn fractions(&self) -> Vec<SampleFraction> {
        match self.pinned_fraction {
            Some(f) => vec![f],
            None if self.fractions_allowed => SampleFraction::all().collect(),
            None => vec![SampleFraction::ONE],
        }
    }

    fn scales(&self) -> Vec<f32> {
        match self.pinned_scale {
            Some(s) => vec![s],
            None => SCALES.iter().copied().filter(|&s| s >= self.min_scale - 1e-6).collect(),
        }
    }

    /// The largest fraction at scale `s` predicted within `budget` ms, none below 1 / `floor`.
    fn best_fraction(&self, s: f32, budget: f64, floor: u32) -> Option<SampleFraction> {
        self.fractions().into_iter().filter(|f| f.period() <= floor).find(|&fraction| {
            self.predict(Choice { scale: s, fraction, levels: ALL_LEVELS })
                .is_some_and(|t| t <= budget)
        })
    }

    /// A still view at `scale`: the fraction that traces the most samples per second within
    /// the still view's limit (None when none fits it).
    fn still_fraction(&self, scale: f32, limit: f64) -> Option<SampleFraction> {
        let rate = |f: SampleFraction| {
            let t = self
                .predict(Choice { scale, fraction: f, levels: ALL_LEVELS })
                .filter(|&t| t <= limit)?;
            Some((f, 1.0 / (f.period() as f64 * t.max(1e-6))))
        };
        self.fractions()
            .into_iter()
            .filter_map(rate)
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(f, _)| f)
    }

    /// A still view's step up from `scale`, where the histories are resampled and its pixels
    /// have gathered STILL_RISE_SAMPLES: the next larger scale at its still fraction, if that
    /// is at least 1/8 within `limit`.
    fn still_rise(&self, scale: f32, limit: f64) -> Option<Choice> {
        if !self.keeps_history || self.scale_samples < STILL_RISE_SAMPLES {
            return None;
        }
        let next = self.scales().into_iter().rev().find(|&s| s > scale + 1e-6)?;
        let fraction = self.still_fraction(next, limit).filter(|f| f.period() <= floor(false))?;
        Some(Choice { scale: next, fraction, levels: ALL_LEVELS })
    }

    fn pick(&mut self, moving: bool) -> Choice {
        let scales = self.scales();
        let budget = self.budget();
        let fits = |g: &Governor, budget: f64| -> Option<Choice> {
            for floor in [floor(moving), u32::MAX] {
                for &s in &scales {
                    if let Some(fraction) = g.best_fraction(s, budget, floor) {
                        return Some(Choice { scale: s, fraction, levels: ALL_LEVELS });
                    }
                }
            }
            None
        };
        let smallest = Choice {
            scale: *scales.last().unwrap_or(&1.0),
            fraction: *self.fractions().last().unwrap_or(&SampleFraction::ONE),
            levels: ALL_LEVELS,
        };
        let want = fits(self, budget).unwrap_or(smallest);
        let cur = self.choice();
        self.limit_ms = budget;
        // Rise after RISE_FRAMES frames that would fit the larger scale with room; on a still
        // view without resampled histories only while the history at this scale is young: a
        // rise restarts every history, which on a settled view trades converged light for a
        // noisy image (time-to-quality, level 320x180: FLIP 0.156 -> 0.499 at a rise 0.84 s
        // after a stop, back to 0.156 only after 3.6 s), while a scale chosen from the first
        // frames (a shader compile) must not stay until the camera moves.
        let rises = want.scale > cur.scale && {
            let young = moving || (!self.keeps_history && self.scale_frames < YOUNG_FRAMES);
            let roomy = young && fits(self, 0.8 * budget).is_some_and(|c| c.scale > cur.scale);
            self.room_frames = if roomy { self.room_frames + 1 } else { 0 };
            self.room_frames >= RISE_FRAMES
        };
        if !moving && self.still() && !rises {
            // A still view rises a step where its history comes along (resampled), else keeps
            // its scale, at the fraction that traces the most samples per second within the
            // still limit.
            let limit = budget.max(self.still_ratio * self.target_ms);
            if let Some(rise) = self.still_rise(cur.scale, limit) {
                self.room_frames = 0;
                self.limit_ms = limit;
                return rise;
            }
            // Where its scale no longer fits (a heavier view, a rise predicted too low), it
            // steps down only as far as the still limit asks: the moving target's choice (the
            // smallest scale, on lavapipe) would trade a settled view for a far smaller image.
            let fitting = |s: f32| self.still_fraction(s, limit).map(|f| (s, f));
            let at_most = |s: &f32| *s <= cur.scale + 1e-6;
            if let Some((scale, fraction)) =
                scales.iter().copied().filter(at_most).find_map(fitting)
            {
                self.limit_ms = limit;
                return Choice { scale, fraction, levels: ALL_LEVELS };
            }
        }
        if want.scale > cur.scale && !rises {
            let fraction = self
                .best_fraction(cur.scale, budget, floor(moving))
                .or_else(|| self.best_fraction(cur.scale, budget, u32::MAX))
                .unwrap_or(smallest.fraction);
            return Choice { scale: cur.scale, fraction, levels: ALL_LEVELS };
        }
        self.room_frames = 0;
        want
    }
}

/// The smallest fraction (as a period) taken before a step of scale: while the camera moves it
/// wants fresh samples (1/4); a still view accumulates, but below 1/8 a pixel waits so long
/// for its next sample that a smaller scale converges sooner (time-to-quality on the level at
/// 320x180 and 100 ms, FLIP 5 s after a cut: 0.133 pinned at 1/4, 0.147 at 1/8, 0.176 at 1/16,
/// 0.183 when free to go to 1/64).
fn floor(moving: bool) -> u32 {
    if moving { 4 } else { 8 }
}

/// The fewest a-trous levels the governor runs at `fraction`: one, or where the frame traces a
/// pixel of each tile (passes/schedule.rs), enough to reach across the tile's longer side
/// (levels step 1 to 2^(L-1) pixels, so they reach 2^L - 1): fewer would leave the pixels far
/// from this frame's samples to their history alone, and a fresh one black.
pub fn min_levels(fraction: SampleFraction) -> u32 {
    let (w, h) = crate::passes::schedule::tile(fraction.period());
    (w.max(h) + 1).next_power_of_two().trailing_zeros().max(1)
}

fn finite_or(v: f64, or: f64) -> f64 {
    if v.is_finite() { v } else { or }
}

#[cfg(test)]
mod tests;
