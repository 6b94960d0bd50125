//! Tunables of the real-time frame, with their units and defaults. `fields.rs` describes each
//! one for panels and presets; `preset.rs` saves and loads them as TOML.

mod cache;
mod denoiser_info;
mod field;
mod fields;
mod fraction;
mod glossy;
pub mod mara;
mod matte;
mod preset;
pub mod progressive;
pub mod registry;
mod reprojection;
pub mod svgf;
mod taa;
mod view;
mod view_spec;

pub use cache::{CacheSettings, MAX_CELLS_LOG2};
pub use fields::{Field, Kind, fields, get as get_field, get_mut as get_field_mut, leaves};
pub use fraction::{MAX_SAMPLE_PERIOD, SampleFraction};
pub use glossy::{GlossySettings, MAX_GLOSSY_SIGMA_PX, ReflectionMv};
pub use matte::MatteSettings;
pub use progressive::{MAX_LEVELS as PROGRESSIVE_MAX_LEVELS, ProgressiveSettings};
pub use registry::all_views;
pub use registry::{DenoiserInfo, Off, Section, Stage};
pub use reprojection::ReprojectionSettings;
pub use svgf::{MAX_LEVELS as SVGF_MAX_LEVELS, STILL_FRAMES_MAX, SvgfSettings};
pub use taa::TaaSettings;
pub use view::View;
pub use view_spec::{FRAME_VIEWS, ViewMap, ViewSpec};

use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::borrow::Cow;
use std::collections::BTreeMap;

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
    /// The reprojection test every temporal stage shares (the frame's, not a denoiser's).
    pub reprojection: ReprojectionSettings,
    pub matte: MatteSettings,
    pub taa: TaaSettings,
    pub glossy: GlossySettings,
    pub svgf: SvgfSettings,
    pub progressive: ProgressiveSettings,
    /// The radiance cache (passes/cache.rs), a stage of the frame any denoiser may read.
    pub cache: CacheSettings,
    /// Indirect paths per pixel per frame (each of the matte and glossy estimators, and the
    /// area-light sample, is averaged over them). 1 is the paper's real-time setting.
    pub paths_per_pixel: u32,
    /// Paths per pixel where the pixel's surface was not on screen last frame (a move or an
    /// object uncovered it), in frames where something moved and a denoiser keeps a history:
    /// Mara's and SVGF's matte temporal stages count a restarted history's sample as that
    /// many frames. Costs (n - paths_per_pixel) paths at those pixels only (at most 3.9% of
    /// the level's at 320x180 on its jump's frame). A cut or a first frame, with no history,
    /// and a still frame trace paths_per_pixel everywhere. The level's jump, uncovered pixels
    /// over the ten frames after it, FLIP at 1 / 8 paths: Mara 0.1357 / 0.1272, SVGF 0.1415 /
    /// 0.1375. 0: off.
    pub uncovered_paths: u32,
    /// Light candidates per matte light sample of the real-time frame (resampled importance
    /// sampling, Talbot 2005; the first step of ReSTIR DI, Bitterli et al. 2020 §3): M samples
    /// of the light tree (or the environment), one kept with probability proportional to its
    /// unshadowed matte contribution, one shadow ray for it; on glossy lobes of roughness 0.2
    /// or more the same candidates are resampled again by their glossy contribution, with a
    /// shadow ray of their own (smoother lobes keep the first candidate and its MIS with the
    /// glossy path). A path whose first vertex's sample was resampled adds no light its first
    /// segment hits (the resampled sample stands for it). 1: one sample, MIS-weighted against
    /// the paths as the reference tracer does. Costs M - 1 tree walks and up to two shadow rays
    /// a traced pixel. The many-lamp hall at 320x180 (lavapipe), frame 30 against Mitsuba, at
    /// M = 1 / 4 / 8: SVGF FLIP 0.0586 / 0.0565 / 0.0547, raw 0.2549 / 0.2388 / 0.2330; the
    /// whole frame 98.8 / 124.1 / 158.6 ms: less than its cost, so the default is 1.
    pub light_candidates: u32,
    /// With light_candidates > 1: the matte light sample of the first path also merges the
    /// reservoir the last frame kept where the surface point was (ReSTIR DI's temporal reuse,
    /// Bitterli et al. 2020 §4), so each pixel's sample stands for up to 21 frames' candidates.
    /// Costs one reservoir read and write a pixel and 64 bytes a pixel. The many-lamp hall's
    /// direct light alone (max_depth 2, raw frame 30, 320x180, M = 8) scores FLIP 0.122 with it
    /// and 0.161 without; the whole raw frame 0.2251 against 0.2330, but SVGF's frame 30 0.0638
    /// against 0.0547: SVGF's temporal filter takes reused, correlated samples for independent
    /// ones. A still view's accumulated mean moves 0.16-0.18% (the biased merge).
    pub light_reuse: bool,
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
    /// the path continues from the first, its light scaled from the mean material to its own so
    /// that a pixel whose samples hit two materials keeps its mean. More samples give less noisy features (and
    /// covariances for the pre-filter) at the cost of k closest-hit rays per pixel. The
    /// accumulate mode traces 1 (its mean over frames is then exact). No effect without a lens.
    pub primary_samples: u32,
    /// Moon et al. 2017's G-buffer pre-filter (`prefilter`), where primaries are traced: the
    /// features are filtered over 7x7 pixels with world-position weights (eq. 3-4) and a
    /// per-pixel bandwidth chosen by SURE (eq. 6), so that a defocused region's noisy normals,
    /// colours and depths stop cutting the denoisers' filters while in-focus detail stays.
    pub prefilter: bool,
    /// Ray cones (Akenine-Moller et al. 2019) choose the mip level of every texture read after
    /// the primary hit, so that an indirect ray landing on a distant or grazing textured
    /// surface reads the mean of what its footprint covers instead of one texel of it: less
    /// noise for the denoisers at the same converged image (tests/textures.rs measures both).
    /// Costs a triangle's texture-coordinate area at each textured secondary hit. Off reads the
    /// finest level everywhere.
    pub texture_lod: bool,
    /// The real-time trace draws each pixel's light sample and matte path's first direction
    /// from screen-space strata (common/rng.wgsl: a randomized R_d lattice over each 16x16
    /// tile) instead of the pixel's own random sequence: every pixel's estimate is as noisy as
    /// before, and a block of pixels' mean is closer to the integral, so the error the
    /// denoisers' windows cannot average away shrinks. Frame 60 of a still view with SVGF,
    /// FLIP (mean of seeds), off / on: cornell_diffuse (256², against Mitsuba) 0.0268 /
    /// 0.0252, cornell_mirror 0.0575 / 0.0573, the level (160x90, seven seeds) 0.0545 /
    /// 0.0551, within its seeds' spread. Off renders the pixel's own random sequence.
    pub screen_strata: bool,
    /// A change of the frame's size (the governor's resolution scale, a window resize)
    /// resamples every history to the new size (passes/rescale.rs) instead of restarting it,
    /// and each temporal stage then counts it as at most this many frames: a still view keeps
    /// what it had accumulated, and the new size's samples replace its blur (more: a better
    /// first frame after the change, a longer-lived blur). The level scaled 2x after 24 still
    /// frames, relMSE of the first frame: Mara 0.064 (0.632 restarted), SVGF 0.052 (0.090); 16
    /// frames on, the progressive filter 0.028 against 0.025 restarted (the blur kept); a cap
    /// of 8 is better only in SVGF's first two frames. Costs one pass per history texture on
    /// the frame after the change (0.8-0.95 ms on an H200 at 1280x720). 0: every history
    /// restarts from one sample.
    pub resample_history_frames: f32,
    /// The settings of denoisers an application registered, by their section's name: `[name]`
    /// in a preset, `name.field` in a field path ([`registry::Section`]).
    #[serde(flatten)]
    pub sections: BTreeMap<String, Value>,
    /// Fault injection for tests: the matte light entering every denoiser reads NaN, +Inf and
    /// -Inf on a sparse pixel pattern (1 in 7).
    #[serde(skip)]
    pub inject_nonfinite: bool,
}

