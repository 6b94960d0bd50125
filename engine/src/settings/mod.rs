//! Tunables of the real-time frame, with their units and defaults. `fields.rs` describes each
//! one for panels and presets; `preset.rs` saves and loads them as TOML.

mod fields;
mod preset;
mod view;

pub use fields::{FIELDS, Field, Kind, get as get_field, get_mut as get_field_mut, leaves};
pub use view::{FRAME_VIEWS, MARA_VIEWS, View, ViewMap, ViewSpec, all_views, register_views};

use serde::{Deserialize, Serialize};
use std::borrow::Cow;
use std::sync::RwLock;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FrameSettings {
    /// Exposure in stops (EV): the image is multiplied by 2^exposure_ev before tone mapping.
    pub exposure_ev: f32,
    /// Path length as Mitsuba counts it (2 = direct light only; -1 = unbounded). Default 6.
    pub max_depth: i32,
    /// Seed of every random sequence; same seed, scene and camera path give the same frames.
    pub seed: u32,
    /// Sum frames while nothing changes (camera, time, settings) and show their mean: the
    /// converged image, for comparison with the real-time one. Each frame then samples a
    /// uniformly random position in its pixels, like the reference tracer's box filter.
    pub accumulate: bool,
    /// What the display shows.
    pub view: View,
    pub denoiser: Denoiser,
    pub matte: MatteSettings,
    pub glossy: GlossySettings,
    /// Indirect paths per pixel per frame (each of the matte and glossy estimators, and the
    /// area-light sample, is averaged over them). 1 is the paper's real-time setting.
    pub paths_per_pixel: u32,
}

impl FrameSettings {
    /// The multiplier 2^EV applied before tone mapping (EV clamped to +-30).
    pub fn exposure_scale(&self) -> f32 {
        2f32.powf(self.exposure_ev.clamp(-30.0, 30.0))
    }
}

impl Default for FrameSettings {
    fn default() -> Self {
        FrameSettings { exposure_ev: 0.0, max_depth: crate::scene::DEFAULT_MAX_DEPTH, seed: 0, accumulate: false, view: View::FINAL, denoiser: Denoiser::NONE, matte: MatteSettings::default(), glossy: GlossySettings::default(), paths_per_pixel: 1 }
    }
}

/// Which denoiser filters the 1-sample frame: the name of one in `crate::denoise`'s registry
/// (`none`, `mara`, or one registered by the application), as presets and `--denoiser` spell it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct Denoiser(Cow<'static, str>);

impl Denoiser {
    /// The raw frame (composite only).
    pub const NONE: Denoiser = Denoiser(Cow::Borrowed("none"));
    /// Mara et al. 2017: the matte and glossy chains, then TAA.
    pub const MARA: Denoiser = Denoiser(Cow::Borrowed("mara"));

    pub fn named(name: &str) -> Denoiser {
        Denoiser(Cow::Owned(name.to_string()))
    }

    pub fn name(&self) -> &str {
        &self.0
    }
}

impl Default for Denoiser {
    fn default() -> Self {
        Denoiser::MARA
    }
}

impl<'de> Deserialize<'de> for Denoiser {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        let known = denoiser_names();
        if !known.contains(&name.as_str()) {
            return Err(serde::de::Error::custom(format!("no denoiser {name:?} (there are {})", known.join(", "))));
        }
        Ok(Denoiser::named(&name))
    }
}

/// Names of the denoisers the frame can make: the built-in ones, and those
/// `crate::denoise::register` added (it keeps this list, which settings read without depending
/// on the denoisers themselves).
static DENOISER_NAMES: RwLock<Vec<&'static str>> = RwLock::new(Vec::new());

pub fn denoiser_names() -> Vec<&'static str> {
    let mut v = vec![Denoiser::NONE.0.as_ref(), "mara"];
    v.extend(DENOISER_NAMES.read().unwrap().iter());
    v
}

/// Called by `crate::denoise::register` only.
pub(crate) fn add_denoiser_name(name: &'static str) {
    DENOISER_NAMES.write().unwrap().push(name);
}

