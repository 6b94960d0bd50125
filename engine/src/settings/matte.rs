//! The matte chain's settings (Mara et al. 2017 §3.4, stages 3-7) and their descriptions.

use super::field::{Field, Kind::*, f};
use serde::{Deserialize, Serialize};

/// The matte chain of Mara et al. 2017, §3.4 (stages 3-7 of Figure 2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MatteSettings {
    /// Stage switches.
    pub temporal: bool,
    pub history_bilateral: bool,
    pub disocclusion: bool,
    /// The 3x3 median (stage 6) is off by default: on the level it cost FLIP everywhere it was
    /// measured (160x90, 128-frame references, a 60-frame path of 20 still, 20 strafing and 20
    /// still frames; with the 1 / sqrt(n) history disk): still 0.1188 on, 0.0890 off; moving
    /// 0.1146 and 0.1058; settled 0.0940 and 0.0892. The median removes energy that fireflies
    /// carry and the reference keeps.
    pub firefly: bool,
    pub bilateral: bool,
    /// Hysteresis h of eq. (11) (paper: 0.98).
    pub hysteresis: f32,
    /// Eq. (11)'s d0 and d1 in pixel footprints at the surface (the paper's 5 cm and 7 cm are
    /// about 6 and 8.5 footprints at 5 m in a 720p, 60-degree view; a footprint keeps the test
    /// the same at any scene scale and resolution).
    pub d0_px: f32,
    pub d1_px: f32,
    /// History is clamped to the current neighbourhood's mean +- this many standard deviations
    /// (Mara et al. §3.4); 0 switches the clamp off, the default. At one sample per pixel the
    /// neighbourhood of an indirectly lit pixel is mostly zeros, and the clamp erases a correct
    /// history: the living room's interior (160x90, 60 frames) came out at 0.049 of a reference
    /// mean of 0.176 with a 4-sigma clamp over 3x3, 0.112 over 33 samples, and 0.173 with no
    /// clamp; cornell_diffuse's FLIP went from 0.081 (4 sigma) to 0.074. Without it, history
    /// lags lighting changes by about 1 / (1 - h) frames; geometric changes still reset it
    /// through the confidence c.
    pub clamp_sigma: f32,
    /// Eq. (11)'s reprojection also rejects a previous texel whose normal is more than this
    /// many degrees from the surface's (180: no normal test, the paper's position test alone,
    /// the default). Matte light varies slowly across a crease, and the test only shortens
    /// histories: FLIP at 160x90, 60 still frames (as GlossySettings::reprojection_normal_degrees
    /// measures, glossy test at 25 degrees) off, at 25 and at 45 degrees: staircase 0.0655,
    /// 0.0675, 0.0688; level 0.0481, 0.0493, 0.0492; living room 0.1632, 0.1728 at 25.
    pub reprojection_normal_degrees: f32,
    /// Taps of the sparse bilateral filters (paper: 50).
    pub taps: u32,
    /// Disk diameter of the history-loop bilateral as a fraction of the screen width (paper: 1%).
    pub history_diameter_fraction: f32,
    /// Beyond this many frames of history the history bilateral's disk shrinks as
    /// 1 / sqrt(history length). The filter runs on the history every frame, so with a fixed
    /// disk its blur compounds: a sample n frames old has been blurred n times, a radius that
    /// grows as sqrt(n). Shrinking the disk as 1 / sqrt(n) keeps that growth logarithmic, while
    /// a fresh history (disocclusion, motion) gets the whole disk. 0: the paper's fixed disk.
    /// Level, 320x180, 60 still frames, 256-frame reference (glossy clipping and bilateral off,
    /// firefly off): FLIP 0.0644 with the fixed disk, 0.0618 past 4 frames, 0.0605 past 1 (the
    /// default).
    pub history_full_frames: f32,
    /// A history resampled bilinearly (the surface moved on screen since the last frame) counts
    /// as at most this many frames, so that its new sample weighs at least 1 / (this + 1). Each
    /// resampling blurs the history a little, and at the paper's 1 - h = 2% a strafe's blur
    /// outlived it: when the camera stopped, the level took over 20 frames to reach the FLIP a
    /// fresh start reached in 10. Texels read exactly (a still view) keep their whole length.
    /// 0: no cap (the paper's blend). Level at 160x90, 20 still, 20 strafing (1.2 m) and 20
    /// still frames, 128-frame references, FLIP 10 frames after the stop (fresh start at the
    /// same view after 10 frames: 0.0774) / moving mean: no cap 0.0830 / 0.1030, 24 frames
    /// 0.0811 / 0.1028, 8 frames 0.0805 / 0.1014, 4 frames 0.0820 / 0.1020 (TAA restarting as
    /// TaaSettings::resampled_frames; the glossy chain uncapped; these caps counted the
    /// new frame among the 8). As shipped, with the glossy chain's cap too: 0.0720 / 0.1002.
    pub resampled_history_frames: f32,
    /// R of the disocclusion radius as a fraction of the screen width (paper: 1/20).
    pub disocclusion_fraction: f32,
    /// Radius multiplier where the confidence c < 1/2 (paper: 6).
    pub low_confidence_multiplier: f32,
    /// Largest final-bilateral radius as a fraction of the screen width.
    pub max_radius_fraction: f32,
    /// Smallest final-bilateral radius as a fraction of the screen width (0: the paper's
    /// r = (1 - c) R alone, which at full confidence is 2% of R, a fraction of a pixel). Stage
    /// (7) is outside the history loop, so its blur does not compound; a still view's history
    /// of tens of frames still carries noise it removes. FLIP at 160x90, 60 still frames,
    /// 256-frame references (living room, level, FlightHelmet): 0 gives 0.1778, 0.0601 and
    /// 0.0113; 3% without an edge-stop 0.1652, 0.0565 and 0.0125; 5% (with edge_stop_sigmas
    /// 4) 0.1710 and 0.0586 on the first two: the 50 taps spread thinner.
    pub min_radius_fraction: f32,
    /// The final bilateral also weighs taps by exp(-|luminance difference| / (k sigma)), sigma
    /// the standard deviation of the history's mean (the input's spread over 16 taps on the
    /// surface, over sqrt(history length)): SVGF's luminance edge-stop. A converged history
    /// then keeps the fine shading (FlightHelmet's contact shadows) that the minimum radius
    /// would blur, while a noisy one is still filtered. 0: no edge-stop. FLIP as above (living
    /// room, level, FlightHelmet) for k = 4, 8, 16: 0.1676 / 0.0574 / 0.0116, 0.1664 / 0.0567 /
    /// 0.0119, 0.1657 / 0.0560 / 0.0122; Lantern 0.0023 with 4 and 16, 0.0025 with none.
    /// The luminance difference is now taken on a guide, each pixel's 3x3 mean on its surface,
    /// against the guide's noise (sigma / 3), and sigma comes from the input minus the
    /// history's mean, not the input's spread (shaders/matte/bilateral.wgsl). FLIP at 160x90,
    /// 60 still frames (second half / last frame; staircase 160x284), taps' own luminance and
    /// spread against the guide and residual, k = 8: living room 0.1541 / 0.1414 and 0.1467 /
    /// 0.1358, staircase 0.0642 / 0.0610 and 0.0591 / 0.0562, level 0.0483 / 0.0458 and
    /// 0.0469 / 0.0444. The residual alone: living room 0.1567 / 0.1441, staircase 0.0634 /
    /// 0.0602; with k = 2 as well, staircase 0.0609 / 0.0566, but the spread with k = 2 took
    /// the living room to 0.1566 / 0.1423: a smaller k kept the staircase's contact shadows,
    /// and the noise differences between single taps cost the living room its filtering.
    pub edge_stop_sigmas: f32,
    /// Bilateral weights: cosine power on normals, plane-distance sigma in pixel footprints.
    pub normal_power: f32,
    pub plane_sigma_px: f32,
    /// Fault injection for tests: the temporal stage reads NaN, +Inf and -Inf in place of the
    /// matte light on a sparse pixel pattern (1 in 7).
    #[serde(skip)]
    pub inject_nonfinite: bool,
}

