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
    /// Stage 6, the 3x3 firefly median; default off: on the level it raised FLIP (60 still
    /// frames: 0.1188 on, 0.0890 off), removing energy that fireflies carry and the reference keeps.
    pub firefly: bool,
    pub bilateral: bool,
    /// Hysteresis h of eq. (11) (paper: 0.98).
    pub hysteresis: f32,
    /// Eq. (11)'s d0 and d1 in pixel footprints at the surface (the paper's 5 cm and 7 cm are
    /// about 6 and 8.5 footprints at 5 m in a 720p, 60-degree view; a footprint keeps the test
    /// the same at any scene scale and resolution).
    pub d0_px: f32,
    pub d1_px: f32,
    /// History clamp to the neighbourhood's mean +- k standard deviations (Mara §3.4), k in [0, 16],
    /// default 0 (off): at one sample per pixel it erases correct indirect history (living room
    /// interior 0.049 of a 0.176 mean at 4 sigma); off, lighting changes lag about 1 / (1 - h) frames.
    pub clamp_sigma: f32,
    /// Reprojection also rejects a texel whose normal is more than this many degrees off, [0, 180],
    /// default 180 (off): matte light varies slowly across a crease and the test only shortens
    /// histories (staircase FLIP 0.0655 off, 0.0675 at 25 degrees).
    pub reprojection_normal_degrees: f32,
    /// Taps of the sparse bilateral filters (paper: 50).
    pub taps: u32,
    /// Disk diameter of the history-loop bilateral as a fraction of the screen width (paper: 1%).
    pub history_diameter_fraction: f32,
    /// Frames of history past which the history bilateral's disk shrinks as 1 / sqrt(n), default 1
    /// (0: the paper's fixed disk): keeps the loop's compounding blur logarithmic (level FLIP
    /// 0.0605, 0.0644 with the fixed disk).
    pub history_full_frames: f32,
    /// The most frames a bilinearly resampled history counts as, default 8 (0: no cap): a strafe's
    /// blur fades within frames of a stop (level FLIP 10 frames after: 0.0720, uncapped 0.0830)
    /// at a noisier moving image.
    pub resampled_history_frames: f32,
    /// R of the disocclusion radius as a fraction of the screen width (paper: 1/20).
    pub disocclusion_fraction: f32,
    /// Radius multiplier where the confidence c < 1/2 (paper: 6).
    pub low_confidence_multiplier: f32,
    /// Largest final-bilateral radius as a fraction of the screen width.
    pub max_radius_fraction: f32,
    /// Smallest final-bilateral radius, [0, 0.5] of the screen width, default 0.03 (0: Mara's
    /// r = (1 - c) R): outside the history loop it removes a still history's residual noise (living
    /// room FLIP 0.1652 against 0.1778) at a cost on fine detail (FlightHelmet 0.0125 against 0.0113).
    pub min_radius_fraction: f32,
    /// The final bilateral's luminance edge-stop, k standard deviations of the guide's noise,
    /// default 8 (0: none): keeps converged shading the minimum radius would blur (second half /
    /// last frame FLIP: living room 0.1467 / 0.1358, level 0.0469 / 0.0444).
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
