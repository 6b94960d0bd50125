//! TAA's settings (passes/taa.rs, shaders/taa/taa.wgsl): a stage of its own after any
//! denoiser's composite. The measurements behind each default are in `docs/decisions.md`.

use super::field::{Field, Kind::*, f};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TaaSettings {
    /// Temporal anti-aliasing over a Halton(2, 3)-jittered raster; off, the raster samples pixel
    /// centres and TAA passes the composite on.
    pub enabled: bool,
    /// Weight of the current frame while a pixel moves or its history is clamped (0.1).
    pub alpha: f32,
    /// A still, unclamped pixel weighs the current frame 2 / (n + 1), down to 1 / this, default 64
    /// (0: `alpha` always): converges edges to the box-filtered pixel (temporal error 0.00270
    /// against 0.00449) at no FLIP cost.
    pub still_frames: f32,
    /// History length a pixel restarts at when it stops after moving, default 1 (0: carries on):
    /// sharp still frames replace the resampling's blur (FLIP 10 frames after a strafe 0.0830,
    /// 0.0932 carrying on).
    pub resampled_frames: f32,
    /// A settled pixel shows the last image blended towards the history by this many times the
    /// history's weight (at most 1), default 4 (0: the history): damps sub-pixel flicker (Lantern
    /// temporal error 3.9e-6 against 2.1e-5) for a quarter of the history's lag.
    pub display_ratio: f32,
    /// Share of a settled pixel's matte-light lag taken out by following the denoiser's current
    /// light, [0, 1], default 1: living room FLIP 0.1358 against 0.1403 at 0; costs where noise
    /// dominates (cornell_diffuse 0.0428 against 0.0407).
    pub current_light: f32,
    /// As `current_light`, for the glossy light, default 1 (living room FLIP 0.1414, 0.1465 at 0).
    pub current_glossy: f32,
}

impl Default for TaaSettings {
    fn default() -> Self {
        TaaSettings {
            enabled: true,
            alpha: 0.1,
            still_frames: 64.0,
            resampled_frames: 1.0,
            display_ratio: 4.0,
            current_light: 1.0,
            current_glossy: 1.0,
        }
    }
}

impl TaaSettings {
    /// Its `--disable` name.
    pub const STAGE: &str = "taa";

    /// Its bit among the chains' stage bits (shaders/matte/common.wgsl: STAGE_TAA).
    pub fn stage_bit(&self) -> u32 {
        (self.enabled as u32) << 5
    }
}

/// Its fields, in panel order.
pub const FIELDS: &[Field] = &[
    f(
        "taa.enabled",
        "taa",
        "",
        Bool,
        "Temporal anti-aliasing with a jittered raster and YCoCg clamping.",
    ),
    f(
        "taa.alpha",
        "taa",
        "",
        Float(0.0, 1.0, 0.005),
        "Weight of the current frame in TAA's blend.",
    ),
    f(
        "taa.display_ratio",
        "taa",
        "",
        Float(0.0, 64.0, 0.5),
        "The shown image follows a settled pixel's history with this many times its weight (0: shows it as is).",
    ),
    f(
        "taa.current_light",
        "taa",
        "",
        Float(0.0, 1.0, 0.05),
        "Share of a settled pixel's matte-light lag taken out (the denoiser's current matte light in place of TAA's average).",
    ),
    f(
        "taa.current_glossy",
        "taa",
        "",
        Float(0.0, 1.0, 0.05),
        "Share of a settled pixel's glossy-light lag taken out (the denoiser's current glossy light in place of TAA's average).",
    ),
    f(
        "taa.resampled_frames",
        "taa",
        "frames",
        Float(0.0, 64.0, 1.0),
        "History length a pixel restarts at when it stands still after moving (0: carries on).",
    ),
    f(
        "taa.still_frames",
        "taa",
        "",
        Float(0.0, 256.0, 1.0),
        "In a still view the current frame's weight falls to 1 / this (0: always alpha).",
    ),
];