/// The matte chain of Mara et al. 2017, §3.4 (stages 3-7 of Figure 2), and TAA.
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
    pub taa: bool,
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
    /// MatteSettings::taa_resampled_frames; the glossy chain uncapped; these caps counted the
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
    /// TAA: weight of the current frame in the blend.
    pub taa_alpha: f32,
    /// TAA: the current frame's weight is 2 / (n + 1) for a history of n frames, the
    /// exponential blend whose samples are on average as old as those of an n-frame mean. It is
    /// held at taa_alpha while the pixel moves or its history is clamped, and in a still view
    /// falls to 1 / taa_still_frames. taa_alpha alone weighs the latest Halton offsets most, so
    /// a pixel on an edge keeps flickering around its box-filtered value (FlightHelmet's horizon
    /// pixel came out 7% too bright). 2 / (n + 1) rather than the plain mean 1 / n: the first
    /// frames, denoised from little history, fade as (k / n)^2 rather than k / n. Measured at
    /// 160x90, 60 frames, 256-frame references: level FLIP 0.0601 and temporal error 0.00270
    /// (the plain mean 1 / n: 0.0623 and 0.00186; taa_alpha alone: 0.0599 and 0.00449);
    /// FlightHelmet 0.0113 and 0.00036 (1 / n: 0.0112 and 0.00024; taa_alpha alone: 0.0116 and
    /// 0.00063). 0: taa_alpha always. In a static view (no camera or object motion) the history
    /// is not clamped at all (shaders/taa/taa.wgsl), so a still pixel always reaches this blend.
    pub taa_still_frames: f32,
    /// TAA: when a pixel that moved in the last frame stands still again (the camera stopped),
    /// its history length restarts at this many frames, so that the sharp still frames replace
    /// a history that bilinear resampling blurred while it moved; held at taa_alpha, that
    /// history still weighed 44% ten frames after the stop. 0: the length carries on. Strafe as
    /// MatteSettings::resampled_history_frames (no history caps), FLIP 1, 5, 10 and 19 frames
    /// after the stop: carrying on 0.1137, 0.1019, 0.0932, 0.0842; restarting at 4 frames
    /// 0.1097, 0.0903, 0.0837, 0.0783; at 1 0.1128, 0.0897, 0.0830, 0.0778.
    pub taa_resampled_frames: f32,
    /// TAA: the image shown for a settled pixel (still, history not clamped) is the last one
    /// shown, blended towards TAA's history with this many times the history's own weight
    /// 2 / (n + 1) (at most 1; 0: the history is shown as is). The jittered raster samples a
    /// sub-pixel edge at a new offset every frame, and the history moves by 2 / (n + 1) of the
    /// edge's contrast each time: on Lantern's lit glass, an edge of 0.94 over black, 0.02 per
    /// frame at frame 45. The second blend damps the Halton offsets' alternation from frame to
    /// frame (periods of 2 and 3) and passes the slower convergence of the denoised light; tied
    /// to the history's weight, it adds a quarter of the history's own lag, so a young history
    /// (the first frames, a stop after moving) is shown nearly as is. Temporal error over frames
    /// 30-59 at 160x90 (Lantern; raw 6.21e-5) and FLIP (level, 60 still frames, second half /
    /// last; the jump of GlossySettings::resampled_history_frames, its still frames 10-19 and
    /// its uncovered pixels 10 frames after the stop), for 0, 2, 4, 8: Lantern 2.1e-5, 2.3e-6,
    /// 3.9e-6, 7.0e-6; level 0.0481 / 0.0456 at 0 and 0.0484 / 0.0458 at 4; jump 0.0756 /
    /// 0.1066, 0.0779 / 0.1118, 0.0762 / 0.1079 at 0, 2, 4. The lag costs most where the
    /// history converges slowest, at 0 and 4: the living room 0.1632 / 0.1502 and 0.1673 /
    /// 0.1544 (its temporal error 0.0209 and 0.0045), the staircase 0.0645 / 0.0615 and 0.0652 /
    /// 0.0621. A constant weight of 0.25 (5.0e-6 on Lantern) lagged the first frames: the
    /// jump's still frames 0.0788.
    pub taa_display_ratio: f32,
    /// TAA: how much of a settled pixel's lag in the matte light it takes out (0: none, 1: all).
    /// TAA's history of a still pixel averages composites whose matte light was itself a running
    /// mean, so it weighs old, little-converged light most. TAA also keeps averages of the matte
    /// factor m (1 - F)^2 and of what the composite adds beside it, and shows
    /// avg(m (1 - F)^2) x the matte temporal's current output + avg(the rest): equal to its
    /// history while the light stands still, and following the light as it converges. Used only
    /// where the matte history continues last frame's (this pixel's own texel) and is at least
    /// as long as TAA's; a sample off the surface or a history taken from a neighbouring texel
    /// (a silhouette under the jitter) keeps TAA's plain average: following the light there
    /// left a dotted line of white pixels along the level's roof against the sky. FLIP at
    /// 160x90, 60 still frames (second half / last frame; staircase 160x284), 0 against 1:
    /// living room 0.1673 / 0.1544 and 0.1592 / 0.1465, staircase 0.0652 / 0.0621 and 0.0647 /
    /// 0.0614, level 0.0484 / 0.0458 and 0.0490 / 0.0464; Lantern 0.0019 / 0.0017 either way,
    /// its temporal error 1/15.7 and 1/15.2 of raw. Measured again with stage 7's guided
    /// edge-stop, 0 against 1: living room 0.1513 / 0.1403 and 0.1467 / 0.1358 (its 64-spp
    /// yardstick 0.1403), staircase 0.0591 / 0.0564 and 0.0591 / 0.0562, level 0.0462 / 0.0440
    /// and 0.0469 / 0.0444. The trade: the current light is the temporal stage's output, before
    /// the spatial filters, and where noise rather than lag dominates it costs: cornell_diffuse
    /// at 256², 30 frames, against 256 accumulated frames, FLIP 0.0407 and 0.0428, relMSE
    /// 0.0016 and 0.0027. The default serves the interiors, whose slow light is the harder case.
    pub taa_current_light: f32,
    /// TAA: as `taa_current_light`, for the glossy light: a settled pixel shows
    /// avg(F(w_s) x the mirror demodulation) x the glossy temporal's current output in place of
    /// TAA's average of the glossy term (0: none, 1: all). Used where the glossy history is this
    /// pixel's own texel, read exactly, and at least as long as TAA's. The glossy history
    /// converges slowly where it reflects bright, rarely sampled light, and TAA's average of it
    /// lagged most there: the pixels that gained most (the top 5% hold 71% of the gain) lie on
    /// the living room's varnished floor, which reflects its windows, and on its mirror. FLIP at
    /// 160x90, 60 still frames (second half / last frame; staircase 160x284), 0 against 1:
    /// living room 0.1592 / 0.1465 and 0.1541 / 0.1414, staircase 0.0647 / 0.0614 and 0.0642 /
    /// 0.0610.
    pub taa_current_glossy: f32,
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
            taa: true,
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
            taa_alpha: 0.1,
            taa_still_frames: 64.0,
            taa_resampled_frames: 1.0,
            taa_display_ratio: 4.0,
            taa_current_light: 1.0,
            taa_current_glossy: 1.0,
            inject_nonfinite: false,
        }
    }
}

