//! Denoisers: what runs between the trace and the composite, behind one contract.
//!
//! The frame (Mara et al. 2017, Figure 2) is gbuffer -> trace -> denoise -> composite -> TAA ->
//! display. A [`Denoiser`] reads the frame's I/O ([`FrameIo`]: the frame uniform, this and the
//! previous frame's G-buffer, the trace's signals), allocates its own per-pixel textures in the
//! frame's labelled memory (so they are read back and reported by label), records its passes,
//! and returns the denoised matte and glossy light the composite remodulates, plus what TAA may
//! follow. TAA and the composite belong to the frame and run after any denoiser.
//!
//! Adding a denoiser: one module implementing [`Denoiser`] (its WGSL in `shaders/`, or given to
//! [`crate::shader::ShaderLibrary::add`]) and one [`Entry`] (in [`BUILT_IN`], or passed to
//! [`register`]). Its name then works in `--denoiser`, presets and the viewer.

pub mod mara;
pub mod progressive;
pub mod svgf;

pub use crate::gpu::{BindKey, Bindings, Gpu, GpuMemory, Parity, PingPong, Recorder, Tex};
pub use crate::passes::chain::{ChainStage, made};
pub use crate::passes::io::{FrameIo, PreviousGBuffer};
pub use crate::passes::matte::ChainView;
pub use crate::passes::taa::{GlossyFollow, TaaFollow};
use crate::settings::{FrameSettings, ViewSpec};
use anyhow::{Result, bail};
use std::sync::RwLock;

/// What a denoiser knows about the scene when it is made.
#[derive(Clone, Copy, Debug)]
pub struct DenoiserScene {
    /// The scene has a specular lobe: the trace writes glossy light and reflection data.
    pub glossy: bool,
    /// Objects move: `prev_from_current` is bound and motion vectors include object motion.
    pub animated: bool,
    /// The scene's bounding-box diagonal (metres).
    pub extent: f32,
}

/// This frame beyond its I/O.
pub struct FrameContext<'a> {
    /// Frames rendered so far (wraps).
    pub index: u32,
    /// Which way round the histories ([`PingPong`]) are this frame: the parity of `index`.
    pub parity: Parity,
    /// Cameras of this frame and the last, the jitter between them, history validity.
    pub view: ChainView,
    pub settings: &'a FrameSettings,
    /// Changes whenever a resource the frame offers may have been replaced (resize, a scene
    /// buffer reallocated): bind groups keyed on it stay valid while it stays.
    pub key: crate::gpu::BindKey,
}

/// The denoised light for the composite (None: the trace's raw light passes through).
#[derive(Clone, Copy, Default)]
pub struct Denoised<'a> {
    pub matte: Option<&'a wgpu::TextureView>,
    pub glossy: Option<&'a wgpu::TextureView>,
    /// The direct light (None: the trace's, which needs no denoising at one sample per pixel).
    pub direct: Option<&'a wgpu::TextureView>,
}

pub trait Denoiser {
    /// Whether it reads the previous frame's depth, normal and object ids (`prev_depth`,
    /// `prev_normal`, `prev_object`); the frame then keeps them (16 bytes per pixel).
    fn needs_previous_gbuffer(&self) -> bool;

    /// Make its per-pixel textures in `memory` (labelled `name/...`), for frame targets of
    /// `size`; called again after a resize.
    fn allocate(&mut self, gpu: &Gpu, memory: &mut GpuMemory, size: (u32, u32));

    /// Record its passes for this frame.
    fn record(&mut self, rec: &mut Recorder, io: &FrameIo, cx: &FrameContext) -> Result<()>;

    /// The light it produced this frame (after [`Denoiser::record`]).
    fn output(&self, parity: Parity) -> Denoised<'_>;