/// Traced primary samples per pixel by default (Moon et al. use 4 in their interactive tests'
/// spirit: the fewest that give a covariance).
pub const DEFAULT_PRIMARY_SAMPLES: u32 = 4;
/// The most traced primary samples per pixel (256: the converged G-buffer the pre-filter's
/// error is measured against).
pub const MAX_PRIMARY_SAMPLES: u32 = 256;

/// Light candidates per matte light sample by default ([`FrameSettings::light_candidates`]).
pub const DEFAULT_LIGHT_CANDIDATES: u32 = 1;
/// The most light candidates a matte light sample resamples.
pub const MAX_LIGHT_CANDIDATES: u32 = 64;

/// The most paths per pixel the real-time frame traces.
pub const MAX_PATHS_PER_PIXEL: u32 = 64;

/// The most samples per pixel the real-time frame takes.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 16;

impl FrameSettings {
    /// The multiplier 2^EV applied before tone mapping (EV clamped to +-30).
    pub fn exposure_scale(&self) -> f32 {
        2f32.powf(self.exposure_ev.clamp(-30.0, 30.0))
    }

    /// Frames between two samples of one pixel: the sample fraction's 1 / f, and 1 in the
    /// accumulate mode, which traces every pixel each frame.
    pub fn sample_period(&self) -> u32 {
        if self.accumulate { 1 } else { self.sample_fraction.period() }
    }
}

impl Default for FrameSettings {
    /// Every setting at its default, registered denoisers' sections included.
    fn default() -> Self {
        let sections = registry::denoisers()
            .iter()
            .filter_map(|d| d.section)
            .map(|s| (s.name.to_string(), (s.defaults)()))
            .collect();
        FrameSettings { sections, ..FrameSettings::typed_default() }
    }
}