impl Default for MatteSettings {
    fn default() -> Self {
        MatteSettings {
            temporal: true,
            history_bilateral: true,
            disocclusion: true,
            firefly: false,
            bilateral: true,
            hysteresis: 0.98,
            d0_px: 6.0,
            d1_px: 8.5,
            clamp_sigma: 0.0,
            reprojection_normal_degrees: 180.0,
            taps: 50,
            history_diameter_fraction: 0.01,
            history_full_frames: 1.0,
            resampled_history_frames: 8.0,
            disocclusion_fraction: 0.05,
            low_confidence_multiplier: 6.0,
            max_radius_fraction: 0.1,
            min_radius_fraction: 0.03,
            edge_stop_sigmas: 8.0,
            normal_power: 32.0,
            plane_sigma_px: 2.0,
            inject_nonfinite: false,
        }
    }
}

impl MatteSettings {
    /// Stage bits as the shaders read them (shaders/matte/common.wgsl: STAGE_*; TAA's bit is
    /// [`super::TaaSettings::stage_bit`]).
    pub fn stage_bits(&self) -> u32 {
        [self.temporal, self.history_bilateral, self.disocclusion, self.firefly, self.bilateral]
            .iter()
            .enumerate()
            .map(|(i, on)| (*on as u32) << i)
            .sum()
    }
}