impl MatteSettings {
    /// Names accepted by `--disable` and shown in the viewer (the glossy chain's are in
    /// [`GlossySettings::STAGES`]).
    pub const STAGES: [&str; 6] = ["matte.temporal", "matte.history_bilateral", "matte.disocclusion", "matte.firefly", "matte.bilateral", "taa"];

    /// Turn a stage off by name; false for an unknown name.
    pub fn disable(&mut self, name: &str) -> bool {
        let f = match name {
            "matte.temporal" => &mut self.temporal,
            "matte.history_bilateral" => &mut self.history_bilateral,
            "matte.disocclusion" => &mut self.disocclusion,
            "matte.firefly" => &mut self.firefly,
            "matte.bilateral" => &mut self.bilateral,
            "taa" => &mut self.taa,
            _ => return false,
        };
        *f = false;
        true
    }

    /// Stage bits as the shaders read them (shaders/matte/common.wgsl: STAGE_*).
    pub fn stage_bits(&self) -> u32 {
        [self.temporal, self.history_bilateral, self.disocclusion, self.firefly, self.bilateral, self.taa]
            .iter()
            .enumerate()
            .map(|(i, on)| (*on as u32) << i)
            .sum()
    }
}

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
    pub const ALL: [ReflectionMv; 3] = [ReflectionMv::Primary, ReflectionMv::Virtual, ReflectionMv::Diamond];

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

