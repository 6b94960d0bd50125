//! The radiance cache's settings (passes/cache.rs, shaders/cache/*.wgsl): a world-space hashed
//! cache of the matte light on surfaces, a stage of the frame between the trace and the
//! denoiser, which a denoiser's temporal stage reads where a pixel's history restarts. The
//! measurements behind each default are in `docs/decisions.md`.

use super::field::{Kind::*, described};
use serde::{Deserialize, Serialize};

/// The most cells the table may hold (2^22: 304 MiB at 76 bytes a cell).
pub const MAX_CELLS_LOG2: u32 = 22;

described! {
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(default)]
    pub struct CacheSettings / FIELDS {
        /// Keep the cache and give a pixel whose matte history restarts (uncovered by a move)
        /// its cell's mean as a prior worth up to `prior_frames` frames (Mara's and SVGF's
        /// temporal stages). Off (the default): no passes, no memory, a restarted pixel starts
        /// from its one sample. The level at 320x180, the 10 frames after a 2 m jump, FLIP of the
        /// uncovered pixels: Mara 0.1514 off, 0.1388 on; SVGF 0.1480 off, 0.1487 on. Costs 80 of
        /// 2181 ms a still frame at 640x360 on lavapipe (3.7%), and a shadow ray per uncovered
        /// pixel.
        enabled: bool = false,
            ("cache.enabled", "cache", "", Bool);
        /// A cell's edge in pixels at its distance from the camera (rounded up to a power of two
        /// in scene units): larger cells fill faster and blur the light more.
        cell_pixels: f32 = 8.0,
            ("cache.cell_pixels", "cache", "pixels", Float(1.0, 32.0, 0.5));
        /// The most frames' worth of samples a prior stands for (a cell with fewer samples gives
        /// fewer): the weight of the cell's blur against the pixel's own samples. 4: the jump
        /// of `enabled` 0.1388 (Mara) and 0.1487 (SVGF); 16: 0.1398 and 0.1555 (SVGF then takes
        /// the cell's blocks for converged light and stops filtering them).
        prior_frames: f32 = 4.0,
            ("cache.prior_frames", "cache", "frames", Float(0.0, 256.0, 1.0));
        /// One secondary sample per tile of this many pixels squared per frame: from the tile's
        /// surface to the one it sees, whose cell it fills (0: the cache takes only what the
        /// camera sees). Costs a ray, a shadow ray and a matte path per tile.
        update_tile: u32 = 4,
            ("cache.update_tile", "cache", "pixels", Int(0, 64));
        /// The most samples a cell's running mean holds; past it new samples weigh 1 / this.
        max_samples: f32 = 1024.0,
            ("cache.max_samples", "cache", "samples", Float(1.0, 65536.0, 16.0));
        /// Frames a cell without a sample is kept before its slot is freed.
        max_age_frames: u32 = 64,
            ("cache.max_age_frames", "cache", "frames", Int(1, 100000));
        /// With an unlimited path length (`max_depth` -1) a matte path ends at a vertex with the
        /// light of the vertex's cell, where the cell holds at least this many samples and the
        /// segment that reached the vertex is longer than the cell's diagonal (0: paths never
        /// end in the cache). The bounces after it then come from the cells, which fill over
        /// frames: less noise for the blur of a cell and the lag of its mean. A white room's
        /// matte light at 64x48: variance 0.46x, mean -0.7%; the level's, living room's and
        /// staircase's still FLIP at 160 wide: -3.8% / -1.1% / -0.8% (SVGF), -4.3% / -0.8% /
        /// -1.1% (Mara); the trace cost 9-10% more on lavapipe and 6-10% more on an H200 at
        /// 1280x720, measured before the segment test (docs/decisions.md).
        path_end_samples: f32 = 16.0,
            ("cache.path_end_samples", "cache", "samples", Float(0.0, 65536.0, 1.0));
        /// A path ends in a cell only where the cell's mean is known to within this relative
        /// standard error (its samples' spread over their count): a firefly among a cell's
        /// first samples would brighten every path that ends there, in every frame, a blob no
        /// denoiser removes. Lower waits longer for a cell: at 0.02 the level's matte light
        /// (160x90, 30 frames, 8 pixels read) came out as with no path ends.
        path_end_error: f32 = 0.1,
            ("cache.path_end_error", "cache", "", Float(0.0, 100.0, 0.01));
        /// Cells in the table, as a power of two (16: 65536 cells, 4.75 MiB at 76 bytes a cell).
        cells_log2: u32 = 16,
            ("cache.cells_log2", "cache", "", Int(10, MAX_CELLS_LOG2 as i64));
    }
    hidden {
    }
}
