//! The real-time frame, as Figure 2 of Mara et al. 2017 draws it: gbuffer (raster) -> trace ->
//! denoise (any [`crate::denoise::Denoiser`], or none) -> composite -> TAA -> display, on one
//! scene. Which passes, bindings and buffers exist follows the scene's features (no glossy
//! lobe: no glossy path and no glossy buffers; no animation: no object motion buffer and no
//! BVH rebuilds) and the denoiser chosen (its textures are made on its first frame).

mod params;
mod plan;
mod readback;
mod record;
mod reload;
mod targets;

pub use crate::accel::BvhKind;
pub use crate::settings::{Denoiser as DenoiserName, FrameSettings, View};
pub use params::{CameraSetup, FrameParams, random_jitter};

use crate::denoise::Denoiser;
use crate::gpu::{BindKey, Gpu, GpuRequirements, GpuScene, GpuTimer, Instancing, PreparedScene};
use crate::passes::cache::RadianceCache;
use crate::passes::composite::CompositePass;
use crate::passes::converge::ConvergeStage;
use crate::passes::gbuffer::{self, GBufferPass};
use crate::passes::prefilter::Prefilter;
use crate::passes::primaries::Primaries;
use crate::passes::supersample::Supersample;
use crate::passes::taa::TaaStage;
use crate::passes::trace::{SceneInputs, TraceInputs, TracePass};
use crate::passes::upscale::UpscaleStage;
use crate::scene::{Camera, Scene};
use anyhow::{Context, Result, bail};
use glam::{Vec2, Vec3};
use record::{FrameHistory, Stages};
use targets::{Targets, Uniforms};

/// Largest image side of the real-time frame.
pub const MAX_SIDE: u32 = 8192;

/// Passes that can write timestamps in one frame: SVGF with glossy light runs 10 a-trous
/// passes, the glossy search one per step, supersampling 4 more; 128 queries cost 1 KiB.
const TIMED_PASSES: u32 = 64;

/// Where the camera is and what time it is in the scene's animation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameInput {
    pub camera: Camera,
    /// Seconds into the scene's animation.
    pub time: f64,
    /// Motion blur: where the shutter opened (`camera` and `time` are where it closes). Each
    /// primary sample then sees the scene at a uniformly random time in between: the camera
    /// blended linearly between the two, objects moving linearly from their open to their
    /// close transforms (shaders/common/motion_blur.wgsl). None: an instant exposure.
    pub shutter: Option<ShutterOpen>,
}

/// The camera and the scene time at the shutter's open.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShutterOpen {
    pub camera: Camera,
    pub time: f64,
}

impl FrameInput {
    /// The exposure over `shutter` of the frame interval `frame_dt` (seconds) ending at `time`,
    /// the camera at the open given by `camera_at` (a camera path's interpolation; the same
    /// camera for a still one). `shutter` = 0: an instant exposure.
    pub fn exposed(
        camera_at: impl Fn(f64) -> Camera,
        time: f64,
        shutter: f64,
        frame_dt: f64,
    ) -> FrameInput {
        let open = time - shutter.clamp(0.0, 1.0) * frame_dt.max(0.0);
        let shutter = (open < time).then(|| ShutterOpen { camera: camera_at(open), time: open });
        FrameInput { camera: camera_at(time), time, shutter }
    }
}

/// Where the display pass draws: a surface texture or an offscreen image of any size (the frame
/// is scaled to cover it).
pub struct DisplayTarget<'a> {
    pub view: &'a wgpu::TextureView,
    pub format: wgpu::TextureFormat,
    pub size: (u32, u32),
}

/// A denoiser the frame made, with the targets epoch it allocated its textures for (None: it
/// holds none), the labels it was asked to keep readable and what it allocated.
struct MadeDenoiser {
    name: String,
    epoch: Option<u64>,
    kept: Vec<String>,
    /// [`Denoiser::layout`] of the settings it was allocated for.
    layout: u64,
    labels: Vec<String>,
    denoiser: Box<dyn Denoiser>,
}

