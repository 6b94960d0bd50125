//! The one registry of denoisers: what each declares (its name, summary, settings fields and
//! preset section, `--disable` stages and debug views) and how to make it. The viewer's panels,
//! presets, `--disable`, the quality tools and the frame all find a denoiser here: the built-in
//! ones (declared in `settings/<name>.rs`) and any an application registers through
//! `crate::denoise::register`.
//!
//! The registry holds what a denoiser declares; `crate::denoise` keeps how each is made, so
//! that settings, which every stage reads, depend on no stage.

pub use super::denoiser_info::{DenoiserInfo, Off, Section, Stage};
use super::taa::TaaSettings;
use super::view_spec::{FRAME_VIEWS, ViewSpec};
use anyhow::{Result, bail};
use std::sync::RwLock;

/// The raw frame: no denoiser.
pub const NONE: DenoiserInfo = DenoiserInfo {
    name: "none",
    summary: "the raw 1-sample frame (composite only)",
    fields: &[],
    section: None,
    stages: &[],
    views: &[],
    fractions: true,
    levels: None,
};

/// The denoisers built into Hush, in the order the viewer lists them.
pub const BUILT_IN: &[DenoiserInfo] =
    &[NONE, super::mara::INFO, super::svgf::INFO, super::progressive::INFO];

static REGISTERED: RwLock<Vec<DenoiserInfo>> = RwLock::new(Vec::new());

/// Every denoiser, built-in first.
pub fn denoisers() -> Vec<DenoiserInfo> {
    let registered = crate::sync::read(&REGISTERED);
    BUILT_IN.iter().chain(registered.iter()).copied().collect()
}

/// Every view: the frame's, then each denoiser's.
pub fn all_views() -> Vec<ViewSpec> {
    let denoisers = denoisers();
    FRAME_VIEWS.iter().chain(denoisers.iter().flat_map(|d| d.views)).copied().collect()
}

/// The denoiser called `name`.
pub fn denoiser(name: &str) -> Result<DenoiserInfo> {
    let all = denoisers();
    match all.iter().find(|e| e.name == name) {
        Some(e) => Ok(*e),
        None => {
            let names: Vec<&str> = all.iter().map(|e| e.name).collect();
            bail!("no denoiser {name:?} (there are {})", names.join(", "))
        }
    }
}

/// Add a denoiser beside the built-in ones; an error if its name, a view's name, a stage's
/// name or its section is taken (`taken`: the names the built-in settings use), or a field lies
/// outside its section.
pub(crate) fn register(info: DenoiserInfo, taken: &[String]) -> Result<()> {
    let mut registered = crate::sync::write(&REGISTERED);
    let all: Vec<DenoiserInfo> = BUILT_IN.iter().chain(registered.iter()).copied().collect();
    let name = info.name;
    if all.iter().any(|e| e.name == name) {
        bail!("a denoiser named {name:?} is already registered");
    }
    let views = all.iter().flat_map(|e| e.views).chain(FRAME_VIEWS);
    if let Some(v) = views.clone().find(|v| info.views.iter().any(|n| n.name == v.name)) {
        bail!("denoiser {name:?}: the view {:?} exists already", v.name);
    }
    let mut stages = all.iter().flat_map(|e| e.stages).map(|s| s.name).chain([TaaSettings::STAGE]);
    if let Some(s) = stages.find(|s| info.stages.iter().any(|n| n.name == *s)) {
        bail!("denoiser {name:?}: the stage {s:?} exists already");
    }
    let sections: Vec<&str> = all.iter().filter_map(|e| e.section.map(|s| s.name)).collect();
    match info.section {
        Some(s) if taken.iter().any(|t| t == s.name) || sections.contains(&s.name) => {
            bail!("denoiser {name:?}: the settings section {:?} is taken", s.name)
        }
        Some(s) => {
            let prefix = format!("{}.", s.name);
            let fields = info.fields.iter().flat_map(|f| f.iter());
            if let Some(f) = fields.clone().find(|f| !f.path.starts_with(&prefix)) {
                bail!("denoiser {name:?}: field {:?} is outside its section {:?}", f.path, s.name);
            }
            if !(s.defaults)().is_object() {
                bail!("denoiser {name:?}: the defaults of section {:?} are not a table", s.name);
            }
        }
        None if !info.fields.is_empty() => {
            bail!("denoiser {name:?}: settings fields need a section to hold them")
        }
        None => {}
    }
    registered.push(info);
    Ok(())
}
