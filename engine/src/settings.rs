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
}

impl Default for FrameSettings {
    fn default() -> Self {
        FrameSettings { exposure_ev: 0.0, max_depth: crate::scene::DEFAULT_MAX_DEPTH, seed: 0, accumulate: false, view: View::Final }
    }
}
