//! The glossy chain's settings (Mara et al. 2017 §3.4 stages 8-10, Voorhuis §4) and their
//! descriptions.

use super::STILL_FRAMES_MAX;
use super::field::{Kind::*, described};
use serde::{Deserialize, Serialize};

/// How the glossy chain finds where a reflection was in the previous frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ReflectionMv {
    /// Surface motion vectors only (the SVGF baseline: reflections smear under motion).
    Primary,
    /// Mara et al. §3.4 after Zimmer et al. 2015: reproject the virtual position of what the
    /// reflection shows (primary hit + secondary hit distance along the camera ray).
    Virtual,
    /// Voorhuis §4.1-4.2.1 and Appendix A: diamond search of the previous frame's reflected hit
    /// positions.
    #[default]
    Diamond,
}

impl ReflectionMv {
    pub const ALL: [ReflectionMv; 3] =
        [ReflectionMv::Primary, ReflectionMv::Virtual, ReflectionMv::Diamond];

    pub fn name(self) -> &'static str {
        match self {
            ReflectionMv::Primary => "primary",
            ReflectionMv::Virtual => "virtual",
            ReflectionMv::Diamond => "diamond",
        }
    }

    pub fn parse(s: &str) -> Option<ReflectionMv> {
        Self::ALL.into_iter().find(|m| m.name() == s)
    }
}