/// The glossy chain: Mara et al. 2017 §3.4 stages 8-10 with the reflection reprojection and
/// neighbourhood clipping of Voorhuis §4.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GlossySettings {
    /// Stage switches. Without `temporal` nothing is reprojected (Voorhuis's "NoSpecReproj").
    pub temporal: bool,
    /// Neighbourhood clipping of the reprojected history (Voorhuis §4.2.3), off by default as
    /// the matte clamp is: at one sample per pixel the 5x5 box of the blurred current frame
    /// rarely holds the rare bright paths a converged history averages, so clipping drains
    /// energy from every glossy surface. Measured with it on and off (jitter-aware
    /// reprojection): the level at 160x90 (60 still frames, 256-frame reference) 0.0738 and
    /// 0.0694 FLIP (a mirror in the hall's doorway lost a fifth of its reflection's brightness);
    /// `hush-cli reflections`, strafe with diamond vectors: reflective FLIP 0.1470 and 0.1371,
    /// ghost region 0.2576 and 0.2395; still camera, chain-output temporal error 0.00537 and
    /// 0.00302. Ghosts are left to the confidence tests.
    pub clipping: bool,
    /// The separable bilateral (stages 9 and 10).
    pub bilateral: bool,
    pub reflection_mv: ReflectionMv,
    /// Below this roughness reflections are reprojected with reflection motion vectors; above it
    /// with the surface's (Voorhuis §4.2.1: 0.4).
    pub roughness_threshold: f32,
    /// At or below this roughness a surface is a mirror: its chain matches exact reflected hit
    /// positions (eq. 1), filters with the reflected surface's normal and demodulates by its
    /// reflectance (§4.1). Above it, the representative-ray distance of eq. (4)-(5).
    pub mirror_roughness: f32,
    /// Neighbourhood clipping applies below this roughness (§4.2.3: 0.9).
    pub clip_roughness: f32,
    /// Hysteresis h, as the matte temporal's (Mara: the same confidence and clamping).
    pub hysteresis: f32,
    /// The surface reprojection (rough surfaces, and every surface in a static view) rejects a
    /// previous texel whose normal is more than this many degrees from the surface's (180: off).
    /// With the jitter a crease's two faces, or a ledge thinner than a pixel and the face behind
    /// it, take turns under one pixel; eq. (11) passes both, but they reflect different things
    /// under different F(w_s), and the chain filters light divided by F: the staircase's table
    /// edge came out 10x too bright. FLIP at 160x90, 60 still frames (second half / last frame;
    /// references of 512 frames for the staircase at 160x284, 2048 for the living room, 1024
    /// otherwise) with the test off, at 25, 10 and 5 degrees: staircase 0.0726 / 0.0702,
    /// 0.0655 / 0.0627, 0.0645 / 0.0615, 0.0644 / 0.0614; FlightHelmet 0.0096 / 0.0091,
    /// 0.0091 / 0.0086, 0.0081 / 0.0072, 0.0080 / 0.0071; Lantern 0.0023 / 0.0023, then
    /// 0.0019 / 0.0018 at every angle; level 0.0486 / 0.0462, then 0.0481 / 0.0456 at every
    /// angle; the living room 0.1603 / 0.1479, 0.1632 / 0.1506, 0.1632 / 0.1502 (its shorter
    /// histories cost more than the mix did).
    pub reprojection_normal_degrees: f32,
    /// First step of the diamond search's large pattern, pixels (Appendix A: 4; 1 = no LDSP
    /// scaling).
    pub initial_step: u32,
    /// Most large-pattern iterations per pixel (bounds the search's cost).
    pub max_search_steps: u32,
    /// Eq. (11)'s d0, d1 for mirrors, in pixel footprints at the reflected distance.
    pub d0_px: f32,
    pub d1_px: f32,
    /// Bilateral sigma = scale x roughness^exponent + epsilon pixels (Mara: 7, 0.1, epsilon).
    /// Epsilon is 1 px so that mirrors (roughness 0) are still filtered, across the reflected
    /// surface's features.
    pub sigma_scale: f32,
    pub sigma_exponent: f32,
    pub sigma_epsilon_px: f32,
    /// Beyond this many frames of history the bilateral's sigma shrinks as 1 / history length:
    /// a converged history needs no spatial blur, a fresh one (disocclusion, motion) gets all
    /// of it, as the matte chain's disocclusion-driven radius. 0: Mara's fixed sigma. FLIP on
    /// the level (160x90, 40 still frames, 128-frame reference): fixed sigma 0.0994, no glossy
    /// bilateral 0.0790, 1 / sqrt(n) past 4 frames 0.0864, past 1 frame 0.0816: the fixed blur
    /// of a converged history costs more than the noise it removes. 1 / n past 1 frame (60
    /// still frames, 256-frame reference, TAA's still blend): 0.0652 against 0.0673 with
    /// 1 / sqrt(n) and 0.0651 with no glossy bilateral; on a path of 20 still, 20 strafing and 20
    /// still frames (128-frame references) FLIP still / moving / settled 0.0942 / 0.1085 /
    /// 0.0946 against 0.0970 / 0.1092 / 0.0950 with 1 / sqrt(n).
    pub sigma_full_frames: f32,
    /// A history resampled bilinearly (by surface or reflection motion) counts as at most this
    /// many frames, as MatteSettings::resampled_history_frames (0: no cap). A moving glossy
    /// history holds the reflections seen on the way, and once the camera stops it weighs
    /// cap / (cap + k) after k still frames: what a fast move uncovered stayed worse than a
    /// fresh start for over 20 frames with a cap of 8. Level at 160x90, 20 still frames, a
    /// 1.2 m strafe in 5 frames, 35 still frames, 128-frame reference: FLIP over the 487
    /// pixels flagged on the last moving frame (grown by one) 10 and 20 frames after the stop,
    /// against 0.1117 and 0.1018 for a fresh start at that view: uncapped 0.1593 / 0.1406, 8
    /// frames 0.1367 / 0.1170, 4 frames 0.1226 / 0.1047, 2 frames 0.1124 / 0.0977, 1 frame
    /// 0.1071 / 0.0943 (whole frame 10 frames after: 0.0807, 0.0749, 0.0717, 0.0701, 0.0695).
    /// The slow strafe of MatteSettings::resampled_history_frames (matte capped at 8), FLIP 10
    /// frames after the stop / moving mean: uncapped 0.0805 / 0.1014, 8 frames 0.0720 / 0.1002,
    /// 2 frames 0.0709 / 0.0999, 1 frame 0.0714 / 0.1013. `hush-cli reflections`, strafe with
    /// diamond vectors, 8 frames and 1: reflective FLIP 0.1256 and 0.1197, ghost region 0.2234
    /// and 0.2111 (primary vectors: 0.1622 and 0.1282); the still camera's are unchanged.
    pub resampled_history_frames: f32,
    /// Voorhuis eq. (6)'s omega, with the ray differential at the secondary hit measured in
    /// pixel footprints of the primary surface (scale-free, unlike the paper's world units):
    /// sigma is multiplied by exp(-footprints / omega) below the roughness threshold.
    pub ray_differential_omega: f32,
    /// Bilateral weight on roughness differences: exp(-(dr / sigma)^2).
    pub roughness_sigma: f32,
    /// Trace each glossy pixel's representative (mirror) ray below the roughness threshold, and
    /// search by eq. (1) on its real hit; off, eq. (4) extends the ray by the sample's depth and
    /// the search uses eq. (5). On the `spheres` strafe (160x90, against a 65x65 brute-force
    /// search) the glossy sphere's vectors were 8.05 px off on average (42.6% within 1 px) with
    /// sampled depths, whose jumps between near and far geometry make eq. (5)'s minimum
    /// ambiguous, and 0.31 px (92.6%) with traced ones, for one closest-hit ray per such pixel.
    pub trace_representative_ray: bool,
    /// Measurements only: also run a brute-force search over a window of this radius (pixels)
    /// and report the diamond search's distance to it in the search view (0: off).
    #[serde(skip)]
    pub reference_search_radius: u32,
}

