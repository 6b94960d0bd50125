//! Denoisers: what runs between the trace and the composite, behind one contract.
//!
//! The frame (Mara et al. 2017, Figure 2) is gbuffer -> trace -> denoise -> composite -> TAA ->
//! display. A [`Denoiser`] reads the frame's I/O ([`FrameIo`]: the frame uniform, this and the
//! previous frame's G-buffer, the trace's signals), allocates its own per-pixel textures in the
//! frame's labelled memory (so they are read back and reported by label), and records its
//! passes, returning from that call the denoised matte and glossy light the composite
//! remodulates, plus what TAA may follow ([`Outputs`]). TAA and the composite belong to the frame and run after any denoiser.
//!
//! Adding a denoiser: one module implementing [`Denoiser`] (its WGSL in `shaders/`, or given to
//! [`crate::shader::ShaderLibrary::add`]) and one [`Entry`]: what it declares
//! ([`DenoiserInfo`]: name, settings fields and preset section, `--disable` stages, debug views)
//! and its maker. A built-in one declares itself in `settings/<name>.rs` and adds its maker to
//! one line here; an application passes its entry to [`register`]. Its name then works in
//! `--denoiser`, presets, the viewer's panels and the quality tools. Every type a denoiser uses
//! is here or re-exported here.

pub mod mara;
pub mod progressive;
pub mod svgf;

pub use crate::gpu::{BindKey, Bindings, Gpu, GpuMemory, Parity, PingPong, Recorder, Tex};
pub use crate::passes::chain::{ChainStage, made};
pub use crate::passes::io::ChainView;
pub use crate::passes::io::{FrameIo, PreviousGBuffer};
pub use crate::passes::taa::{GlossyFollow, MatteFollow, MatteState, TaaFollow};
pub use crate::settings::FrameSettings;
pub use crate::settings::{
    DenoiserInfo, Field, Kind, Off, Section, Stage, ViewMap, ViewSpec, disable_stage, fields,
    stage_names,
};
use anyhow::Result;

/// What a denoiser knows about the scene when it is made.
#[derive(Clone, Copy, Debug)]
pub struct DenoiserScene {
    /// The scene has a specular lobe: the trace writes glossy light and reflection data.
    pub glossy: bool,
    /// How points move: which motion module the stages that reproject are made with.
    pub motion: crate::gpu::Motion,
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
    pub key: BindKey,
}

/// The denoised light for the composite (None: the trace's raw light passes through).
#[derive(Clone, Copy, Default)]
pub struct Denoised<'a> {
    pub matte: Option<&'a wgpu::TextureView>,
    pub glossy: Option<&'a wgpu::TextureView>,
    /// The direct light (None: the trace's, which needs no denoising at one sample per pixel).
    pub direct: Option<&'a wgpu::TextureView>,
}

/// What a denoiser made this frame, for the stages after it, at each history parity (they make
/// their bind groups for both at once): the light the composite remodulates, and what TAA may
/// follow (nothing: TAA averages the composite alone).
#[derive(Clone, Copy, Default)]
pub struct Outputs<'a> {
    pub light: [Denoised<'a>; 2],
    pub follow: [TaaFollow<'a>; 2],
}

impl<'a> Outputs<'a> {
    /// The same light and the same TAA follow at either parity.
    pub fn same(light: Denoised<'a>, follow: TaaFollow<'a>) -> Outputs<'a> {
        Outputs { light: [light; 2], follow: [follow; 2] }
    }

    /// The light and what TAA follows at parity `p`.
    pub fn at(&self, p: Parity) -> (Denoised<'a>, TaaFollow<'a>) {
        (self.light[p.index()], self.follow[p.index()])
    }
}

pub trait Denoiser {
    /// Whether it reads the previous frame's depth, normal and object ids (`prev_depth`,
    /// `prev_normal`, `prev_object`); the frame then keeps them (16 bytes per pixel).
    fn needs_previous_gbuffer(&self) -> bool;

    /// Whether its stages read the glossy path's reflection data (`tr_reflection`, `tr_mirror`,
    /// `tr_mirror_hit`: the virtual position, the mirror direction and what the glossy path hit,
    /// Voorhuis §4), or offer TAA a glossy light to follow (TAA demodulates it with them). The
    /// frame writes and keeps them (28 bytes a pixel) only while such a denoiser runs; the
    /// default, false, leaves them out, and a program that binds them then fails to make.
    fn reads_reflections(&self) -> bool {
        false
    }

