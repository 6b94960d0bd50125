//! What the display shows: the image, or any labelled texture of the frame through a small
//! mapping (shaders/realtime/display.wgsl). A stage offers a debug view by naming one of its
//! textures and a [`super::ViewMap`]: no WGSL and no enum variant per view.

use super::registry::all_views;
use super::view_spec::ViewSpec;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

/// A debug view's name (`gbuffer/normal`, `matte/confidence`, ...), or `final`: the image.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct View(Cow<'static, str>);

impl View {
    pub const FINAL: View = View(Cow::Borrowed("final"));

    pub fn named(name: &str) -> View {
        View(Cow::Owned(name.to_string()))
    }

    pub fn name(&self) -> &str {
        &self.0
    }

    pub fn is_final(&self) -> bool {
        *self == View::FINAL
    }

    /// The view of this name among the built-in and registered ones.
    pub fn spec(&self) -> Option<ViewSpec> {
        all_views().into_iter().find(|v| v.name == self.name())
    }
}

impl Default for View {
    fn default() -> Self {
        View::FINAL
    }
}

impl<'de> Deserialize<'de> for View {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        if name != View::FINAL.name() && !all_views().iter().any(|v| v.name == name) {
            return Err(serde::de::Error::custom(format!("no view {name:?}")));
        }
        Ok(View::named(&name))
    }
}