described! {
    /// The glossy chain: Mara et al. 2017 §3.4 stages 8-10 with the reflection reprojection and
    /// neighbourhood clipping of Voorhuis §4.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(default)]
    pub struct GlossySettings / FIELDS {
        /// Reflection motion: surface (primary), virtual position, or diamond search.
        reflection_mv: ReflectionMv = ReflectionMv::Diamond,
            ("glossy.reflection_mv", "glossy/motion", "", Choice(reflection_mvs));
        /// Below this roughness reflections are reprojected with reflection motion vectors; above it
        /// with the surface's. Voorhuis §4.2.1's 0.4 is a Beckmann alpha: 0.632 here (GGX alpha =
        /// roughness²), which moved the level's and the living room's FLIP by at most 1% on a
        /// strafe (docs/decisions.md; presets/voorhuis.toml carries it).
        roughness_threshold: f32 = 0.4,
            ("glossy.roughness_threshold", "glossy/motion", "roughness", Float(0.0, 1.0, 0.005));
        /// At or below this roughness a surface is a mirror: its chain matches exact reflected hit
        /// positions (eq. 1), filters with the reflected surface's normal and demodulates by its
        /// reflectance (§4.1). Above it, the representative-ray distance of eq. (4)-(5).
        mirror_roughness: f32 = 0.01,
            ("glossy.mirror_roughness", "glossy/motion", "roughness", Float(0.0, 1.0, 0.001));
        /// First step of the diamond search's large pattern, pixels (Appendix A: 4; 1 = no LDSP
        /// scaling).
        initial_step: u32 = 4,
            ("glossy.initial_step", "glossy/motion", "px", Int(1, 64));
        /// Most large-pattern iterations per pixel (bounds the search's cost).
        max_search_steps: u32 = 32,
            ("glossy.max_search_steps", "glossy/motion", "steps", Int(1, 256));
        /// Trace each glossy pixel's representative (mirror) ray below the roughness threshold, and
        /// search by eq. (1) on its real hit; off, eq. (4) extends the ray by the sample's depth and
        /// the search uses eq. (5). On the `spheres` strafe (160x90, against a 65x65 brute-force
        /// search) the glossy sphere's vectors were 8.05 px off on average (42.6% within 1 px) with
        /// sampled depths, whose jumps between near and far geometry make eq. (5)'s minimum
        /// ambiguous, and 0.31 px (92.6%) with traced ones, for one closest-hit ray per such pixel.
        /// A constant of the motion stage's program (a change makes it again): on lavapipe eq. (5)
        /// cost every search tap even while unused (denoise/mara/glossy.rs: MotionProgram).
        trace_representative_ray: bool = true,
            ("glossy.trace_representative_ray", "glossy/motion", "", Bool);
        /// Stage switches. Without `temporal` nothing is reprojected (Voorhuis's "NoSpecReproj").
        temporal: bool = true,
            ("glossy.temporal", "glossy/temporal", "", Bool);
        /// Hysteresis h, as the matte temporal's (Mara: the same confidence and clamping).
        hysteresis: f32 = 0.98,
            ("glossy.hysteresis", "glossy/temporal", "", Float(0.0, 1.0, 0.001));
        /// As `matte.still_frames`, for the glossy history: in a still view the new frame weighs
        /// 1 / n down to 1 / this (default 2^24, no cap; 0: the hysteresis always).
        still_frames: f32 = STILL_FRAMES_MAX,
            ("glossy.still_frames", "glossy/temporal", "frames", Float(0.0, STILL_FRAMES_MAX as f64, 1.0));
        /// The surface reprojection rejects a texel whose normal is more than this many degrees off,
        /// [0, 180], default 10 (180: off): a crease's faces reflect different things under one
        /// pixel (staircase FLIP 0.0645 at 10, 0.0726 off; the living room's shorter histories cost
        /// 0.1632 against 0.1603).
        reprojection_normal_degrees: f32 = 10.0,
            ("glossy.reprojection_normal_degrees", "glossy/temporal", "degrees", Float(0.0, 180.0, 0.5));
        /// Eq. (11)'s d0, d1 for mirrors, in pixel footprints at the reflected distance.
        d0_px: f32 = 2.0,
            ("glossy.d0_px", "glossy/temporal", "footprints", Float(0.0, 64.0, 0.05));
        /// Eq. 11's d1 for mirrors, at the reflected distance.
        d1_px: f32 = 4.0,
            ("glossy.d1_px", "glossy/temporal", "footprints", Float(0.0, 64.0, 0.05));
        /// Neighbourhood clipping of the reprojected history (Voorhuis §4.2.3), default off: at one
        /// sample per pixel the box rarely holds the bright paths a converged history averages (level
        /// FLIP 0.0738 on, 0.0694 off); ghosts are left to the confidence tests.
        clipping: bool = false,
            ("glossy.clipping", "glossy/temporal", "", Bool);
        /// Neighbourhood clipping applies below this roughness (§4.2.3: 0.9).
        clip_roughness: f32 = 0.9,
            ("glossy.clip_roughness", "glossy/temporal", "roughness", Float(0.0, 1.0, 0.005));
        /// Below the roughness threshold a glossy pixel's history, not only a mirror's, must have
        /// reflected the same point: a previous pixel (and each bilinear tap) whose traced
        /// representative hit lies within d1 reaches of this one's, a reach being a pixel's
        /// footprint there plus the lobe's spread (roughness^2 x the secondary distance). Off,
        /// such history is taken wherever the previous pixel had a glossy lobe (Voorhuis §4.2.3).
        /// `hush-cli reflections` strafe (160x90), ghost-region FLIP 0.2211 on, 0.2219 off
        /// (no reprojection 0.2106); still views are unchanged.
        hit_test: bool = true,
            ("glossy.hit_test", "glossy/temporal", "", Bool);
        /// The separable bilateral (stages 9 and 10).
        bilateral: bool = true,
            ("glossy.bilateral", "glossy/bilateral", "", Bool);
        /// Bilateral sigma = scale x roughness^exponent + epsilon pixels (Mara: 7, 0.1, epsilon).
        /// Epsilon is 1 px so that mirrors (roughness 0) are still filtered, across the reflected
        /// surface's features.
        sigma_scale: f32 = 7.0,
            ("glossy.sigma_scale", "glossy/bilateral", "px", Float(0.0, 9.0, 0.05));
        /// Roughness exponent of sigma (Mara 0.1).
        sigma_exponent: f32 = 0.1,
            ("glossy.sigma_exponent", "glossy/bilateral", "", Float(0.0, 4.0, 0.005));
        /// Sigma at roughness 0.
        sigma_epsilon_px: f32 = 1.0,
            ("glossy.sigma_epsilon_px", "glossy/bilateral", "px", Float(0.0, 9.0, 0.05));
        /// Frames of history past which the bilateral's sigma shrinks as 1 / n, default 1 (0: Mara's
        /// fixed sigma): a converged history needs no spatial blur (level FLIP 0.0652, fixed 0.0994).
        sigma_full_frames: f32 = 1.0,
            ("glossy.sigma_full_frames", "glossy/bilateral", "frames", Float(0.0, 256.0, 0.1));
        /// The most frames a resampled glossy history counts as, default 1 (0: no cap): what a move
        /// uncovered recovers like a fresh start (FLIP 10 frames after a strafe: 0.1071, uncapped
        /// 0.1593) and reflections ghost less (ghost region 0.2111, 8 frames 0.2234).
        resampled_history_frames: f32 = 1.0,
            ("glossy.resampled_history_frames", "glossy/temporal", "frames", Float(0.0, 1024.0, 1.0));
        /// Voorhuis eq. (6)'s omega, with the ray differential at the secondary hit measured in
        /// pixel footprints of the primary surface (scale-free, unlike the paper's world units):
        /// sigma is multiplied by exp(-footprints / omega) below the roughness threshold.
        ray_differential_omega: f32 = 16.0,
            ("glossy.ray_differential_omega", "glossy/bilateral", "footprints", Float(0.001, 1024.0, 0.1));
        /// Bilateral weight on roughness differences: exp(-(dr / sigma)^2).
        roughness_sigma: f32 = 0.1,
            ("glossy.roughness_sigma", "glossy/bilateral", "roughness", Float(0.0, 1.0, 0.001));
    }
    hidden {
        /// Measurements only: also run a brute-force search over a window of this radius (pixels)
        /// and report the diamond search's distance to it in the search view (0: off). A constant
        /// of the motion stage's program, which carries the search only while this is set.
        #[serde(skip)]
        reference_search_radius: u32 = 0;
    }
}

