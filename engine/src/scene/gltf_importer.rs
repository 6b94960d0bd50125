//! The state of one glTF import: the scene's files, the warnings so far, the load budget and
//! the triangles placed; `gltf_import` drives it, `gltf_mesh` and `gltf_material` read through it.

use super::files::SceneFiles;
use crate::limits::Budget;
use std::collections::HashMap;

/// Where each (glTF texture, sRGB) pair went in the scene's texture list.
pub(super) type TextureSlots = HashMap<(usize, bool), u32>;

pub(super) struct Importer<'a> {
    pub(super) files: &'a dyn SceneFiles,
    pub(super) warnings: Vec<String>,
    pub(super) max_texture_size: u32,
    pub(super) budget: Budget,
    /// Triangles placed so far (instances counted), against `Limits::triangles`.
    pub(super) triangles: u64,
    /// The one animation that plays (`LoadOptions::animation`); None: all of them.
    pub(super) animation: Option<usize>,
}

impl Importer<'_> {
    /// A problem a viewer can live with: logged and kept in the scene's warnings.
    pub(super) fn warn(&mut self, msg: String) {
        log::warn!("{msg}");
        self.warnings.push(msg);
    }
}