pub struct Renderer {
    pub scene: Scene,
    pub prepared: PreparedScene,
    pub gpu_scene: GpuScene,
    targets: Targets,
    uniforms: Uniforms,
    stages: Stages,
    /// Every denoiser chosen so far (switching back keeps its pipelines; only the one that ran
    /// last holds textures).
    denoisers: Vec<MadeDenoiser>,
    /// Labels the frame keeps readable after every frame ([`Renderer::keep`]).
    kept: Vec<String>,
    history: FrameHistory,
    timer: Option<GpuTimer>,
    /// Pass times are picked up by [`Renderer::poll_pass_spans`] frames later, not read back.
    async_timings: bool,
    /// Deforming meshes posed on the GPU (None: the scene has none, or they are posed on the
    /// CPU).
    posing: Option<crate::gpu::posing::GpuPosing>,
    /// The targets of the last size rendered, after a resize and until the next frame
    /// resamples their histories into the new ones (passes/rescale.rs).
    rescale_from: Option<Targets>,
    /// What the last resampling carried across a change of size.
    last_rescale: crate::passes::rescale::Rescaled,
    /// The size the frame is shown at ([`Renderer::show_at`]).
    shown_size: Option<(u32, u32)>,
}

impl PreparedScene {
    /// Features and limits of the real-time frame on this scene.
    pub fn realtime_requirements(&self, size: (u32, u32)) -> GpuRequirements {
        let mut r = self.requirements(size.0 as u64 * size.1 as u64, 16);
        // The supersampling's samples pass binds the trace's buffers and two of its own, the
        // radiance cache's update five.
        r.max_storage_buffers_per_shader_stage += 5;
        r.max_color_attachment_bytes_per_sample = gbuffer::COLOR_BYTES_PER_SAMPLE;
        // matte, direct, and with a glossy lobe glossy, reflection, mirror and mirror hit; the
        // pre-filter's covariance step writes 4 (WebGPU's default).
        r.max_storage_textures_per_shader_stage = if self.features.glossy { 6 } else { 4 };
        // TAA reads the most: the G-buffer (7), the trace's outputs (2, +4 glossy), its four
        // histories and the denoiser's light it follows (2, +3 glossy): 22 in a glossy scene
        // (WebGPU's default is 16; desktop Vulkan, Metal and D3D12 adapters offer far more).
        // The trace reads the scene's tables beside the G-buffer (9), its own inputs (5), the
        // glossy inputs (4) and the radiance cache's prior (1): a scene of many tables needs
        // more than TAA.
        let taa = if self.features.glossy { 22 } else { 15 };
        let trace = self.sampled_texture_count() + 19;
        r.max_sampled_textures_per_shader_stage =
            r.max_sampled_textures_per_shader_stage.max(taa).max(trace);
        r
    }
}

fn check_size((w, h): (u32, u32)) -> Result<()> {
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        bail!("frame size {w}x{h} is out of range (1..={MAX_SIDE} per side)");
    }
    Ok(())
}

impl Renderer {
    /// Prepare `scene`, open a headless device that fits it, and build the frame.
    pub fn headless(scene: Scene, kind: BvhKind, size: (u32, u32)) -> Result<(Gpu, Renderer)> {
        Self::headless_with(scene, kind, Instancing::Auto, size)
    }

    /// [`Renderer::headless`], storing shared meshes once as `instancing` says.
    pub fn headless_with(
        scene: Scene,
        kind: BvhKind,
        instancing: Instancing,
        size: (u32, u32),
    ) -> Result<(Gpu, Renderer)> {
        check_size(size)?;
        let prepared = PreparedScene::with_instancing(&scene, kind, instancing)
            .with_context(|| format!("preparing scene {:?}", scene.name))?;
        let gpu = Gpu::headless(&prepared.realtime_requirements(size))?;
        let r = Renderer::new(&gpu, scene, prepared, size)?;
        Ok((gpu, r))
    }

