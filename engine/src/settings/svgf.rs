//! SVGF's settings (Schied et al. 2017, with the extensions of Voorhuis §4 and §6;
//! `denoise/svgf.rs`, shaders/svgf/*.wgsl). Every stage and every one of Voorhuis's changes is
//! a switch, so that `hush-cli quality` can ablate each.

use super::denoiser_info::{DenoiserInfo, Off, Stage};
use super::field::{Kind::*, described};
use super::view_spec::v;
use super::{ViewMap, ViewSpec};
use serde::{Deserialize, Serialize};

described! {
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(default)]
    pub struct SvgfSettings / FIELDS {
        /// Temporal accumulation of the light and its luminance moments (SVGF §4.1). Off, every
        /// frame starts over: variance comes from the spatial estimate alone.
        temporal: bool = true,
            ("svgf.temporal", "svgf/temporal", "", Bool);
        /// Weight of the current frame in the light's exponential moving average (0.2 in SVGF).
        alpha: f32 = 0.2,
            ("svgf.alpha", "svgf/temporal", "", Float(0.01, 1.0, 0.005));
        /// Weight of the current frame in the moments' moving average (0.2 in SVGF).
        alpha_moments: f32 = 0.2,
            ("svgf.alpha_moments", "svgf/temporal", "", Float(0.01, 1.0, 0.005));
        /// In a still view (no camera or object motion) the light's and the moments' weights fall
        /// as 1 / h to 1 / this: a true mean of up to this many frames, where SVGF's 0.2 keeps
        /// about 9. The default, 2^24, is no cap: the mean of every frame since the view settled,
        /// which converges to the reference. 0: `alpha` always (Schied et al.).
        still_frames: f32 = STILL_FRAMES_MAX,
            ("svgf.still_frames", "svgf/temporal", "frames", Float(0.0, STILL_FRAMES_MAX as f64, 1.0));
        /// Next frame's history is the first a-trous level's output (Schied et al. §4.3); off, the
        /// temporally integrated light before any spatial filter, so that a long history does not
        /// compound the filter's blur.
        filtered_history: bool = false,
            ("svgf.filtered_history", "svgf/temporal", "", Bool);
        /// The luminance edge-stop measures differences against the variance of the accumulated
        /// light (the sample variance times the sum of the squared integration weights) rather
        /// than of one sample (Schied et al.), so that edges sharpen as the history grows.
        variance_of_mean: bool = true,
            ("svgf.variance_of_mean", "svgf/atrous", "", Bool);
        /// Voorhuis §6: the spatial estimate averages the neighbours' accumulated moments (not this
        /// frame's luminance), and the moments are true averages up to 4 reprojections.
        accumulated_moments: bool = true,
            ("svgf.accumulated_moments", "svgf/temporal", "", Bool);
        /// Temporal accumulation of the glossy light; off (with `temporal` on), only the matte light
        /// accumulates: Voorhuis's "NoSpecReproj" (§7.1), the glossy light filtered spatially alone.
        glossy_temporal: bool = true,
            ("svgf.glossy_temporal", "svgf/temporal", "", Bool);
        /// Voorhuis §4: glossy light below `roughness_threshold` is reprojected with the reflection
        /// motion vectors of the diamond search (the Mara glossy chain's `glossy/motion` stage);
        /// off, with the surface's.
        reflection_reprojection: bool = true,
            ("svgf.reflection_reprojection", "svgf/temporal", "", Bool);
        /// Voorhuis §4.2.3: glossy history is clipped to the 5x5 box of the 7x7-blurred current
        /// frame below `clip_roughness`, as the consistency tests are dropped there.
        clipping: bool = false,
            ("svgf.clipping", "svgf/temporal", "", Bool);
        /// Voorhuis §4.2.1: the roughness below which reflections are reprojected with reflection
        /// motion vectors (his 0.4 is a Beckmann alpha, 0.632 here: `glossy.roughness_threshold`).
        roughness_threshold: f32 = 0.4,
            ("svgf.roughness_threshold", "svgf/temporal", "", Float(0.0, 1.0, 0.01));
        /// Voorhuis §4.2.3: the roughness below which the glossy history is clipped (0.9).
        clip_roughness: f32 = 0.9,
            ("svgf.clip_roughness", "svgf/temporal", "", Float(0.0, 1.0, 0.01));
        /// Below the roughness threshold a pixel's history (mirror or glossy) must have reflected
        /// the same point, as in the Mara glossy chain (`glossy.hit_test`). Off, it is taken
        /// wherever the previous pixel had a glossy lobe, as Voorhuis §4.2.3 does.
        /// `hush-cli reflections` strafe (160x90), ghost-region FLIP 0.2244 on (mirrors and
        /// glossy lobes), 0.2259 with mirrors alone, 0.2296 with neither; no reprojection 0.2304.
        hit_test: bool = true,
            ("svgf.hit_test", "svgf/temporal", "", Bool);
        /// The spatial variance estimate (7x7, SVGF §4.2) where fewer than 4 frames accumulated;
        /// off, those pixels use the temporal moments as they are.
        spatial_variance: bool = true,
            ("svgf.spatial_variance", "svgf/variance", "", Bool);
        /// Levels of the edge-avoiding a-trous wavelet filter (step 2^i; SVGF: 5). The first
        /// level's output is the next frame's history. 0: no spatial filter.
        levels: u32 = 5,
            ("svgf.levels", "svgf/atrous", "levels", Int(0, MAX_LEVELS as i64));
        /// SVGF's 5x5 B3-spline a-trous kernel (24 taps a level); off, a 3x3 kernel (1/4, 1/2,
        /// 1/4 per axis, 8 taps) that reaches half as far. Off by default: on lavapipe it
        /// halves the a-trous passes (level 640x360, matte + glossy, two runs: 864 / 816 ms with
        /// the 5x5, 446 / 431 with the 3x3; SVGF's share of the frame 35.2 / 37.1% against
        /// 32.6 / 29.1%; on an H200 at 1280x720 1.05 -> 0.58 ms) and the still views measured
        /// came out the same or better (docs/decisions.md).
        kernel_5x5: bool = false,
            ("svgf.kernel_5x5", "svgf/atrous", "", Bool);
        /// Where the light accumulated at least this many samples' worth (1 / the sum of the squared
        /// integration weights: a still view's long mean, not a moving pixel's 0.2 average of about
        /// 9), only the first `settled_levels` levels filter it: the wide levels' blur then costs
        /// more (light pulled across corners and shadow edges) than their noise reduction gains.
        /// 0: every level everywhere (Schied et al.).
        settled_samples: f32 = 16.0,
            ("svgf.settled_samples", "svgf/atrous", "samples", Float(0.0, 1024.0, 1.0));
        /// Levels that still filter settled light (see `settled_samples`).
        settled_levels: u32 = 2,
            ("svgf.settled_levels", "svgf/atrous", "levels", Int(0, MAX_LEVELS as i64));
        /// Luminance edge-stop sigma_l, in standard deviations of the variance (SVGF: 4).
        sigma_l: f32 = 4.0,
            ("svgf.sigma_l", "svgf/atrous", "sigma", Float(0.0, 64.0, 0.1));
        /// Normal edge-stop exponent sigma_n (SVGF: 128).
        sigma_n: f32 = 128.0,
            ("svgf.sigma_n", "svgf/atrous", "", Float(0.0, 512.0, 1.0));
        /// Depth edge-stop sigma_z, in depth gradients (SVGF: 1).
        sigma_z: f32 = 1.0,
            ("svgf.sigma_z", "svgf/atrous", "gradients", Float(0.0, 64.0, 0.1));
        /// Voorhuis §6 eq. (8): sigma_l x (8 - min(7, h)) for a history of h frames.
        bandwidth_boost: bool = true,
            ("svgf.bandwidth_boost", "svgf/atrous", "", Bool);
        /// SVGF's filtering of the variance at every a-trous level (var' = sum w^2 var / (sum w)^2).
        /// Voorhuis §6 turns it off for indirect light (all Hush filters), trading some overblur
        /// for smoother, steadier light.
        variance_filtering: bool = true,
            ("svgf.variance_filtering", "svgf/atrous", "", Bool);
        /// Voorhuis §4.1: behind mirrors the light is demodulated by the reflected surface's
        /// reflectance and the a-trous edge-stops on the reflected surface's normal and distance.
        mirror_features: bool = true,
            ("svgf.mirror_features", "svgf/atrous", "", Bool);
        /// The final filter of settled light (svgf/regression.wgsl; both signals): a fit of the
        /// accumulated light over its surface's neighbours in windows of 1 to `regression_radius`
        /// pixels, each window accepted by the intersection of confidence intervals, so that the
        /// reach falls as the history's variance falls and a still view converges to its mean
        /// without blur bias. Off, settled light shows the a-trous output. Frame 60 of a still
        /// view (256², TAA after): cornell_diffuse FLIP 0.0271 against 0.0297 off, cornell_mirror
        /// 0.0571 against 0.0750; it costs a 192-tap pass per signal.
        regression: bool = true,
            ("svgf.regression", "svgf/regression", "", Bool);
        /// The regression's widest window radius (windows of 1, 2, 4 ... pixels up to it; 16: 0.0272,
        /// 8: 0.0283, 32: 0.0275 on cornell_diffuse at frame 60).
        regression_radius: u32 = 16,
            ("svgf.regression_radius", "svgf/regression", "pixels", Int(1, 32));
        /// The order of the regression's fit: 0 a mean, 1 a plane, 2 a quadric in screen space. A
        /// mean pulls a gradient's light across a window cut by an edge, a plane misses the
        /// curvature of a falloff (cornell_diffuse at frame 60, gamma 1: 2 0.0293, 1 0.0318).
        regression_order: u32 = 2,
            ("svgf.regression_order", "svgf/regression", "", Int(0, 2));
        /// The intervals' half-width gamma, in standard deviations of each window's estimate: wider
        /// windows are accepted while their fit stays within gamma sigma of every smaller one's.
        /// Lower keeps less blur bias and more noise (cornell_diffuse at frame 60: 0.5 0.0297,
        /// 1 0.0293, 2 0.0304, 3 0.0310 with TAA's own mean).
        regression_k: f32 = 1.0,
            ("svgf.regression_k", "svgf/regression", "sigma", Float(0.1, 16.0, 0.1));
        /// Past this many samples' worth the intervals (gamma and the first windows' 3 sigma) narrow
        /// as sqrt(this / samples), so that a window's accepted bias falls faster than the noise of
        /// its estimate and a still view ends at its own mean; at a fixed width the bias stays a
        /// fixed share of the noise and relMSE stops at a fixed multiple of the accumulation's
        /// (cornell_diffuse at 128², 1024 frames: relMSE 2.25x the accumulation's and FLIP
        /// 0.0223; fixed, 2.51x and 0.0279; frame 60 the same). 0: fixed intervals.
        regression_full_samples: f32 = 64.0,
            ("svgf.regression_full_samples", "svgf/regression", "samples", Float(0.0, STILL_FRAMES_MAX as f64, 1.0));
        /// Light with fewer samples' worth than this shows the a-trous output.
        regression_samples: f32 = 16.0,
            ("svgf.regression_samples", "svgf/regression", "samples", Float(1.0, 1024.0, 1.0));
        /// The regression's spike cut (svgf/variance.wgsl, svgf/regression.wgsl): where a pixel's
        /// accumulated light is over this many times its second brightest neighbour's on its
        /// surface, and one rare path makes most of its samples' spread (their mean square over 8
        /// times their mean's square), the fit reads it cut to that level and the cut light is
        /// averaged over the pixel's surface within 16 pixels (svgf/spread.wgsl): a caustic path's
        /// light is spread over its surface, where the windows' tests dropped it and left the
        /// surface dark. 0: off. Frame 60 of a still view (256², seeds 0-3): cornell_mirror FLIP
        /// 0.0494 / 0.0506 / 0.0504 / 0.0492 against 0.0554 / 0.0566 / 0.0561 / 0.0549 off,
        /// cornell_diffuse 0.0238 either way (seed 0). Costs a 3x3 read per pixel and signal in
        /// the variance stage, one load per regression tap, and two separable passes of 33 taps
        /// where the light is fitted (cornell_mirror at 320², lavapipe: 57 of 661 ms a still
        /// frame for both signals).
        spike_ratio: f32 = 1.2,
            ("svgf.spike_ratio", "svgf/regression", "", Float(0.0, 16.0, 0.1));
        /// Voorhuis §6's firefly suppression after the a-trous, outside the history loop, on diffuse
        /// light (the matte light, and the glossy light behind mirrors) that has not settled
        /// (`settled_samples`): a pixel brighter than all its neighbours is brought down to the
        /// brightest of them. Catches the fireflies of young histories; costs a 3x3 read per pixel
        /// and signal.
        firefly: bool = true,
            ("svgf.firefly", "svgf/final", "", Bool);
    }
    hidden {
    }
}