impl Default for GlossySettings {
    fn default() -> Self {
        GlossySettings {
            temporal: true,
            clipping: false,
            bilateral: true,
            reflection_mv: ReflectionMv::Diamond,
            roughness_threshold: 0.4,
            mirror_roughness: 0.01,
            clip_roughness: 0.9,
            hysteresis: 0.98,
            reprojection_normal_degrees: 10.0,
            initial_step: 4,
            max_search_steps: 32,
            d0_px: 2.0,
            d1_px: 4.0,
            sigma_scale: 7.0,
            sigma_exponent: 0.1,
            sigma_epsilon_px: 1.0,
            sigma_full_frames: 1.0,
            resampled_history_frames: 1.0,
            ray_differential_omega: 16.0,
            roughness_sigma: 0.1,
            trace_representative_ray: true,
            reference_search_radius: 0,
        }
    }
}

impl GlossySettings {
    pub const STAGES: [&str; 3] = ["glossy.temporal", "glossy.clipping", "glossy.bilateral"];

    pub fn disable(&mut self, name: &str) -> bool {
        let f = match name {
            "glossy.temporal" => &mut self.temporal,
            "glossy.clipping" => &mut self.clipping,
            "glossy.bilateral" => &mut self.bilateral,
            _ => return false,
        };
        *f = false;
        true
    }