/// Its fields, in panel order.
pub const FIELDS: &[Field] = &[
    f(
        "matte.temporal",
        "matte/temporal",
        "",
        Bool,
        "Stage 3: reverse reprojection with confidence (Mara eq. 11).",
    ),
    f(
        "matte.hysteresis",
        "matte/temporal",
        "",
        Float(0.0, 1.0, 0.001),
        "h of eq. 11: the history's weight at full confidence (paper 0.98).",
    ),
    f(
        "matte.d0_px",
        "matte/temporal",
        "footprints",
        Float(0.0, 64.0, 0.05),
        "Eq. 11's d0: full confidence below this reprojection distance.",
    ),
    f(
        "matte.d1_px",
        "matte/temporal",
        "footprints",
        Float(0.0, 64.0, 0.05),
        "Eq. 11's d1: zero confidence beyond this reprojection distance.",
    ),
    f(
        "matte.clamp_sigma",
        "matte/temporal",
        "sigma",
        Float(0.0, 16.0, 0.05),
        "Clamp history to the neighbourhood's mean +- this many deviations (0: off).",
    ),
    f(
        "matte.reprojection_normal_degrees",
        "matte/temporal",
        "degrees",
        Float(0.0, 180.0, 0.5),
        "Reprojection rejects a previous texel whose normal differs by more (180: off).",
    ),
    f(
        "matte.history_bilateral",
        "matte/history_bilateral",
        "",
        Bool,
        "Stage 4: sparse bilateral on what is written back to history.",
    ),
    f(
        "matte.taps",
        "matte/history_bilateral",
        "taps",
        Int(1, 256),
        "Taps of both sparse bilaterals (paper 50).",
    ),
    f(
        "matte.history_diameter_fraction",
        "matte/history_bilateral",
        "of width",
        Float(0.0, 0.2, 0.0005),
        "Disk diameter of the history bilateral (paper 1%).",
    ),
    f(
        "matte.history_full_frames",
        "matte/history_bilateral",
        "frames",
        Float(0.0, 1024.0, 0.1),
        "Past this history length the disk shrinks as 1/sqrt(length) (0: fixed).",
    ),
    f(
        "matte.resampled_history_frames",
        "matte/temporal",
        "frames",
        Float(0.0, 1024.0, 1.0),
        "A bilinearly resampled history counts as at most this many frames (0: no cap).",
    ),
    f(
        "matte.normal_power",
        "matte/history_bilateral",
        "exponent",
        Float(0.0, 512.0, 0.5),
        "Bilateral normal weight: cos^power (both sparse bilaterals).",
    ),
    f(
        "matte.plane_sigma_px",
        "matte/history_bilateral",
        "footprints",
        Float(0.0, 64.0, 0.05),
        "Bilateral plane-distance sigma (both sparse bilaterals).",
    ),
    f(
        "matte.disocclusion",
        "matte/disocclusion",
        "",
        Bool,
        "Stage 5: the disocclusion-driven radius r = (1 - min c) R.",
    ),
    f(
        "matte.disocclusion_fraction",
        "matte/disocclusion",
        "of width",
        Float(0.0, 0.5, 0.001),
        "R as a fraction of the width (paper 1/20).",
    ),
    f(
        "matte.low_confidence_multiplier",
        "matte/disocclusion",
        "x",
        Float(1.0, 32.0, 0.05),
        "Radius multiplier where c < 1/2 (paper 6).",
    ),
    f("matte.firefly", "matte/firefly", "", Bool, "Stage 6: 3x3 median outside the history loop."),
    f(
        "matte.bilateral",
        "matte/bilateral",
        "",
        Bool,
        "Stage 7: final sparse bilateral with radius r.",
    ),
    f(
        "matte.max_radius_fraction",
        "matte/bilateral",
        "of width",
        Float(0.0, 0.5, 0.001),
        "Largest final-bilateral radius.",
    ),
    f(
        "matte.min_radius_fraction",
        "matte/bilateral",
        "of width",
        Float(0.0, 0.5, 0.001),
        "Smallest final-bilateral radius (0: the paper's (1 - c) R alone).",
    ),
    f(
        "matte.edge_stop_sigmas",
        "matte/bilateral",
        "sigma",
        Float(0.0, 256.0, 0.5),
        "Final bilateral's luminance edge-stop, in standard deviations of the history's noise (0: none).",
    ),
];