impl FrameSettings {
    /// The built-in settings at their defaults (no registered sections).
    fn typed_default() -> FrameSettings {
        FrameSettings {
            exposure_ev: 0.0,
            max_depth: crate::scene::DEFAULT_MAX_DEPTH,
            seed: 0,
            accumulate: false,
            view: View::FINAL,
            denoiser: Denoiser::NONE,
            reprojection: ReprojectionSettings::default(),
            matte: MatteSettings::default(),
            taa: TaaSettings::default(),
            glossy: GlossySettings::default(),
            svgf: SvgfSettings::default(),
            progressive: ProgressiveSettings::default(),
            cache: CacheSettings::default(),
            paths_per_pixel: 1,
            uncovered_paths: 8,
            light_candidates: DEFAULT_LIGHT_CANDIDATES,
            light_reuse: true,
            texture_lod: true,
            screen_strata: true,
            resample_history_frames: 4.0,
            samples_per_pixel: 1,
            sample_fraction: SampleFraction::ONE,
            primary_samples: DEFAULT_PRIMARY_SAMPLES,
            prefilter: true,
            sections: BTreeMap::new(),
            inject_nonfinite: false,
        }
    }

    /// The names the built-in settings take at the top of a preset: no section may use one.
    pub fn typed_sections() -> Vec<String> {
        match FrameSettings::typed_default().to_value() {
            Value::Object(m) => m.keys().cloned().collect(),
            _ => vec![],
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
    pub const NONE: Denoiser = Denoiser(Cow::Borrowed(registry::NONE.name));

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

/// Names of the denoisers the frame can make, built-in first ([`registry::denoisers`]).
pub fn denoiser_names() -> Vec<&'static str> {
    registry::denoisers().iter().map(|d| d.name).collect()
}

/// TAA's `--disable` name: TAA runs after any denoiser.
pub const TAA_STAGE: &str = TaaSettings::STAGE;

/// The still-view mean's `--disable` name (`passes/converge.rs`): it runs after TAA.
pub const CONVERGE_STAGE: &str = "converge";

/// Every stage `--disable` accepts: each denoiser's, then TAA's (and its glossy term under
/// motion) and the still-view mean's.
pub fn stages() -> Vec<Stage> {
    let taa = Stage { name: TAA_STAGE, path: "taa.enabled", off: Off::False };
    let converge = Stage { name: CONVERGE_STAGE, path: "taa.converge_sigmas", off: Off::Zero };
    registry::denoisers()
        .iter()
        .flat_map(|d| d.stages.iter().copied())
        .chain([taa, Stage::switch("taa.moving_glossy"), converge])
        .collect()
}

/// Every stage name `--disable` accepts.
pub fn stage_names() -> Vec<&'static str> {
    stages().iter().map(|s| s.name).collect()
}

/// Switch off a stage of any denoiser or TAA by its `--disable` name: its setting set to its
/// off value. False for an unknown name.
pub fn disable_stage(s: &mut FrameSettings, name: &str) -> bool {
    let Some(stage) = stages().into_iter().find(|st| st.name == name) else { return false };
    let mut v = s.to_value();
    let Some(field) = get_field_mut(&mut v, stage.path) else { return false };
    *field = match stage.off {
        Off::False => Value::Bool(false),
        Off::Zero => Value::from(0),
    };
    match FrameSettings::from_value(&v) {
        Ok(changed) => {
            *s = changed;
            true
        }
        Err(_) => false,
    }
}

/// The a-trous levels the chosen denoiser's settings ask for, where it declares them
/// ([`DenoiserInfo::levels`]: SVGF, the progressive filter); None for Mara's chains and `none`.
pub fn filter_levels(s: &FrameSettings) -> Option<u32> {
    levels_at(&s.to_value(), levels_path(s)?)
}

/// The chosen denoiser's a-trous levels brought down to `cap` where they are more (the
/// frame-time governor's [`crate::governor::Choice::levels`]); other settings and other
/// denoisers are left as they are.
pub fn cap_filter_levels(s: &mut FrameSettings, cap: u32) {
    let Some(path) = levels_path(s) else { return };
    let mut v = s.to_value();
    if levels_at(&v, path).is_none_or(|levels| levels <= cap) {
        return;
    }
    if let Some(field) = get_field_mut(&mut v, path) {
        *field = Value::from(cap);
    }
    // The cap is below a value the settings already held, so it is in range.
    if let Ok(capped) = FrameSettings::from_value(&v) {
        *s = capped;
    }
}

/// The dotted path of the chosen denoiser's a-trous levels, where it has them.
fn levels_path(s: &FrameSettings) -> Option<&'static str> {
    registry::denoiser(s.denoiser.name()).ok()?.levels
}

fn levels_at(v: &Value, path: &str) -> Option<u32> {
    u32::try_from(get_field(v, path)?.as_u64()?).ok()
}

/// A switch word as the shaders read it: bit i is the i-th switch's state (each switch named by
/// the WGSL constant that tests it).
pub fn switch_bits(switches: &[(&str, bool)]) -> u32 {
    switches.iter().enumerate().map(|(i, (_, on))| (*on as u32) << i).sum()
}
