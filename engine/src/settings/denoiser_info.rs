//! What a denoiser declares to the registry ([`super::registry`]): its name and summary, its
//! settings' fields and preset section, its `--disable` stages and its debug views.

use super::field::Field;
use super::view_spec::ViewSpec;
use serde_json::Value;

/// A stage a user may switch off by name (`--disable NAME`, the quality tool's ablations): the
/// setting that turns it off, and the value that does.
#[derive(Clone, Copy, Debug)]
pub struct Stage {
    pub name: &'static str,
    /// Dotted path of the setting (`svgf.temporal`, `accumulate.clamp`).
    pub path: &'static str,
    pub off: Off,
}

/// What a stage's setting is set to when the stage is switched off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Off {
    False,
    Zero,
}

impl Stage {
    /// A stage `name` (`chain/stage`: its passes' label, settings group and WGSL file stem)
    /// switched off by setting the boolean at `path` to false.
    pub const fn named(name: &'static str, path: &'static str) -> Stage {
        Stage { name, path, off: Off::False }
    }

    /// A switch that covers several stages or a part of one, named by its setting's `path`
    /// and switched off by setting it to false.
    pub const fn switch(path: &'static str) -> Stage {
        Stage { name: path, path, off: Off::False }
    }
}

/// The preset section of a denoiser whose settings are not a field of
/// [`super::FrameSettings`] (an application's): `[name]` in TOML, `name.*` in field paths, held
/// in [`super::FrameSettings::sections`].
#[derive(Clone, Copy, Debug)]
pub struct Section {
    pub name: &'static str,
    /// The section's default values, as a JSON object (every field the section has).
    pub defaults: fn() -> Value,
}

/// Everything a denoiser declares, except how it is made.
#[derive(Clone, Copy, Debug)]
pub struct DenoiserInfo {
    /// As `--denoiser`, presets and the viewer spell it (lower case).
    pub name: &'static str,
    /// One line for the viewer and `--help`.
    pub summary: &'static str,
    /// Its settings' descriptions, in panel order (slices of [`Field`], one per technique).
    pub fields: &'static [&'static [Field]],
    /// Its own preset section, for settings that are not a field of `FrameSettings`.
    pub section: Option<Section>,
    /// What `--disable` may switch off.
    pub stages: &'static [Stage],
    /// Its debug views: textures it allocates, by label, and how to show them.
    pub views: &'static [ViewSpec],
    /// It takes sample fractions below 1 (it fills the pixels a frame did not trace).
    pub fractions: bool,
    /// Dotted path of its setting that counts the a-trous levels of its spatial filter, which
    /// the frame-time governor may turn down where nothing else fits (`crate::governor`).
    pub levels: Option<&'static str>,
}