    /// Make its per-pixel textures in `memory` (labelled `name/...`), for frame targets of
    /// `size` and frames with `settings`. `kept`: the frame reads the textures whose labels
    /// start with one of these after the denoiser, besides its outputs (a debug view, a test's
    /// readback), so they must then hold what this frame wrote; a denoiser whose intermediates
    /// share memory ([`crate::gpu::graph`]) keeps them apart. Called again after a resize, when
    /// `kept` or [`Denoiser::layout`] changes, and when the denoiser is chosen again after
    /// another (the frame forgets an inactive denoiser's textures: [`Denoiser::release`]).
    fn allocate(
        &mut self,
        gpu: &Gpu,
        memory: &mut GpuMemory,
        size: (u32, u32),
        kept: &[String],
        settings: &FrameSettings,
    ) -> Result<()>;

    /// What of `settings` its textures' placement depends on (the progressive filter's level
    /// count decides which of its textures the composite reads): the frame allocates again when
    /// it changes. The default, 0: nothing.
    fn layout(&self, _settings: &FrameSettings) -> u64 {
        0
    }

    /// Drop its per-pixel textures: another denoiser runs now, and only the active one holds
    /// memory. Its pipelines stay, for a switch back.
    fn release(&mut self);

    /// Record its passes for this frame, and return what it made: the light the composite
    /// remodulates and what TAA may follow.
    fn record<'s>(
        &'s mut self,
        rec: &mut Recorder,
        io: &FrameIo,
        cx: &FrameContext,
    ) -> Result<Outputs<'s>>;

    /// Whether it takes frames where only some pixels were traced (a sample fraction below 1,
    /// [`crate::settings::SampleFraction`]; `scheduled_pixel` in shaders/realtime/frame.wgsl
    /// says which). The default, false: the frame refuses fractions below 1 with it.
    fn fills_untraced_pixels(&self) -> bool {
        false
    }

    /// Its pipelines, for hot reload.
    fn pipelines(&mut self) -> Vec<&mut dyn crate::shader::Reload>;
}

/// Makes a denoiser for a scene.
pub type MakeDenoiser = fn(&Gpu, &DenoiserScene) -> Result<Box<dyn Denoiser>>;

/// A denoiser the frame can be asked for by name: what it declares (name, summary, settings
/// fields and preset section, `--disable` stages, debug views) and how to make it.
#[derive(Clone, Copy)]
pub struct Entry {
    pub info: DenoiserInfo,
    /// Make it for a scene (None: no denoiser, the raw frame).
    pub make: Option<MakeDenoiser>,
}

/// How each built-in denoiser is made (what it declares is in `settings/<name>.rs`).
const BUILT_IN_MAKERS: &[(&str, MakeDenoiser)] = &[
    (crate::settings::mara::INFO.name, mara::make),
    (crate::settings::svgf::INFO.name, svgf::make),
    (crate::settings::progressive::INFO.name, progressive::make),
];

/// The makers of the denoisers an application registered.
static REGISTERED_MAKERS: std::sync::RwLock<Vec<(&'static str, MakeDenoiser)>> =
    std::sync::RwLock::new(Vec::new());

/// Add a denoiser beside the built-in ones (an application's or a test's own): its name then
/// works in `--denoiser`, presets and the viewer, its settings in presets, panels and
/// `--disable`. An error if its name, a view, a stage or its settings section is taken.
pub fn register(entry: Entry) -> Result<()> {
    let taken = FrameSettings::typed_sections();
    // The maker first, so that no frame finds the name without it.
    let mut makers = crate::sync::write(&REGISTERED_MAKERS);
    crate::settings::registry::register(entry.info, &taken)?;
    if let Some(make) = entry.make {
        makers.push((entry.info.name, make));
    }
    Ok(())
}

/// Every denoiser, built-in first.
pub fn entries() -> Vec<Entry> {
    crate::settings::registry::denoisers().into_iter().map(entry).collect()
}

/// The denoiser called `name`.
pub fn find(name: &str) -> Result<Entry> {
    crate::settings::registry::denoiser(name).map(entry)
}

fn entry(info: DenoiserInfo) -> Entry {
    let registered = crate::sync::read(&REGISTERED_MAKERS);
    let mut makers = BUILT_IN_MAKERS.iter().chain(registered.iter());
    Entry { info, make: makers.find(|(n, _)| *n == info.name).map(|(_, m)| *m) }
}

#[cfg(test)]
mod tests {
    /// Every built-in denoiser but `none` can be made.
    #[test]
    fn every_built_in_denoiser_has_a_maker() {
        for info in crate::settings::registry::BUILT_IN {
            let made = super::find(info.name).map(|e| e.make.is_some());
            assert_eq!(made.ok(), Some(info.name != crate::settings::registry::NONE.name));
        }
    }
}
