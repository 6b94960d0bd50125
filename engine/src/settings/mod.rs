//! Tunables of the real-time frame, with their units and defaults. `fields.rs` describes each
//! one for panels and presets; `preset.rs` saves and loads them as TOML.

mod fields;
mod fraction;
mod glossy;
mod matte;
mod preset;
mod progressive;
mod svgf;
mod taa;
mod view;

pub use fields::{Field, Kind, fields, get as get_field, get_mut as get_field_mut, leaves};
pub use fraction::{MAX_SAMPLE_PERIOD, SampleFraction};
pub use glossy::{GlossySettings, MAX_GLOSSY_SIGMA_PX, ReflectionMv};
pub use matte::MatteSettings;
pub use progressive::{MAX_LEVELS as PROGRESSIVE_MAX_LEVELS, ProgressiveSettings};
pub use svgf::{MAX_LEVELS as SVGF_MAX_LEVELS, SvgfSettings};
pub use taa::TaaSettings;
pub use view::{
    FRAME_VIEWS, MARA_VIEWS, PROGRESSIVE_VIEWS, SVGF_VIEWS, View, ViewMap, ViewSpec, all_views,
    register_views,
};

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
    pub taa: TaaSettings,
    pub glossy: GlossySettings,
    pub svgf: SvgfSettings,
    pub progressive: ProgressiveSettings,
    /// Indirect paths per pixel per frame (each of the matte and glossy estimators, and the
    /// area-light sample, is averaged over them). 1 is the paper's real-time setting.
    pub paths_per_pixel: u32,
    /// Samples per pixel k of the real-time frame (Voorhuis §5, guide rays): the raster's sample
    /// (the guide) and k - 1 traced at random positions in the pixel, each mixed into its most
    /// similar guide among the four nearest pixels before denoising (eq. 7), the pixel then the
    /// mean of its samples' guides after the composite. Anti-aliases without TAA and feeds the
    /// denoiser k times the samples; costs a traced primary ray and a full sample per extra
    /// sample. The accumulate mode ignores it (it box-filters by itself).
    pub samples_per_pixel: u32,
    /// Fraction f of the pixels traced per frame, 1 or 1/N (N = 2 ... 128; Dundr et al. §5):
    /// each frame traces one pixel of every N-pixel tile, each pixel once in N frames, and the
    /// trace's cost falls with f; a pixel not traced keeps its last sample. Only denoisers that
    /// fill the gaps accept f < 1 (none: shows each pixel's last sample). Needs k = 1 samples per
    /// pixel; the accumulate mode ignores it.
    pub sample_fraction: SampleFraction,
    /// Primary samples per pixel k where the camera has a thin lens (depth of field): the
    /// raster cannot draw a random primary hit, so `gbuffer/primaries` traces k lens rays per
    /// pixel and writes the mean of their features as the G-buffer (Moon et al. 2017 §4.2), and
    /// the path continues from the first. More samples give less noisy features (and
    /// covariances for the pre-filter) at the cost of k closest-hit rays per pixel. The
    /// accumulate mode traces 1 (its mean over frames is then exact). No effect without a lens.
    pub primary_samples: u32,
    /// Moon et al. 2017's G-buffer pre-filter (`prefilter`), where primaries are traced: the
    /// features are filtered over 7x7 pixels with world-position weights (eq. 3-4) and a
    /// per-pixel bandwidth chosen by SURE (eq. 6), so that a defocused region's noisy normals,
    /// colours and depths stop cutting the denoisers' filters while in-focus detail stays.
    pub prefilter: bool,
}

/// Traced primary samples per pixel by default (Moon et al. use 4 in their interactive tests'
/// spirit: the fewest that give a covariance).
pub const DEFAULT_PRIMARY_SAMPLES: u32 = 4;
/// The most traced primary samples per pixel (256: the converged G-buffer the pre-filter's
/// error is measured against).
pub const MAX_PRIMARY_SAMPLES: u32 = 256;

/// The most samples per pixel the real-time frame takes.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 16;

impl FrameSettings {
    /// The multiplier 2^EV applied before tone mapping (EV clamped to +-30).
    pub fn exposure_scale(&self) -> f32 {
        2f32.powf(self.exposure_ev.clamp(-30.0, 30.0))
    }
}

impl Default for FrameSettings {
    fn default() -> Self {
        FrameSettings {
            exposure_ev: 0.0,
            max_depth: crate::scene::DEFAULT_MAX_DEPTH,
            seed: 0,
            accumulate: false,
            view: View::FINAL,
            denoiser: Denoiser::NONE,
            matte: MatteSettings::default(),
            taa: TaaSettings::default(),
            glossy: GlossySettings::default(),
            svgf: SvgfSettings::default(),
            progressive: ProgressiveSettings::default(),
            paths_per_pixel: 1,
            samples_per_pixel: 1,
            sample_fraction: SampleFraction::ONE,
            primary_samples: DEFAULT_PRIMARY_SAMPLES,
            prefilter: true,
        }
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
            return Err(serde::de::Error::custom(format!(
                "no denoiser {name:?} (there are {})",
                known.join(", ")
            )));
        }
        Ok(Denoiser::named(&name))
    }
}

/// Names of the denoisers the frame can make: the built-in ones, and those
/// `crate::denoise::register` added (it keeps this list, which settings read without depending
/// on the denoisers themselves).
static DENOISER_NAMES: RwLock<Vec<&'static str>> = RwLock::new(Vec::new());

pub fn denoiser_names() -> Vec<&'static str> {
    let mut v = vec![Denoiser::NONE.0.as_ref(), "mara", "svgf", "progressive"];
    v.extend(crate::sync::read(&DENOISER_NAMES).iter());
    v
}

/// Called by `crate::denoise::register` only.
pub(crate) fn add_denoiser_name(name: &'static str) {
    crate::sync::write(&DENOISER_NAMES).push(name);
}

/// Disable a stage of any denoiser or TAA by its `--disable` name; false for an unknown name.
pub fn disable_stage(s: &mut FrameSettings, name: &str) -> bool {
    if name == TaaSettings::STAGE {
        s.taa.enabled = false;
        return true;
    }
    s.matte.disable(name)
        || s.glossy.disable(name)
        || s.svgf.disable(name)
        || s.progressive.disable(name)
}

/// Every stage name `--disable` accepts.
pub fn stage_names() -> Vec<&'static str> {
    MatteSettings::STAGES
        .iter()
        .chain(&[TaaSettings::STAGE])
        .chain(GlossySettings::STAGES.iter())
        .chain(SvgfSettings::STAGES.iter())
        .chain(ProgressiveSettings::STAGES.iter())
        .copied()
        .collect()
}
