//! The frame's reprojection test (Mara et al. 2017 eq. (11)): what every denoiser's temporal
//! stages and TAA use to decide whether the previous frame's texel shows the surface a pixel
//! shows now. The frame owns it (shaders/realtime/frame.wgsl: `d0_px`, `d1_px`), so that one
//! setting steers every history alike; each denoiser's own normal test stays in its group.

use super::field::{Kind::*, described};
use serde::{Deserialize, Serialize};

described! {
    /// Eq. (11)'s reprojection distances, shared by every temporal stage.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(default)]
    pub struct ReprojectionSettings / FIELDS {
        /// Eq. (11)'s d0 in pixel footprints at the surface: full confidence in a previous texel
        /// within it (the paper's 5 cm and 7 cm are about 6 and 8.5 footprints at 5 m in a 720p,
        /// 60-degree view; a footprint keeps the test the same at any scene scale and
        /// resolution). Mara's temporal stages fade their history between d0 and d1; every
        /// reprojection takes the texel under the motion vector as it is within d0 and searches
        /// its 3x3 neighbours beyond.
        d0_px: f32 = 6.0,
            ("reprojection.d0_px", "reprojection", "footprints", Float(0.0, 64.0, 0.05));
        /// Eq. (11)'s d1: no texel beyond it is the same surface. SVGF's, the progressive
        /// filter's and TAA's tests pass a bilinear tap within it; larger keeps histories across
        /// more of a move at the risk of smearing one surface onto the next.
        d1_px: f32 = 8.5,
            ("reprojection.d1_px", "reprojection", "footprints", Float(0.0, 64.0, 0.05));
    }
    hidden {
    }
}