    /// Whether it takes frames where only some pixels were traced (a sample fraction below 1,
    /// [`crate::settings::SampleFraction`]; `scheduled_pixel` in shaders/realtime/frame.wgsl
    /// says which). The default, false: the frame refuses fractions below 1 with it.
    fn fills_untraced_pixels(&self) -> bool {
        false
    }

    /// What TAA may follow (the default, nothing: TAA averages the composite alone).
    fn taa_follow(&self, _parity: Parity) -> TaaFollow<'_> {
        TaaFollow::default()
    }

    /// Its pipelines, for hot reload.
    fn pipelines(&mut self) -> Vec<&mut dyn crate::shader::Reload>;
}

/// Makes a denoiser for a scene.
pub type MakeDenoiser = fn(&Gpu, &DenoiserScene) -> Result<Box<dyn Denoiser>>;

/// A denoiser the frame can be asked for by name.
#[derive(Clone, Copy)]
pub struct Entry {
    /// As `--denoiser`, presets and the viewer spell it (lower case).
    pub name: &'static str,
    /// One line for the viewer and `--help`.
    pub summary: &'static str,
    /// Make it for a scene (None: no denoiser, the raw frame).
    pub make: Option<MakeDenoiser>,
    /// Its debug views: textures it allocates, by label, and how to show them.
    pub views: &'static [ViewSpec],
    /// It takes sample fractions below 1 (as [`Denoiser::fills_untraced_pixels`] says once made;
    /// here so that an error can name the denoisers that do without making them).
    pub fractions: bool,
}

/// The denoisers built into Hush.
pub const BUILT_IN: &[Entry] = &[
    Entry {
        name: "none",
        summary: "the raw 1-sample frame (composite only)",
        make: None,
        views: &[],
        fractions: true,
    },
    Entry {
        name: "mara",
        summary: "Mara et al. 2017: the matte and glossy chains, then TAA",
        make: Some(mara::make),
        views: crate::settings::MARA_VIEWS,
        fractions: false,
    },
    Entry {
        name: "svgf",
        summary: "SVGF (Schied et al. 2017) with Voorhuis's reflections and robustness, then TAA",
        make: Some(svgf::make),
        views: crate::settings::SVGF_VIEWS,
        fractions: false,
    },
    Entry {
        name: "progressive",
        summary: "Dundr et al.'s progressive SVGF, for sample fractions below 1 (--spp 1/N), then TAA",
        make: Some(progressive::make),
        views: crate::settings::PROGRESSIVE_VIEWS,
        fractions: true,
    },
];

static REGISTERED: RwLock<Vec<Entry>> = RwLock::new(Vec::new());

/// Add a denoiser beside the built-in ones (an application's or a test's own); an error if the
/// name is taken.
pub fn register(entry: Entry) -> Result<()> {
    let mut r = crate::sync::write(&REGISTERED);
    if entries_in(&r).iter().any(|e| e.name == entry.name) {
        bail!("a denoiser named {:?} is already registered", entry.name);
    }
    r.push(entry);
    crate::settings::add_denoiser_name(entry.name);
    crate::settings::register_views(entry.views);
    Ok(())
}

fn entries_in(registered: &[Entry]) -> Vec<Entry> {
    BUILT_IN.iter().chain(registered).copied().collect()
}

/// Every denoiser, built-in first.
pub fn entries() -> Vec<Entry> {
    entries_in(&crate::sync::read(&REGISTERED))
}

/// The denoiser called `name`.
pub fn find(name: &str) -> Result<Entry> {
    let all = entries();
    match all.iter().find(|e| e.name == name) {
        Some(e) => Ok(*e),
        None => bail!(
            "no denoiser {name:?} (there are {})",
            all.iter().map(|e| e.name).collect::<Vec<_>>().join(", ")
        ),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn settings_know_every_built_in_name() {
        let names: Vec<&str> = super::BUILT_IN.iter().map(|e| e.name).collect();
        assert_eq!(crate::settings::denoiser_names()[..names.len()], names[..]);
    }
}