    pub fn new(
        gpu: &Gpu,
        scene: Scene,
        prepared: PreparedScene,
        size: (u32, u32),
    ) -> Result<Renderer> {
        check_size(size)?;
        gpu.check_realtime_formats()?;
        gpu.validated("creating the real-time frame", || Self::create(gpu, scene, prepared, size))
    }

    fn create(
        gpu: &Gpu,
        scene: Scene,
        prepared: PreparedScene,
        size: (u32, u32),
    ) -> Result<Renderer> {
        let gpu_scene = prepared.upload(gpu);
        let targets = Targets::new(gpu, size, prepared.features.glossy, 0, 0);
        let mut uniforms = Uniforms::new(gpu);
        let u = &uniforms;
        let gbuffer =
            GBufferPass::new(gpu, &gpu_scene, &u.frame).context("creating the G-buffer pass")?;
        let moving = prepared.shutter_moves();
        let scene_in =
            SceneInputs { scene: &gpu_scene, params: &u.params, frame: &u.frame, moving };
        let trace_in = TraceInputs {
            scene: scene_in,
            g: &targets.gbuffer,
            t: &targets.trace,
            cache: None,
            previous_depth: None,
        };
        let trace = TracePass::new(gpu, &trace_in).context("creating the trace pass")?;
        let io = targets.io(&u.frame, &gpu_scene);
        let composite = CompositePass::new(gpu, &u.shown(&targets, &io, None))
            .context("creating the composite pass")?;
        let taa = TaaStage::new(gpu, &mut uniforms.memory, prepared.features.motion());
        let converge = ConvergeStage::new(gpu, &mut uniforms.memory);
        let upscale = UpscaleStage::new(gpu, &mut uniforms.memory, prepared.features.motion());
        let stages = Stages {
            gbuffer,
            trace,
            composite,
            display: None,
            taa,
            converge,
            upscale,
            supersample: Supersample::new(),
            primaries: Primaries::default(),
            prefilter: Prefilter::default(),
            cache: RadianceCache::default(),
            rescale: Default::default(),
        };
        let mut r = Renderer {
            scene,
            prepared,
            gpu_scene,
            targets,
            uniforms,
            stages,
            denoisers: vec![],
            kept: vec![],
            history: FrameHistory::default(),
            timer: GpuTimer::new(gpu, TIMED_PASSES),
            async_timings: false,
            posing: None,
            rescale_from: None,
            last_rescale: Default::default(),
            shown_size: None,
        };
        r.set_gpu_posing(gpu, true)?;
        log::info!("{}", r.report());
        Ok(r)
    }

    /// Pose deforming meshes and refit their tree on the GPU (`on`, the default where the scene
    /// allows it: [`crate::gpu::PreparedScene::posing_supported`]) or on the CPU, which
    /// flattens them and uploads their triangles every frame.
    pub fn set_gpu_posing(&mut self, gpu: &Gpu, on: bool) -> Result<()> {
        self.posing = if on {
            crate::gpu::posing::GpuPosing::new(gpu, &self.prepared)
                .context("creating the GPU posing passes")?
        } else {
            None
        };
        self.prepared.gpu_posing = self.posing.is_some();
        Ok(())
    }

    /// The GPU posing passes, where deforming meshes are posed on the GPU.
    pub fn gpu_posing(&self) -> Option<&crate::gpu::posing::GpuPosing> {
        self.posing.as_ref()
    }

    /// What the frame enabled and allocated, for logs and the viewer.
    pub fn report(&self) -> String {
        let f = &self.prepared.features;
        let (w, h) = self.targets.size;
        let per_pixel = self.bytes_per_pixel();
        let buffers = self
            .targets
            .memory
            .allocations
            .iter()
            .map(|(l, b)| format!("{l}={b}"))
            .collect::<Vec<_>>()
            .join(" ");
        format!(
            "real-time frame {w}x{h}: passes gbuffer, trace ({}), composite, display; animated: {}; scene {} bytes, per-pixel targets {} bytes ({per_pixel:.0} B/pixel): {buffers}",
            if f.glossy { "matte + glossy" } else { "matte only" },
            f.animated,
            self.gpu_scene.memory.total_bytes(),
            self.targets.memory.total_bytes(),
        )
    }

