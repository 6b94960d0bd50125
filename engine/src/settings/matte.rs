//! The matte chain's settings (Mara et al. 2017 §3.4, stages 3-7) and their descriptions.

use super::STILL_FRAMES_MAX;
use super::field::{Kind::*, described};
use serde::{Deserialize, Serialize};

described! {
    /// The matte chain of Mara et al. 2017, §3.4 (stages 3-7 of Figure 2).
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(default)]
    pub struct MatteSettings / FIELDS {
        /// Stage 3: reverse reprojection with confidence (Mara eq. 11).
        temporal: bool = true,
            ("matte.temporal", "matte/temporal", "", Bool);
        /// h of eq. 11: the history's weight at full confidence (paper 0.98).
        hysteresis: f32 = 0.98,
            ("matte.hysteresis", "matte/temporal", "", Float(0.0, 1.0, 0.001));
        /// History clamp to the neighbourhood's mean +- k standard deviations (Mara §3.4), k in [0, 16],
        /// default 0 (off): at one sample per pixel it erases correct indirect history (living room
        /// interior 0.049 of a 0.176 mean at 4 sigma); off, lighting changes lag about 1 / (1 - h) frames.
        clamp_sigma: f32 = 0.0,
            ("matte.clamp_sigma", "matte/temporal", "sigma", Float(0.0, 16.0, 0.05));
        /// In a still view (no camera or object motion) a history at full confidence weighs the new
        /// frame 1 / n down to 1 / this, where the hysteresis keeps 1 - h (1 / 50 at the paper's
        /// 0.98): a true mean of up to this many frames. The default, 2^24, is no cap: the mean of
        /// every frame since the view settled (cornell_diffuse at 128², 1024 frames, with a fixed
        /// edge-stop: relMSE 0.000547, 2.3x the plain accumulation's, FLIP 0.0244; with the
        /// hysteresis alone 0.000960, 4.0x, and 0.0289). 0: the paper's exponential blend always.
        still_frames: f32 = STILL_FRAMES_MAX,
            ("matte.still_frames", "matte/temporal", "frames", Float(0.0, STILL_FRAMES_MAX as f64, 1.0));
        /// Mara's reprojection also rejects a texel whose normal is more than this many degrees off, [0, 180],
        /// default 180 (off): matte light varies slowly across a crease and the test only shortens
        /// histories (staircase FLIP 0.0655 off, 0.0675 at 25 degrees).
        reprojection_normal_degrees: f32 = 180.0,
            ("matte.reprojection_normal_degrees", "matte/temporal", "degrees", Float(0.0, 180.0, 0.5));
        /// In a still view, once a pixel's history is longer than `edge_stop_full_frames`, its
        /// reprojection also rejects a previous texel whose normal is more than this many degrees
        /// off (and reads a neighbour on its own face), [0, 180], default 25 (180: off). With the
        /// jitter a crease's two faces take turns under its pixels, and the position test passes
        /// both: the history mixes their light, which differs where one face is lit and the other
        /// not, and the mean converges to that mix rather than to the pixel. cornell_diffuse at
        /// 128², 1024 frames: relMSE 1.40x the plain accumulation's (2.35x off); cornell_mirror
        /// 0.82x (0.88x). The first 64 frames are unchanged, where an always-on test costs (FLIP
        /// at 60 frames, living room 0.1548 at 60 degrees against 0.1482 off).
        still_normal_degrees: f32 = 25.0,
            ("matte.still_normal_degrees", "matte/temporal", "degrees", Float(0.0, 180.0, 0.5));
        /// Stage 4: sparse bilateral on what is written back to history.
        history_bilateral: bool = true,
            ("matte.history_bilateral", "matte/history_bilateral", "", Bool);
        /// Taps of the sparse bilateral filters (paper: 50).
        taps: u32 = 50,
            ("matte.taps", "matte/history_bilateral", "taps", Int(1, 256));
        /// Disk diameter of the history-loop bilateral as a fraction of the screen width (paper: 1%).
        history_diameter_fraction: f32 = 0.01,
            ("matte.history_diameter_fraction", "matte/history_bilateral", "of width", Float(0.0, 0.2, 0.0005));
        /// Frames of history past which the history bilateral's disk shrinks as 1 / sqrt(n), default 1
        /// (0: the paper's fixed disk): keeps the loop's compounding blur logarithmic (level FLIP
        /// 0.0605, 0.0644 with the fixed disk).
        history_full_frames: f32 = 1.0,
            ("matte.history_full_frames", "matte/history_bilateral", "frames", Float(0.0, 1024.0, 0.1));
        /// The most frames a bilinearly resampled history counts as, default 8 (0: no cap): a strafe's
        /// blur fades within frames of a stop (level FLIP 10 frames after: 0.0720, uncapped 0.0830)
        /// at a noisier moving image.
        resampled_history_frames: f32 = 8.0,
            ("matte.resampled_history_frames", "matte/temporal", "frames", Float(0.0, 1024.0, 1.0));
        /// Bilateral weights: cosine power on normals, plane-distance sigma in pixel footprints.
        normal_power: f32 = 32.0,
            ("matte.normal_power", "matte/history_bilateral", "exponent", Float(0.0, 512.0, 0.5));
        /// Bilateral plane-distance sigma (both sparse bilaterals).
        plane_sigma_px: f32 = 2.0,
            ("matte.plane_sigma_px", "matte/history_bilateral", "footprints", Float(0.0, 64.0, 0.05));
        /// Stage 5: the disocclusion-driven radius r = (1 - min c) R.
        disocclusion: bool = true,
            ("matte.disocclusion", "matte/disocclusion", "", Bool);
        /// R of the disocclusion radius as a fraction of the screen width (paper: 1/20).
        disocclusion_fraction: f32 = 0.05,
            ("matte.disocclusion_fraction", "matte/disocclusion", "of width", Float(0.0, 0.5, 0.001));
        /// Radius multiplier where the confidence c < 1/2 (paper: 6).
        low_confidence_multiplier: f32 = 6.0,
            ("matte.low_confidence_multiplier", "matte/disocclusion", "x", Float(1.0, 32.0, 0.05));
        /// Stage 6, the 3x3 firefly median; default off: on the level it raised FLIP (60 still
        /// frames: 0.1188 on, 0.0890 off), removing energy that fireflies carry and the reference keeps.
        firefly: bool = false,
            ("matte.firefly", "matte/firefly", "", Bool);
        /// Stage 7: final sparse bilateral with radius r.
        bilateral: bool = true,
            ("matte.bilateral", "matte/bilateral", "", Bool);
        /// Largest final-bilateral radius as a fraction of the screen width.
        max_radius_fraction: f32 = 0.1,
            ("matte.max_radius_fraction", "matte/bilateral", "of width", Float(0.0, 0.5, 0.001));
        /// Smallest final-bilateral radius, [0, 0.5] of the screen width, default 0.03 (0: Mara's
        /// r = (1 - c) R): outside the history loop it removes a still history's residual noise (living
        /// room FLIP 0.1652 against 0.1778) at a cost on fine detail (FlightHelmet 0.0125 against 0.0113).
        min_radius_fraction: f32 = 0.03,
            ("matte.min_radius_fraction", "matte/bilateral", "of width", Float(0.0, 0.5, 0.001));
        /// The final bilateral's luminance edge-stop, k standard deviations of the guide's noise,
        /// default 8 (0: none): keeps converged shading the minimum radius would blur (second half /
        /// last frame FLIP: living room 0.1467 / 0.1358, level 0.0469 / 0.0444).
        edge_stop_sigmas: f32 = 8.0,
            ("matte.edge_stop_sigmas", "matte/bilateral", "sigma", Float(0.0, 256.0, 0.5));
        /// Past this many frames of history the edge-stop's k narrows as sqrt(this / n), so that
        /// the blur it lets through falls faster than the history's noise (cornell_diffuse at
        /// 128², 1024 still frames: FLIP 0.0217, 0.0244 with a fixed k; relMSE 0.000559 and
        /// 0.000547; frame 60 the same). 0: a fixed k.
        edge_stop_full_frames: f32 = 64.0,
            ("matte.edge_stop_full_frames", "matte/bilateral", "frames", Float(0.0, STILL_FRAMES_MAX as f64, 1.0));
        /// The sparse bilateral's taps (stages 4 and 7) weighted by a Gaussian of their distance
        /// whose standard deviation is this fraction of the disk's radius (0: none, each tap of
        /// the disk weighed by the G-buffer alone). Mara et al. §3.2's kernel is Gaussian, of a
        /// width the paper does not give; presets/paper.toml uses 0.5 (the disk's edge at 2
        /// sigma). Off by default: it narrows the blur, which pays where 60 still frames already
        /// averaged most noise and costs where they did not. Frame 60, 256², Mara against
        /// Mitsuba, FLIP at sigma 0 / 1.0 / 0.7 / 0.5 / 0.35 / 0.25: cornell_diffuse 0.0369 /
        /// 0.0358 / 0.0347 / 0.0331 / 0.0311 / 0.0304; cornell_mirror 0.0682 and 0.0674 at 0.5.
        /// 160x90, 30 still frames, second-half FLIP (relMSE) at 0 / 0.5 / 0.35: level 0.0535
        /// (0.0270) / 0.0536 (0.0287) / 0.0545 (0.0306); living room 0.1803 (0.1433) / 0.1810
        /// (0.1476) / 0.1833 (0.1541).
        tap_sigma_fraction: f32 = 0.0,
            ("matte.tap_sigma_fraction", "matte/bilateral", "of radius", Float(0.0, 4.0, 0.01));
    }
    hidden {
    }
}

impl MatteSettings {
    /// Stage bits as the shaders read them (shaders/matte/common.wgsl: STAGE_*).
    pub fn stage_bits(&self) -> u32 {
        super::switch_bits(&self.switches())
    }

    /// Each stage by its WGSL constant, in the order of its bit (checked against the WGSL by a
    /// test).
    pub fn switches(&self) -> [(&'static str, bool); 5] {
        [
            ("STAGE_TEMPORAL", self.temporal),
            ("STAGE_HISTORY_BILATERAL", self.history_bilateral),
            ("STAGE_DISOCCLUSION", self.disocclusion),
            ("STAGE_FIREFLY", self.firefly),
            ("STAGE_BILATERAL", self.bilateral),
        ]
    }
}