impl GlossySettings {
    /// Stage bits as shaders/glossy/common.wgsl reads them.
    pub fn stage_bits(&self) -> u32 {
        super::switch_bits(&self.switches())
    }

    /// Each stage by its WGSL constant (`GSTAGE_*`), in the order of its bit (checked against
    /// the WGSL by a test).
    pub fn switches(&self) -> [(&'static str, bool); 4] {
        [
            ("GSTAGE_TEMPORAL", self.temporal),
            ("GSTAGE_CLIPPING", self.clipping),
            ("GSTAGE_BILATERAL", self.bilateral),
            ("GSTAGE_HIT_TEST", self.hit_test),
        ]
    }

    /// The glossy bilateral's Gaussian sigma in pixels: Mara et al. §3.4's 7 r^0.1 + epsilon,
    /// times Voorhuis eq. (6)'s exp(-dP / omega) below the roughness threshold, where
    /// `footprints` is the secondary hit's ray differential in primary pixel footprints.
    /// shaders/glossy/common.wgsl's glossy_sigma is the same function.
    pub fn sigma_px(&self, roughness: f32, footprints: f32) -> f32 {
        let base = self.sigma_scale * roughness.clamp(0.0, 1.0).powf(self.sigma_exponent)
            + self.sigma_epsilon_px;
        let scale = if roughness < self.roughness_threshold {
            (-footprints.max(0.0) / self.ray_differential_omega.max(1e-3)).exp()
        } else {
            1.0
        };
        (base * scale).clamp(0.0, MAX_GLOSSY_SIGMA_PX)
    }
}

/// Largest glossy bilateral sigma, pixels (the kernel reaches 2.5 sigma).
pub const MAX_GLOSSY_SIGMA_PX: f32 = 9.0;

fn reflection_mvs() -> Vec<String> {
    super::field::names(&ReflectionMv::ALL)
}
