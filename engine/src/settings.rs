//! Tunables with their units and defaults. The foundation's only settings concern the reference
//! tracer; the real-time passes add theirs here.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Settings {
    /// Reference tracer: samples per pixel accumulated by `hush-cli render` (samples).
    pub spp: u32,
    /// Random seed; the same seed, scene and view give the same image on the same adapter.
    pub seed: u32,
    /// Largest texture side kept on load (texels); larger textures are halved until they fit.
    pub max_texture_size: u32,
}

impl Default for Settings {
    fn default() -> Self {
        Settings { spp: 64, seed: 0, max_texture_size: crate::scene::DEFAULT_MAX_TEXTURE_SIZE }
    }
}