    /// Move the sun (the first directional light); false if the scene has none.
    pub fn set_sun_direction(&mut self, gpu: &Gpu, dir: Vec3) -> bool {
        if !self.scene.set_sun_direction(dir) {
            return false;
        }
        self.prepared.repack_lighting(&self.scene);
        self.gpu_scene.update_lighting(gpu, &self.prepared);
        self.history.accumulated_state = None;
        self.history.converge_state = None;
        true
    }

    pub fn size(&self) -> (u32, u32) {
        self.targets.size
    }

    /// Show the frame at `size` (None: at the render size). Where that is larger than the render
    /// size and a denoiser runs, the temporal upscaler (passes/upscale.rs,
    /// `TaaSettings::upscale`) reconstructs it from the jittered frames in TAA's place; else
    /// the display stretches the render size's image.
    pub fn show_at(&mut self, size: Option<(u32, u32)>) -> Result<()> {
        if let Some(s) = size {
            check_size(s)?;
        }
        self.shown_size = size;
        Ok(())
    }

    /// The size of the image the last frame showed: the upscaler's where it ran, else the
    /// render size.
    pub fn shown_image_size(&self) -> (u32, u32) {
        self.stages.upscale.output().map_or(self.targets.size, |(_, s)| s)
    }

    /// Bytes of the upscaler's shown-size targets (0 while it does not run).
    pub fn upscale_bytes(&self) -> u64 {
        self.stages.upscale.memory.total_bytes()
    }

    /// Every buffer and texture of the frame and the scene, (label, bytes).
    pub fn allocations(&self) -> Vec<(String, u64)> {
        let mut v = self.gpu_scene.memory.allocations.clone();
        v.extend(self.targets.memory.allocations.iter().cloned());
        v.extend(self.uniforms.memory.allocations.iter().cloned());
        v.extend(self.stages.upscale.memory.allocations.iter().cloned());
        if let Some(c) = self.stages.cache.cells() {
            v.extend(c.memory.allocations.iter().cloned());
        }
        v
    }

    /// Bytes per pixel of the per-pixel targets.
    pub fn bytes_per_pixel(&self) -> f64 {
        let (w, h) = self.targets.size;
        self.targets.memory.total_bytes() as f64 / (w as f64 * h as f64)
    }

    /// Bytes per pixel of the per-pixel targets that live within a frame (the transient pools'
    /// slots, [`crate::gpu::graph`]); the rest outlives it.
    pub fn transient_bytes_per_pixel(&self) -> f64 {
        let (w, h) = self.targets.size;
        self.targets.memory.transient_bytes() as f64 / (w as f64 * h as f64)
    }

    /// Keep the textures whose labels start with one of `prefixes` readable after every frame
    /// ([`Renderer::read_texture`]; `&["svgf/"]` keeps all of SVGF's, and then no two of its
    /// textures share memory): a denoiser's intermediate otherwise shares its memory with a
    /// later texture of the frame, and holds that one's texels once the frame ends. The next
    /// frame places them again. The trace's reflection data (`trace/reflection`, `trace/mirror`)
    /// is written only while something reads it; naming it here makes every frame write it.
    /// The composite's image (`composite/hdr`) holds the still-view mean's image once that stage
    /// ran; naming it here gives that stage a buffer of its own (16 bytes a pixel).
    pub fn keep(&mut self, prefixes: &[&str]) {
        self.kept = prefixes.iter().map(|l| l.to_string()).collect();
    }

