//! The progressive filter's settings (Dundr et al., "Progressive spatiotemporal variance-guided
//! filtering", §4-5; `denoise/progressive.rs`, shaders/progressive/*.wgsl): the denoiser for
//! sample fractions below 1, which also runs at one sample per pixel.

use super::STILL_FRAMES_MAX;
use super::denoiser_info::{DenoiserInfo, Off, Stage};
use super::field::{Kind::*, described};
use super::view_spec::v;
use super::{ViewMap, ViewSpec};
use serde::{Deserialize, Serialize};

/// The most a-trous levels (steps 1 to 2^(levels - 1) pixels).
pub const MAX_LEVELS: u32 = 6;

described! {
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(default)]
    pub struct ProgressiveSettings / FIELDS {
        /// Accumulation of light and luminance moments over samples (§4.2). Off, every frame starts
        /// over from the samples it traced.
        temporal: bool = true,
            ("progressive.temporal", "progressive/temporal", "", Bool);
        /// a of r = max(a, 1 / age) (§4.2): the smallest weight of a new sample (Dundr: 0.1).
        alpha: f32 = 0.1,
            ("progressive.alpha", "progressive/temporal", "", Float(0.01, 1.0, 0.005));
        /// In a still view a falls to 1 / this, so the light becomes a true mean of up to this many
        /// samples. The default, 2^24, is no cap: the mean of every sample since the view settled
        /// (with `epsilon_full_samples`, docs/decisions.md). 0: `alpha` always (Dundr).
        still_samples: f32 = STILL_FRAMES_MAX,
            ("progressive.still_samples", "progressive/temporal", "samples", Float(0.0, STILL_FRAMES_MAX as f64, 1.0));
        /// A-trous levels of the 3x3 kernel, large scale first (§4.4; Dundr: 5, 61x61 pixels).
        /// 0: no spatial filter (untraced pixels stay as they were).
        levels: u32 = 5,
            ("progressive.levels", "progressive/atrous", "", Int(0, MAX_LEVELS as i64));
        /// Normal weight exponent sigma_N (§4.4.1; Dundr: 64).
        sigma_n: f32 = 64.0,
            ("progressive.sigma_n", "progressive/atrous", "", Float(0.0, 256.0, 1.0));
        /// Depth weight sigma_D in depth gradients (§4.4.2; Dundr: 1).
        sigma_d: f32 = 1.0,
            ("progressive.sigma_d", "progressive/atrous", "", Float(0.01, 16.0, 0.05));
        /// Luminance weight sigma_L (§4.4.3, exp(-|L0 - L1| / (sigma_L var + epsilon)); Dundr: 4).
        sigma_l: f32 = 4.0,
            ("progressive.sigma_l", "progressive/atrous", "", Float(0.0, 64.0, 0.1));
        /// epsilon of the luminance weight (Dundr: 0.01 to 0.1), in displayed light (the light
        /// times the exposure): a dim scene shown brighter is not blurred across its gradients
        /// the more for its dimness (a floor lit 0.006 to 0.075, 128 still frames: the darkest
        /// band 8% too bright shown at +3.5 EV, 38% at 0 EV).
        epsilon_l: f32 = 0.05,
            ("progressive.epsilon_l", "progressive/atrous", "", Float(0.0, 1.0, 0.005));
        /// In a still view `epsilon_l` falls as this / (samples accumulated) past this many
        /// samples, as the variance of the mean beside it does, so that the filter's reach falls
        /// and the view converges (cornell_diffuse at 128², 1024 frames: relMSE 1.55x the plain
        /// accumulation's, FLIP 0.0235; fixed, 9.4x and 0.0763; frame 60 the same). 0: Dundr's
        /// fixed epsilon.
        epsilon_full_samples: f32 = 64.0,
            ("progressive.epsilon_full_samples", "progressive/atrous", "samples", Float(0.0, STILL_FRAMES_MAX as f64, 1.0));
        /// Dundr's feedback (§4.4, §5): the first a-trous level (step 1, run before the others)
        /// becomes the history of each pixel traced this frame whose light, this sample
        /// included, holds fewer than this many samples. A pixel takes it once per sample it
        /// receives (§5's "once a full sample per pixel gets accumulated"), not every frame, so
        /// the blur does not compound while it waits. Young light is smoothed before it
        /// accumulates; old light stays the plain mean. At 4 (the first 3 samples): level
        /// 160x90, 64 frames at 1/16 spp, FLIP 0.1388 -> 0.1278; cornell_diffuse 256², 0.0780 ->
        /// 0.0759; a still view's frame 60 (cornell_diffuse 128²) 0.0735 -> 0.0751 and frame
        /// 1024 relMSE 1.55x -> 1.57x the plain mean's. 0: never; 2^24: always (Dundr).
        feedback_samples: f32 = 4.0,
            ("progressive.feedback_samples", "progressive/atrous", "samples", Float(0.0, STILL_FRAMES_MAX as f64, 1.0));
        /// The luminance weight w_L between a pixel and a tap divides by the larger of their two
        /// variances, where Dundr's divides by the pixel's own. Symmetric, it lets a pixel that
        /// drew a rare bright sample give its light to the neighbours whose light it takes; with
        /// the pixel's own the filter lost light (the level, 64 frames at 1/16 spp, TAA off: mean
        /// -4.6% with the filter, +0.3% without). Level 160x90, 4 samples per pixel: FLIP 1/16 x
        /// 64 0.1240 -> 0.1182, 1 x 4 0.1179 -> 0.1069; a still view's frame 60 (256²)
        /// cornell_mirror 0.0863 -> 0.0748, cornell_diffuse 0.0517 -> 0.0516. Off: Dundr's.
        symmetric_luminance: bool = true,
            ("progressive.symmetric_luminance", "progressive/atrous", "", Bool);
        /// With `symmetric_luminance`, a tap's variance widens w_L at most to this x the
        /// pixel's own, so that one bright path (a large variance) is not spread over a patch
        /// of its darker neighbours. Last-frame FLIP at 1/16 spp x 64 frames, uncapped -> 64:
        /// level 160x90 0.1019 / 0.1021 / 0.0989 / 0.1083 -> 0.0991 / 0.1010 / 0.0989 / 0.1004
        /// (seeds 0-3; relMSE 0.0451 -> 0.0432, mean -1.5% -> -2.2% in red), cornell_diffuse
        /// 256² 0.0567 / 0.0570 / 0.0578 / 0.0561 -> 0.0568 / 0.0571 / 0.0578 / 0.0561; it
        /// costs caustics, which are such paths (cornell_mirror 0.1138 -> 0.1187; at 1 spp x 60
        /// 0.0789 -> 0.0793). At 16: level 0.0998 (mean), cornell_mirror 0.1223. 0: no cap.
        variance_cap: f32 = 64.0,
            ("progressive.variance_cap", "progressive/atrous", "x", Float(0.0, 65536.0, 1.0));
        /// In a still view a level of step s pixels filters a pixel only while its light holds
        /// at most this x (16 / s)^2 samples: at 1, the step-16 level stops after the first
        /// sample, step 8 after 4, step 4 after 16, step 2 after 64 and step 1 after 256, so the
        /// filter's area shrinks as the light's variance falls and a still view ends at its
        /// plain mean. Pixels without samples are filled by every level. FLIP of the last frame
        /// (docs/decisions.md), 0 -> 1: cornell_diffuse 256², 64 frames at 1/16 spp 0.0641 ->
        /// 0.0588 (Mara's 4 frames at 1 spp: 0.0586), 60 still frames at 1 spp 0.0508 ->
        /// 0.0287, 64 frames at 1/64 unchanged (0.0893); the level 160x90 at 1/16 x 64 0.1113 /
        /// 0.1097 -> 0.1100 / 0.1098 at seeds 0 / 1 (Mara's: 0.0996 / 0.0993). 0: every level
        /// everywhere (Dundr).
        reach_samples: f32 = 1.0,
            ("progressive.reach_samples", "progressive/atrous", "samples", Float(0.0, 65536.0, 0.25));
        /// TAA follows the filter's matte light (`taa.current_light`'s share), as it follows
        /// Mara's and SVGF's, instead of averaging the frames shown, at every sample fraction.
        /// Off by default (below one sample per pixel `taa_follow_fractions` turns it on
        /// alone): at one sample per pixel cornell_mirror's still frame 60 gains 5% (0.0917 ->
        /// 0.0869), but a still view's relMSE at 1024 frames (cornell_diffuse 128²) rises from
        /// 1.56x the plain accumulation's to 2.14x: at a pixel whose jittered samples fall on
        /// two surfaces TAA then shows the product of the averaged material and light, not the
        /// average of the products.
        taa_follow: bool = false,
            ("progressive.taa_follow", "taa", "", Bool);
        /// Where a frame traces one pixel in N > 1, TAA follows the filter's matte light as
        /// `taa_follow` does, at pixels whose light holds at least two samples (one is mostly
        /// what the a-trous levels filled in around it). There TAA blends at `taa.alpha` (no
        /// long still-view mean), and its average lags the light, which gains a sample only
        /// every N frames. Last-frame FLIP off -> on, 64 frames at 1/16 spp: level 160x90 (mean
        /// of seeds 0-3) 0.1019 -> 0.0998, cornell_diffuse 256² 0.0589 -> 0.0570,
        /// cornell_mirror 0.1245 -> 0.1187; at 1/64 spp (one sample per pixel) the same 0.1672
        /// on the level. The trade: the image moves more from frame to frame under motion (the
        /// level's jump at 1/4 spp, measured before `variance_cap`: temporal error 0.0208 ->
        /// 0.0235).
        taa_follow_fractions: bool = true,
            ("progressive.taa_follow_fractions", "taa", "", Bool);
    }
    hidden {
    }
}