impl SvgfSettings {
    /// Base SVGF (Schied et al. 2017) without Voorhuis's changes: variance filtered at every
    /// level, no moment averages, no bandwidth boost, no firefly median, reflections reprojected
    /// with the surface's motion and not clipped.
    pub fn schied() -> SvgfSettings {
        SvgfSettings {
            accumulated_moments: false,
            bandwidth_boost: false,
            variance_filtering: true,
            firefly: false,
            regression: false,
            reflection_reprojection: false,
            clipping: false,
            hit_test: false,
            mirror_features: false,
            still_frames: 0.0,
            settled_samples: 0.0,
            variance_of_mean: false,
            filtered_history: true,
            kernel_5x5: true,
            ..Default::default()
        }
    }

    /// Switch bits as shaders/svgf/common.wgsl reads them (SV_*).
    pub fn bits(&self) -> u32 {
        super::switch_bits(&self.switches())
    }

    /// Each switch by the WGSL constant that tests it (shaders/svgf/common.wgsl `SV_*`), in the
    /// order of its bit in [`SvgfSettings::bits`] (a test checks the constants against it).
    pub fn switches(&self) -> [(&'static str, bool); 14] {
        [
            ("SV_TEMPORAL", self.temporal),
            ("SV_SPATIAL_VARIANCE", self.spatial_variance),
            ("SV_ACCUMULATED_MOMENTS", self.accumulated_moments),
            ("SV_BANDWIDTH_BOOST", self.bandwidth_boost),
            ("SV_VARIANCE_FILTERING", self.variance_filtering),
            ("SV_FIREFLY", self.firefly),
            ("SV_REFLECTION_REPROJECTION", self.reflection_reprojection),
            ("SV_CLIPPING", self.clipping),
            ("SV_MIRROR_FEATURES", self.mirror_features),
            ("SV_VARIANCE_OF_MEAN", self.variance_of_mean),
            ("SV_FILTERED_HISTORY", self.filtered_history),
            ("SV_GLOSSY_TEMPORAL", self.glossy_temporal),
            ("SV_REGRESSION", self.regression),
            ("SV_HIT_TEST", self.hit_test),
        ]
    }

    /// The a-trous levels the filter runs (at most 5: steps 1 to 16 pixels).
    pub fn atrous_levels(&self) -> u32 {
        self.levels.min(MAX_LEVELS)
    }
}

/// The longest still-view mean of any denoiser's history, in frames (frame counts stay exact in f32 up to 2^24).
pub const STILL_FRAMES_MAX: f32 = 16_777_216.0;

/// The a-trous filter's deepest level (step 16 pixels, a 65-pixel footprint).
pub const MAX_LEVELS: u32 = 5;

impl super::Denoiser {
    /// SVGF with Voorhuis's extensions, then TAA.
    pub const SVGF: super::Denoiser = super::Denoiser(std::borrow::Cow::Borrowed(INFO.name));
}

pub const INFO: DenoiserInfo = DenoiserInfo {
    name: "svgf",
    summary: "SVGF (Schied et al. 2017) with Voorhuis's reflections and robustness, then TAA",
    fields: &[FIELDS],
    section: None,
    stages: &[
        Stage::named("svgf/temporal", "svgf.temporal"),
        Stage::named("svgf/temporal_glossy", "svgf.glossy_temporal"),
        Stage::named("svgf/variance", "svgf.spatial_variance"),
        Stage { name: "svgf/atrous", path: "svgf.levels", off: Off::Zero },
        Stage::named("svgf/regression", "svgf.regression"),
        Stage::switch("svgf.accumulated_moments"),
        Stage::switch("svgf.bandwidth_boost"),
        Stage::switch("svgf.firefly"),
        Stage::switch("svgf.reflection_reprojection"),
        Stage::switch("svgf.clipping"),
        Stage::switch("svgf.mirror_features"),
        Stage::switch("svgf.hit_test"),
    ],
    views: VIEWS,
    fractions: false,
    levels: Some("svgf.levels"),
};

/// The views of SVGF (`crate::denoise::svgf`): every intermediate of both signals.
pub const VIEWS: &[ViewSpec] = &[
    v("svgf/matte integrated", "svgf/matte integrated", ViewMap::Light),
    // The luminance variance that steers the first a-trous level; 1 is white.
    v("svgf/matte variance", "svgf/matte variance", ViewMap::Grey { channel: 3, divisor: 1.0 }),
    v(
        "svgf/matte history length",
        "svgf/matte moments 0",
        ViewMap::Grey { channel: 2, divisor: 32.0 },
    ),
    v(
        "svgf/matte first moment",
        "svgf/matte moments 0",
        ViewMap::Grey { channel: 0, divisor: 1.0 },
    ),
    v("svgf/matte history", "svgf/matte history 0", ViewMap::Light),
    // The light the regression's spike cut takes off each pixel (`spike_ratio`), and its mean
    // over each pixel's surface, which the regression adds (svgf/spread.wgsl).
    v("svgf/matte spikes", "svgf/matte excess", ViewMap::Light),
    v("svgf/matte spread", "svgf/matte spread", ViewMap::Light),
    // The final regression's output (settled light; the rest is the a-trous output).
    v("svgf/matte regression", "svgf/matte regressed", ViewMap::Light),
    v("svgf/matte", "svgf/matte out", ViewMap::Light),
    v("svgf/glossy integrated", "svgf/glossy integrated", ViewMap::Light),
    v("svgf/glossy variance", "svgf/glossy variance", ViewMap::Grey { channel: 3, divisor: 1.0 }),
    v(
        "svgf/glossy history length",
        "svgf/glossy moments 0",
        ViewMap::Grey { channel: 2, divisor: 32.0 },
    ),
    v("svgf/glossy history", "svgf/glossy history 0", ViewMap::Light),
    v("svgf/glossy spikes", "svgf/glossy excess", ViewMap::Light),
    v("svgf/glossy spread", "svgf/glossy spread", ViewMap::Light),
    v("svgf/glossy motion", "svgf/glossy motion", ViewMap::Motion { channel: 0 }),
    v("svgf/glossy", "svgf/glossy out", ViewMap::Light),
];