    /// Render at `size` from the next frame on. Where `FrameSettings::resample_history_frames`
    /// is above 0 (the default) and a denoiser runs, that frame resamples every history to the
    /// new size (passes/rescale.rs); else the histories restart.
    pub fn resize(&mut self, gpu: &Gpu, size: (u32, u32)) -> Result<()> {
        check_size(size)?;
        if size == self.targets.size {
            return Ok(());
        }
        // The accumulation restarts (its buffer is new); the cameras stay until the next frame
        // decides whether its histories are resampled.
        let h = &mut self.history;
        (h.accumulated, h.accumulated_state, h.converge_state) = (0, None, None);
        // Back to the last size rendered before a frame ran at this one: its targets are whole.
        if let Some(old) = self.rescale_from.take_if(|r| r.size == size) {
            self.targets = old;
            return Ok(());
        }
        let t = &self.targets;
        let new =
            Targets::new(gpu, size, self.prepared.features.glossy, t.epoch + 1, t.generation + 1);
        let old = std::mem::replace(&mut self.targets, new);
        // Resized again before a frame: the histories are still the last rendered size's, and
        // the targets in between were never drawn.
        if self.rescale_from.is_none() {
            self.rescale_from = Some(old);
        }
        Ok(())
    }

    /// What the last resampling of the histories carried across a change of size: the labels
    /// of the textures resampled, and of those no pass could write.
    pub fn last_rescale(&self) -> &crate::passes::rescale::Rescaled {
        &self.last_rescale
    }

    /// Near plane: 2^-14 of the scene's extent (reversed Z keeps depth precise far beyond it).
    pub(crate) fn near(&self) -> f32 {
        (self.prepared.extent * 2f64.powi(-14)) as f32
    }

    /// The camera as the raster and the tracer see it at the current size.
    pub fn camera_setup(&self, camera: &Camera) -> CameraSetup {
        CameraSetup::new(camera, self.prepared.origin, self.targets.size, self.near())
    }

    /// What the frame's bind groups depend on: the scene's buffers, the targets, and for the
    /// stages after the denoiser, which denoiser ran.
    fn bind_key(&self, denoiser: Option<usize>) -> BindKey {
        let (scene, targets) = (self.gpu_scene.generation, self.targets.generation);
        BindKey { scene, targets, denoiser, ..BindKey::default() }
    }

    /// Render one frame; with `target`, also tone-map (or show `settings.view`) into it.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        input: &FrameInput,
        settings: &FrameSettings,
        target: Option<&DisplayTarget>,
    ) -> Result<()> {
        gpu.validated("rendering a frame", || {
            // Named by hand: puffin's function scope would read this impl's path as
            // "Renderer>::render".
            puffin::profile_scope!("Renderer::render");
            let plan = self.plan(gpu, input, settings, target)?;
            self.record_frame(gpu, &plan, target)
        })
    }

    /// Whether the denoiser `settings` asks for takes sample fractions below 1 (the raw frame
    /// does: it shows each pixel's last sample).
    pub fn fills_untraced_pixels(&mut self, gpu: &Gpu, settings: &FrameSettings) -> Result<bool> {
        let plain = FrameSettings { accumulate: false, ..settings.clone() };
        Ok(match self.denoiser_for(gpu, &plain)? {
            None => true,
            Some(i) => self.denoisers[i].denoiser.fills_untraced_pixels(),
        })
    }
}

/// Halton (2, 3) sub-pixel positions, 64 per cycle: the TAA jitter. A still pixel averages up
/// to `TaaSettings::still_frames` (64) of them, so the cycle is that long: the first 16 points cover a
/// horizontal edge at mid-pixel 9 times in 16 (a 6% coverage error); 64 points, within 2%
/// in x and 4% in y at any edge position, better than 64 random positions (about 10%).
pub fn halton_jitter(frame: u32) -> Vec2 {
    let h = |mut i: u32, b: u32| {
        let (mut f, mut r) = (1.0f32, 0.0f32);
        while i > 0 {
            f /= b as f32;
            r += f * (i % b) as f32;
            i /= b;
        }
        r
    };
    let i = frame % 64 + 1;
    Vec2::new(h(i, 2), h(i, 3))
}