    /// Stage bits as shaders/glossy/common.wgsl reads them.
    pub fn stage_bits(&self) -> u32 {
        self.temporal as u32 | (self.clipping as u32) << 1 | (self.bilateral as u32) << 2
    }

    /// The glossy bilateral's Gaussian sigma in pixels: Mara et al. §3.4's 7 r^0.1 + epsilon,
    /// times Voorhuis eq. (6)'s exp(-dP / omega) below the roughness threshold, where
    /// `footprints` is the secondary hit's ray differential in primary pixel footprints.
    /// shaders/glossy/common.wgsl's glossy_sigma is the same function.
    pub fn sigma_px(&self, roughness: f32, footprints: f32) -> f32 {
        let base = self.sigma_scale * roughness.clamp(0.0, 1.0).powf(self.sigma_exponent) + self.sigma_epsilon_px;
        let scale = if roughness < self.roughness_threshold { (-footprints.max(0.0) / self.ray_differential_omega.max(1e-3)).exp() } else { 1.0 };
        (base * scale).clamp(0.0, MAX_GLOSSY_SIGMA_PX)
    }
}

/// Largest glossy bilateral sigma, pixels (the kernel reaches 2.5 sigma).
pub const MAX_GLOSSY_SIGMA_PX: f32 = 9.0;

/// Disable a stage of either chain by its `--disable` name; false for an unknown name.
pub fn disable_stage(s: &mut FrameSettings, name: &str) -> bool {
    s.matte.disable(name) || s.glossy.disable(name)
}

/// Every stage name `--disable` accepts.
pub fn stage_names() -> Vec<&'static str> {
    MatteSettings::STAGES.iter().chain(GlossySettings::STAGES.iter()).copied().collect()
}
