//! TAA's settings (passes/taa.rs, shaders/taa/taa.wgsl): a stage of its own after any
//! denoiser's composite. The measurements behind each default are in `docs/decisions.md`.

use super::field::{Kind::*, described};
use serde::{Deserialize, Serialize};

described! {
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(default)]
    pub struct TaaSettings / FIELDS {
        /// Temporal anti-aliasing over a Halton(2, 3)-jittered raster; off, the raster samples pixel
        /// centres and TAA passes the composite on.
        enabled: bool = true,
            ("taa.enabled", "taa", "", Bool);
        /// Weight of the current frame while a pixel moves or its history is clamped (0.1).
        alpha: f32 = 0.1,
            ("taa.alpha", "taa", "", Float(0.0, 1.0, 0.005));
        /// A settled pixel shows the last image blended towards the history by this many times the
        /// history's weight (at most 1), default 4 (0: the history): damps sub-pixel flicker (Lantern
        /// temporal error 3.9e-6 against 2.1e-5) for a quarter of the history's lag.
        display_ratio: f32 = 4.0,
            ("taa.display_ratio", "taa", "", Float(0.0, 64.0, 0.5));
        /// Share of a settled pixel's matte-light lag taken out by following the denoiser's current
        /// light, [0, 1], default 1: living room FLIP 0.1358 against 0.1403 at 0; costs where noise
        /// dominates (cornell_diffuse 0.0428 against 0.0407).
        current_light: f32 = 1.0,
            ("taa.current_light", "taa", "", Float(0.0, 1.0, 0.05));
        /// As `current_light`, for the glossy light, default 1 (living room FLIP 0.1414, 0.1465 at 0).
        /// Where TAA follows both lights (Mara's chains) one share applies to both, the larger of
        /// the two: TAA keeps no average of each light's term apart, so between 0 and 1 this
        /// changes nothing beside `current_light` 1. At 0 a still view's reflections move less
        /// (`hush-cli reflections`, Mara: 0.00101 against 0.00139 a frame) and lag more.
        current_glossy: f32 = 1.0,
            ("taa.current_glossy", "taa", "", Float(0.0, 1.0, 0.05));
        /// Where a pixel moves, the glossy term in TAA's history is replaced by the one the
        /// composite shows now: the denoiser carried it along the reflection's motion, TAA's
        /// history moves with the surface, and reflections move over their surfaces. Default on:
        /// `hush-cli reflections` strafe, reflective / ghost-region FLIP Mara 0.1168 / 0.2211 ->
        /// 0.0977 / 0.1941, SVGF 0.1153 / 0.2244 -> 0.0933 / 0.1923; the glossy term is no longer
        /// averaged by TAA while it moves, so Mara's relative error there rises 6%. Still pixels
        /// are unchanged. 24 bytes per pixel.
        moving_glossy: bool = true,
            ("taa.moving_glossy", "taa", "", Bool);
        /// History length a pixel restarts at when it stops after moving, default 1 (0: carries on):
        /// sharp still frames replace the resampling's blur (FLIP 10 frames after a strafe 0.0830,
        /// 0.0932 carrying on).
        resampled_frames: f32 = 1.0,
            ("taa.resampled_frames", "taa", "frames", Float(0.0, 64.0, 1.0));
        /// A still, unclamped pixel weighs the current frame 2 / (n + 1), down to 1 / this, default 64
        /// (0: `alpha` always): converges edges to the box-filtered pixel (temporal error 0.00270
        /// against 0.00449) at no FLIP cost. Not where a frame traces one pixel in N > 1: there
        /// the light gains a sample per pixel every N frames and a long mean keeps the young
        /// frames (level 160x90, 64 frames at 1/16 spp, progressive: FLIP 0.1338 with it, 0.1182
        /// at `alpha`).
        still_frames: f32 = 64.0,
            ("taa.still_frames", "taa", "", Float(0.0, 256.0, 1.0));
        /// In a still view the image shown moves from TAA's towards the plain mean of each pixel's
        /// samples where the two differ by more than this many times the mean's variance
        /// (passes/converge.rs; 0: off, and its 56 bytes per pixel are not allocated), default 2:
        /// lets a still image end at the mean of every sample (cornell_diffuse 128², relMSE after
        /// 1024 frames 1.06x the accumulation's for SVGF, 2.25x off) at no cost by frame 60
        /// (256², FLIP 0.0269, 0.0271 off); at 1 frame 60's relMSE rose to 0.00058 from 0.00046.
        converge_sigmas: f32 = 2.0,
            ("taa.converge_sigmas", "taa", "", Float(0.0, 16.0, 0.25));
        /// The still-view mean is weighed in from this many samples per pixel on (its variance is
        /// too uncertain before), default 16.
        converge_min_samples: f32 = 16.0,
            ("taa.converge_min_samples", "taa", "samples", Float(2.0, 1024.0, 1.0));
        /// Where the frame is traced below the size it is shown at (the governor's scale, `render
        /// --scale`), the temporal upscaler takes TAA's place (passes/upscale.rs): each shown pixel
        /// accumulates the jittered samples that land near it, and a still view converges to the
        /// shown resolution's detail instead of stretching the render pixels. Off: the image is
        /// stretched. 48 bytes per shown pixel while it runs.
        upscale: bool = true,
            ("taa.upscale", "taa", "", Bool);
        /// The upscaler takes the materials (albedo and emission) from a raster at the shown
        /// size, so that textures keep its detail at any scale (level SVGF frame 60 at scale
        /// 0.25, FLIP 0.1400 against 0.1777 without). The raster costs its pixels: on a GPU
        /// little, on a software rasterizer as much as sixteen render-size rasters at scale 0.25
        /// (the viewer turns it off there).
        upscale_materials: bool = true,
            ("taa.upscale_materials", "taa", "", Bool);
        /// The upscaler's kernel: a Gaussian of this standard deviation in shown pixels, default
        /// 0.4. Narrower is sharper and needs more frames to fill every pixel: SVGF's frame 60
        /// at scale 0.5 (160x90 level, 160x160 cornell_mirror) FLIP 0.1036 / 0.1015 at 0.3,
        /// 0.1030 at 0.4, 0.1050 / 0.1055 at 0.5.
        upscale_sigma: f32 = 0.4,
            ("taa.upscale_sigma", "taa", "px", Float(0.2, 2.0, 0.05));
        /// While anything moves, the upscaler's history keeps at most this many frames' worth of
        /// samples, default 10 (TAA's `alpha` 0.1): more is smoother and lags more.
        upscale_moving_frames: f32 = 10.0,
            ("taa.upscale_moving_frames", "taa", "frames", Float(1.0, 64.0, 1.0));
    }
    hidden {
    }
}

impl TaaSettings {
    /// Its `--disable` name.
    pub const STAGE: &str = "taa";
}
