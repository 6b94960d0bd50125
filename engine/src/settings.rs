//! Tunables of the real-time frame, with their units and defaults.

use crate::frame::View;
use serde::{Deserialize, Serialize};

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
        FrameSettings { exposure_ev: 0.0, max_depth: crate::scene::DEFAULT_MAX_DEPTH, seed: 0, accumulate: false, view: View::Final, denoiser: Denoiser::None, matte: MatteSettings::default(), paths_per_pixel: 1 }
    }
}

/// Which denoiser filters the 1-sample frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Denoiser {
    /// The raw frame (composite only).
    None,
    /// Mara et al. 2017: matte chain (temporal, history bilateral, disocclusion radius, firefly
    /// median, final bilateral) and TAA.
    #[default]
    Mara,
}

/// The matte chain of Mara et al. 2017, §3.4 (stages 3-7 of Figure 2), and TAA.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MatteSettings {
    /// Stage switches.
    pub temporal: bool,
    pub history_bilateral: bool,
    pub disocclusion: bool,
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
    /// Taps of the sparse bilateral filters (paper: 50).
    pub taps: u32,
    /// Disk diameter of the history-loop bilateral as a fraction of the screen width (paper: 1%).
    pub history_diameter_fraction: f32,
    /// R of the disocclusion radius as a fraction of the screen width (paper: 1/20).
    pub disocclusion_fraction: f32,
    /// Radius multiplier where the confidence c < 1/2 (paper: 6).
    pub low_confidence_multiplier: f32,
    /// Largest final-bilateral radius as a fraction of the screen width.
    pub max_radius_fraction: f32,
    /// Bilateral weights: cosine power on normals, plane-distance sigma in pixel footprints.
    pub normal_power: f32,
    pub plane_sigma_px: f32,
    /// TAA: weight of the current frame in the blend.
    pub taa_alpha: f32,
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
            firefly: true,
            bilateral: true,
            taa: true,
            hysteresis: 0.98,
            d0_px: 6.0,
            d1_px: 8.5,
            clamp_sigma: 0.0,
            taps: 50,
            history_diameter_fraction: 0.01,
            disocclusion_fraction: 0.05,
            low_confidence_multiplier: 6.0,
            max_radius_fraction: 0.1,
            normal_power: 32.0,
            plane_sigma_px: 2.0,
            taa_alpha: 0.1,
            inject_nonfinite: false,
        }
    }
}

impl MatteSettings {
    /// Names accepted by `--disable` and shown in the viewer.
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