impl super::Denoiser {
    /// Dundr et al.'s progressive filter, then TAA.
    pub const PROGRESSIVE: super::Denoiser = super::Denoiser(std::borrow::Cow::Borrowed(INFO.name));
}

pub const INFO: DenoiserInfo = DenoiserInfo {
    name: "progressive",
    summary: "Dundr et al.'s progressive SVGF, for sample fractions below 1 (--spp 1/N), then TAA",
    fields: &[FIELDS],
    section: None,
    stages: &[
        Stage::named("progressive/temporal", "progressive.temporal"),
        Stage { name: "progressive/atrous", path: "progressive.levels", off: Off::Zero },
    ],
    views: VIEWS,
    fractions: true,
    levels: Some("progressive.levels"),
};

/// The progressive filter's views (`crate::denoise::progressive`).
pub const VIEWS: &[ViewSpec] = &[
    v("progressive/matte accumulated", "progressive/matte history 0", ViewMap::Light),
    // The 3x3-blurred luminance variance; 1 is white (no estimate yet: white).
    v(
        "progressive/matte variance",
        "progressive/matte variance",
        ViewMap::Grey { channel: 3, divisor: 1.0 },
    ),
    // Samples accumulated per pixel; 32 is white, black where none arrived yet.
    v(
        "progressive/matte samples",
        "progressive/matte moments 0",
        ViewMap::Grey { channel: 2, divisor: 32.0 },
    ),
    v("progressive/direct accumulated", "progressive/direct history 0", ViewMap::Light),
    v("progressive/glossy accumulated", "progressive/glossy history 0", ViewMap::Light),
];
