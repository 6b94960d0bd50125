//! The real-time frame, as Figure 2 of Mara et al. 2017 draws it: gbuffer (raster) -> trace ->
//! denoise (any [`crate::denoise::Denoiser`], or none) -> composite -> TAA -> display, on one
//! scene. Which passes, bindings and buffers exist follows the scene's features (no glossy
//! lobe: no glossy path and no glossy buffers; no animation: no object motion buffer and no
//! BVH rebuilds) and the denoiser chosen (its textures are made on its first frame).

mod params;
mod readback;
mod reload;

pub use crate::settings::View;
pub use params::{CameraSetup, FrameParams, random_jitter};

use crate::accel::BvhKind;
use crate::denoise::{Denoiser, DenoiserScene, FrameContext};
use crate::gpu::{BindKey, Gpu, GpuMemory, GpuRequirements, GpuScene, GpuTimer, PreparedScene};
use crate::passes::composite::{CompositePass, DisplayPass, FrameBuffers};
use crate::passes::gbuffer::{self, GBufferPass, GBufferTargets};
use crate::passes::io::{FrameIo, PreviousGBuffer};
use crate::passes::matte::{ChainView, DenoiseParams};
use crate::passes::prefilter::{Prefilter, PrefilterTargets};
use crate::passes::primaries::{Primaries, PrimaryTargets};
use crate::passes::reference::{TraceParams, TraceView, make_params};
use crate::passes::supersample::{Supersample, SupersampleTargets};
use crate::passes::taa::TaaStage;
use crate::passes::trace::{TracePass, TraceTargets};
use crate::scene::{Camera, Scene};
use crate::settings::FrameSettings;
use anyhow::{Context, Result, bail};
use glam::{Mat4, Vec2, Vec3};

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

/// Per-pixel targets of the frame, remade on resize.
struct Targets {
    size: (u32, u32),
    gbuffer: GBufferTargets,
    trace: TraceTargets,
    hdr: wgpu::Buffer,
    accumulation: Option<wgpu::Buffer>,
    /// Made when a denoiser that reads the previous frame's G-buffer first runs.
    previous: Option<PreviousGBuffer>,
    /// Made for k > 1 samples per pixel (remade when k changes).
    supersample: Option<SupersampleTargets>,
    /// Made when a thin lens or a moving shutter is first rendered (traced primaries), and when the
    /// pre-filter first runs.
    primaries: Option<PrimaryTargets>,
    prefilter: Option<PrefilterTargets>,
    /// Every per-pixel allocation, the denoisers' and TAA's included: bytes per pixel, and
    /// textures by label for readback.
    memory: GpuMemory,
    /// Which set of targets this is (one per size): stages allocate again when it changes.
    epoch: u64,
    /// Bumped whenever a target is added or replaced, so bind groups are remade.
    generation: u64,
}

impl Targets {
    fn new(gpu: &Gpu, size: (u32, u32), glossy: bool, epoch: u64, generation: u64) -> Targets {
        let mut memory = GpuMemory::default();
        let gbuffer = GBufferTargets::new(gpu, &mut memory, size);
        let trace = TraceTargets::new(gpu, &mut memory, size, glossy);
        // COPY_DST: the supersampling's resolve writes it back.
        let usage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        let hdr =
            memory.buffer(&gpu.device, "composite/hdr", size.0 as u64 * size.1 as u64 * 16, usage);
        Targets {
            size,
            gbuffer,
            trace,
            hdr,
            accumulation: None,
            previous: None,
            supersample: None,
            primaries: None,
            prefilter: None,
            memory,
            epoch,
            generation,
        }
    }

    fn io<'a>(&'a self, frame: &'a wgpu::Buffer, objects: Option<&'a wgpu::Buffer>) -> FrameIo<'a> {
        FrameIo {
            size: self.size,
            frame,
            objects,
            gbuffer: &self.gbuffer,
            previous: self.previous.as_ref(),
            trace: &self.trace,
            mixed: None,
            hdr: &self.hdr,
            memory: &self.memory,
        }
    }
}

/// A denoiser the frame made, with the targets epoch it allocated its textures for.
struct MadeDenoiser {
    name: String,
    epoch: Option<u64>,
    denoiser: Box<dyn Denoiser>,
}

pub struct Renderer {
    pub scene: Scene,
    pub prepared: PreparedScene,
    pub gpu_scene: GpuScene,
    targets: Targets,
    params_buf: wgpu::Buffer,
    frame_buf: wgpu::Buffer,
    display_buf: wgpu::Buffer,
    /// Bound where accumulation is off, so the composite's layout stays the same.
    no_accumulation: wgpu::Buffer,
    gbuffer: GBufferPass,
    trace: TracePass,
    composite: CompositePass,
    display: Option<DisplayPass>,
    /// Every denoiser chosen so far (switching back keeps its pipelines and textures).
    denoisers: Vec<MadeDenoiser>,
    taa: TaaStage,
    supersample: Supersample,
    primaries: Primaries,
    prefilter: Prefilter,
    /// The index in `denoisers` of the one that ran last frame (its image is then TAA's).
    denoised_last: Option<usize>,
    timer: Option<GpuTimer>,
    /// Pass times are picked up by [`Renderer::poll_pass_spans`] frames later, not read back.
    async_timings: bool,
    prev_view_proj: Option<Mat4>,
    /// The previous frame's jittered view-projection (its depth buffer was rasterised with it)
    /// and its jitter.
    prev_jittered: Option<(Mat4, Vec2)>,
    frame_index: u32,
    accumulated: u32,
    accumulated_state: Option<(FrameInput, FrameSettings)>,
    /// Uniform and small buffers of the frame (the per-pixel ones are in `targets`).
    memory: GpuMemory,
}

impl PreparedScene {
    /// Features and limits of the real-time frame on this scene.
    pub fn realtime_requirements(&self, size: (u32, u32)) -> GpuRequirements {
        let mut r = self.requirements(size.0 as u64 * size.1 as u64, 16);
        // The supersampling's samples pass binds the trace's buffers and two of its own.
        r.max_storage_buffers_per_shader_stage += 2;
        r.max_color_attachment_bytes_per_sample = gbuffer::COLOR_BYTES_PER_SAMPLE;
        // matte, direct, and with a glossy lobe glossy, reflection, mirror and mirror hit; the
        // pre-filter's covariance step writes 4 (WebGPU's default).
        r.max_storage_textures_per_shader_stage = if self.features.glossy { 6 } else { 4 };
        // TAA reads the most: the G-buffer (7), the trace's outputs (2, +4 glossy), its four
        // histories and the denoiser's light it follows (2, +3 glossy): 22 in a glossy scene
        // (WebGPU's default is 16; desktop Vulkan, Metal and D3D12 adapters offer far more).
        r.max_sampled_textures_per_shader_stage = if self.features.glossy { 22 } else { 15 };
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
        check_size(size)?;
        let prepared = PreparedScene::new(&scene, kind)
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
        let mut memory = GpuMemory::default();
        let u = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        let d = &gpu.device;
        let params_buf = memory.buffer(d, "frame/scene params", size_of::<TraceParams>() as u64, u);
        let frame_buf = memory.buffer(d, "frame/params", size_of::<FrameParams>() as u64, u);
        let display_buf = memory.buffer(d, "display/options", 32, u);
        let no_accumulation =
            memory.buffer(d, "composite/no accumulation", 16, wgpu::BufferUsages::STORAGE);
        let gbuffer =
            GBufferPass::new(gpu, &gpu_scene, &frame_buf).context("creating the G-buffer pass")?;
        let trace = TracePass::new(
            gpu,
            &gpu_scene,
            &params_buf,
            &frame_buf,
            &targets.gbuffer,
            &targets.trace,
        )
        .context("creating the trace pass")?;
        let io = targets.io(&frame_buf, gpu_scene.objects.as_ref());
        let fb = FrameBuffers {
            io,
            shown: &targets.hdr,
            accumulation: &no_accumulation,
            display: &display_buf,
            matte: None,
            glossy: None,
            direct: None,
        };
        let composite = CompositePass::new(gpu, &fb).context("creating the composite pass")?;
        let taa = TaaStage::new(gpu, &mut memory, prepared.features.animated);
        let timer = GpuTimer::new(gpu, TIMED_PASSES);
        let r = Renderer {
            scene,
            prepared,
            gpu_scene,
            targets,
            params_buf,
            frame_buf,
            display_buf,
            no_accumulation,
            gbuffer,
            trace,
            composite,
            display: None,
            denoisers: vec![],
            taa,
            supersample: Supersample::new(),
            primaries: Primaries::default(),
            prefilter: Prefilter::default(),
            denoised_last: None,
            timer,
            async_timings: false,
            prev_view_proj: None,
            prev_jittered: None,
            frame_index: 0,
            accumulated: 0,
            accumulated_state: None,
            memory,
        };
        log::info!("{}", r.report());
        Ok(r)
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
        self.accumulated_state = None;
        true
    }

    pub fn size(&self) -> (u32, u32) {
        self.targets.size
    }

    /// Every buffer and texture of the frame and the scene, (label, bytes).
    pub fn allocations(&self) -> Vec<(String, u64)> {
        let mut v = self.gpu_scene.memory.allocations.clone();
        v.extend(self.targets.memory.allocations.iter().cloned());
        v.extend(self.memory.allocations.iter().cloned());
        v
    }

    /// Bytes per pixel of the per-pixel targets.
    pub fn bytes_per_pixel(&self) -> f64 {
        let (w, h) = self.targets.size;
        self.targets.memory.total_bytes() as f64 / (w as f64 * h as f64)
    }

    pub fn resize(&mut self, gpu: &Gpu, size: (u32, u32)) -> Result<()> {
        check_size(size)?;
        if size == self.targets.size {
            return Ok(());
        }
        let t = &self.targets;
        self.targets =
            Targets::new(gpu, size, self.prepared.features.glossy, t.epoch + 1, t.generation + 1);
        self.prev_view_proj = None;
        self.prev_jittered = None;
        self.denoised_last = None;
        self.accumulated = 0;
        self.accumulated_state = None;
        Ok(())
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
        gpu.validated("rendering a frame", || self.record_frame(gpu, input, settings, target))
    }

    /// The index in `denoisers` of the one `settings` asks for (made and allocated on first
    /// use), or None for the raw frame; None also in accumulate mode.
    fn denoiser_for(&mut self, gpu: &Gpu, settings: &FrameSettings) -> Result<Option<usize>> {
        if settings.accumulate {
            return Ok(None);
        }
        let name = settings.denoiser.name();
        let i = match self.denoisers.iter().position(|d| d.name == name) {
            Some(i) => i,
            None => {
                let Some(make) = crate::denoise::find(name)?.make else { return Ok(None) };
                let scene = DenoiserScene {
                    glossy: self.prepared.features.glossy,
                    animated: self.prepared.features.animated,
                    extent: self.prepared.extent as f32,
                };
                let denoiser =
                    make(gpu, &scene).with_context(|| format!("creating the {name} denoiser"))?;
                self.denoisers.push(MadeDenoiser { name: name.to_string(), epoch: None, denoiser });
                self.denoisers.len() - 1
            }
        };
        let t = &mut self.targets;
        let d = &mut self.denoisers[i];
        if d.epoch != Some(t.epoch) {
            d.denoiser.allocate(gpu, &mut t.memory, t.size);
            d.epoch = Some(t.epoch);
            t.generation += 1;
        }
        if d.denoiser.needs_previous_gbuffer() && t.previous.is_none() {
            t.previous = Some(PreviousGBuffer::new(&gpu.device, &mut t.memory, t.size));
            t.generation += 1;
        }
        Ok(Some(i))
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

    /// Accumulation restarts whenever anything that changes the image changes.
    fn update_accumulation(&mut self, gpu: &Gpu, input: &FrameInput, settings: &FrameSettings) {
        if !settings.accumulate {
            self.accumulated = 0;
            self.accumulated_state = None;
            return;
        }
        let same = self.accumulated_state.as_ref().is_some_and(|(i, s)| {
            i == input && s.max_depth == settings.max_depth && s.seed == settings.seed
        });
        self.accumulated = if same { self.accumulated + 1 } else { 1 };
        self.accumulated_state = Some((*input, settings.clone()));
        let t = &mut self.targets;
        if t.accumulation.is_none() {
            let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
            t.accumulation = Some(t.memory.buffer(
                &gpu.device,
                "composite/accumulation",
                t.size.0 as u64 * t.size.1 as u64 * 16,
                usage,
            ));
            t.generation += 1;
        }
    }

    /// This frame's jitter, its camera against the last frame's, and the frame and trace
    /// uniforms written; returns what the denoiser and TAA know of the cameras, and the
    /// jittered view-projection and jitter (the next frame's "previous").
    #[allow(clippy::too_many_arguments)]
    fn upload_frame(
        &mut self,
        gpu: &Gpu,
        input: &FrameInput,
        settings: &FrameSettings,
        cam: &CameraSetup,
        moved: bool,
        denoised: bool,
        primary_samples: u32,
    ) -> (ChainView, Mat4, Vec2) {
        let size = self.targets.size;
        let jitter = if settings.accumulate {
            random_jitter(self.frame_index, settings.seed)
        } else if denoised && settings.taa.enabled {
            halton_jitter(self.frame_index)
        } else {
            Vec2::splat(0.5)
        };
        let jittered = cam.jittered(jitter, size);
        let (prev_jittered, prev_jitter) = self.prev_jittered.unwrap_or((jittered, jitter));
        let view = ChainView {
            inv_view_proj: jittered.inverse(),
            prev_inv_view_proj: prev_jittered.inverse(),
            jitter_shift: prev_jitter - jitter,
            // Set by the caller, which knows whether the same denoiser ran last frame.
            history_valid: false,
            static_view: !moved && self.prev_view_proj == Some(cam.view_proj),
        };
        let g = &settings.glossy;
        // The glossy chain's reflection motion wants the representative ray of glossy surfaces.
        let representative = if denoised
            && g.trace_representative_ray
            && g.reflection_mv != crate::settings::ReflectionMv::Primary
        {
            g.roughness_threshold
        } else {
            0.0
        };
        let prev = self.prev_view_proj.unwrap_or(cam.view_proj);
        let mut fp = FrameParams::new(
            cam,
            jittered,
            prev,
            jitter,
            size,
            self.frame_index,
            settings,
            self.accumulated,
            self.prepared.ray_epsilon(),
            representative,
        );
        fp.primary_samples = primary_samples;
        let trace_view = TraceView {
            camera: input.camera,
            width: size.0,
            height: size.1,
            max_depth: settings.max_depth,
            seed: settings.seed,
            shutter_camera: input.shutter.map(|s| s.camera),
        };
        let tp = make_params(&self.prepared, &trace_view);
        gpu.queue.write_buffer(&self.params_buf, 0, bytemuck::bytes_of(&tp));
        gpu.queue.write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(&fp));
        (view, jittered, jitter)
    }

    fn record_frame(
        &mut self,
        gpu: &Gpu,
        input: &FrameInput,
        settings: &FrameSettings,
        target: Option<&DisplayTarget>,
    ) -> Result<()> {
        puffin::profile_function!();
        let mut moved = false;
        if self.prepared.features.animated {
            puffin::profile_scope!("animate");
            moved = self.prepared.expose(&self.scene, input.time, input.shutter.map(|s| s.time));
            self.gpu_scene.update_geometry(gpu, &self.prepared, moved);
        }
        let size = self.targets.size;
        let cam = self.camera_setup(&input.camera);

        self.update_accumulation(gpu, input, settings);
        let setup = crate::profile::scope("upload");
        let denoiser = self.denoiser_for(gpu, settings)?;
        if denoiser.is_some() {
            let t = &mut self.targets;
            if self.taa.allocate(gpu, &mut t.memory, t.size, t.epoch) {
                t.generation += 1;
            }
        }
        // Samples per pixel (Voorhuis §5); the accumulate mode box-filters by itself.
        let samples = if settings.accumulate {
            1
        } else {
            settings.samples_per_pixel.clamp(1, crate::settings::MAX_SAMPLES_PER_PIXEL)
        };
        // Below one sample per pixel (Dundr §5): only denoisers that fill the untraced pixels.
        let period = if settings.accumulate { 1 } else { settings.sample_fraction.period() };
        if period > 1 {
            if samples > 1 {
                bail!(
                    "sample fraction {} traces some pixels each frame and {samples} samples per pixel traces every pixel {samples} times: choose one",
                    settings.sample_fraction
                );
            }
            if let Some(i) =
                denoiser.filter(|&i| !self.denoisers[i].denoiser.fills_untraced_pixels())
            {
                let fills: Vec<&str> = crate::denoise::entries()
                    .into_iter()
                    .filter(|e| e.fractions)
                    .map(|e| e.name)
                    .collect();
                bail!(
                    "the {} denoiser needs every pixel traced each frame; sample fraction {} needs one that fills untraced pixels ({})",
                    self.denoisers[i].name,
                    settings.sample_fraction,
                    fills.join(", ")
                );
            }
        }
        if samples > 1
            && self
                .targets
                .supersample
                .as_ref()
                .is_none_or(|s| s.k != samples || s.epoch != self.targets.epoch)
        {
            let t = &mut self.targets;
            t.memory.forget(SupersampleTargets::PREFIX);
            t.supersample = Some(SupersampleTargets::new(
                &gpu.device,
                &mut t.memory,
                t.size,
                samples,
                self.prepared.features.glossy,
                t.epoch,
            ));
            t.generation += 1;
        }
        // A thin lens or motion blur (a stochastic primary hit): the G-buffer is traced (k rays
        // per pixel, each through its own lens point at its own time), not rasterised; the
        // accumulate mode traces one, so that its mean over frames is exact.
        let blurred = input.shutter.is_some_and(|s| s.camera != input.camera)
            || self.prepared.shutter_moves();
        let traced = input.camera.lens.is_some_and(|l| l.aperture_radius > 0.0) || blurred;
        let primary_samples = match (traced, settings.accumulate) {
            (false, _) => 0,
            (true, true) => 1,
            (true, false) => {
                settings.primary_samples.clamp(1, crate::settings::MAX_PRIMARY_SAMPLES)
            }
        };
        let prefilter = traced && settings.prefilter && !settings.accumulate;
        if traced {
            if samples > 1 {
                bail!(
                    "{samples} samples per pixel (guide rays) need the raster's G-buffer, which depth of field and motion blur replace by traced primaries: set samples per pixel to 1 (they trace {} primary samples per pixel)",
                    settings.primary_samples
                );
            }
            let t = &mut self.targets;
            if t.primaries.as_ref().is_none_or(|p| p.epoch != t.epoch) {
                t.memory.forget(PrimaryTargets::PREFIX);
                t.primaries =
                    Some(PrimaryTargets::new(&gpu.device, &mut t.memory, t.size, t.epoch));
                t.generation += 1;
            }
            if prefilter && t.prefilter.as_ref().is_none_or(|p| p.epoch != t.epoch) {
                t.memory.forget(PrefilterTargets::PREFIX);
                t.prefilter =
                    Some(PrefilterTargets::new(&gpu.device, &mut t.memory, t.size, t.epoch));
                t.generation += 1;
            }
        }
        let (mut view, jittered, jitter) = self.upload_frame(
            gpu,
            input,
            settings,
            &cam,
            moved,
            denoiser.is_some(),
            primary_samples,
        );
        view.history_valid =
            denoiser.is_some() && self.denoised_last == denoiser && self.prev_jittered.is_some();
        self.denoised_last = denoiser;
        if let Some(target) = target {
            self.prepare_display(gpu, target, settings)?;
        }
        drop(setup);

        let encode = crate::profile::scope("encode");
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        if let Some(t) = self.timer.as_mut() {
            t.begin_frame();
        }
        // Bind groups depend on the scene only through its buffers' generation.
        let key = self.bind_key(None);
        // Stages after the denoiser also bind its outputs.
        let output_key = self.bind_key(denoiser);
        let parity = crate::gpu::Parity::of_frame(self.frame_index);
        // gbuffer -> trace -> denoise -> composite -> TAA -> display (Mara et al. 2017, Figure 2).
        let t = &self.targets;
        match t.primaries.as_ref().filter(|_| traced) {
            None => {
                let _pass = crate::profile::scope(gbuffer::LABEL);
                self.gbuffer.record(
                    gpu,
                    &mut enc,
                    &self.gpu_scene,
                    &self.frame_buf,
                    &t.gbuffer,
                    self.timer.as_mut(),
                )?;
            }
            Some(p) => {
                // The pre-filter stage (Moon et al. 2017) between the traced features and the
                // G-buffer every later stage reads.
                self.primaries.record_trace(
                    gpu,
                    &mut enc,
                    key,
                    &self.gpu_scene,
                    &self.params_buf,
                    &self.frame_buf,
                    p,
                    size,
                    self.prepared.shutter_moves(),
                    self.timer.as_mut(),
                )?;
                let mut edges = None;
                if let Some(pf) = t.prefilter.as_ref().filter(|_| prefilter) {
                    let offered = crate::passes::prefilter::bindings(&self.frame_buf, p, pf);
                    self.prefilter.record(
                        gpu,
                        &mut enc,
                        key,
                        size,
                        &offered,
                        self.timer.as_mut(),
                    )?;
                    edges = Some(&pf.features);
                }
                self.primaries.record_resolve(
                    gpu,
                    &mut enc,
                    key,
                    &self.frame_buf,
                    p,
                    edges,
                    &t.gbuffer,
                    self.timer.as_mut(),
                )?;
            }
        }
        let pass = crate::profile::scope(crate::passes::trace::LABEL);
        self.trace.record(
            gpu,
            &mut enc,
            key,
            &self.gpu_scene,
            &self.params_buf,
            &self.frame_buf,
            &t.gbuffer,
            &t.trace,
            size,
            period,
            self.prepared.shutter_moves(),
            self.timer.as_mut(),
        )?;
        drop(pass);
        let mut io = t.io(&self.frame_buf, self.gpu_scene.objects.as_ref());
        let ss = t.supersample.as_ref().filter(|s| s.k == samples);
        if let Some(ss) = ss {
            let trace = crate::passes::trace::bindings(
                &self.gpu_scene,
                &self.params_buf,
                &self.frame_buf,
                &t.gbuffer,
                &t.trace,
            );
            self.supersample.record_mix(
                gpu,
                &mut enc,
                key,
                &self.gpu_scene,
                trace,
                &io,
                ss,
                self.timer.as_mut(),
            )?;
            io.mixed = Some(&ss.mixed);
        }
        let cx = FrameContext { index: self.frame_index, parity, view, settings, key };
        let mut denoiser = denoiser.map(|i| &mut self.denoisers[i].denoiser);
        if let Some(d) = denoiser.as_deref_mut() {
            d.record(gpu, &mut enc, &io, &cx, self.timer.as_mut())?;
        }
        let denoiser = denoiser.map(|d| &**d);
        let accumulation = t.accumulation.as_ref().unwrap_or(&self.no_accumulation);
        let fb = |p: crate::gpu::Parity| {
            let out = denoiser.map(|d| d.output(p)).unwrap_or_default();
            FrameBuffers {
                io,
                shown: &t.hdr,
                accumulation,
                display: &self.display_buf,
                matte: out.matte,
                glossy: out.glossy,
                direct: out.direct,
            }
        };
        let pass = crate::profile::scope(crate::passes::composite::COMPOSITE);
        self.composite.record(gpu, &mut enc, output_key, fb, parity, self.timer.as_mut())?;
        drop(pass);
        if let Some(ss) = ss {
            self.supersample.record_resolve(gpu, &mut enc, key, &io, ss, self.timer.as_mut())?;
        }
        if let Some(d) = denoiser {
            // TAA runs after any denoiser; with its stage off it passes the composite on.
            let dp = DenoiseParams::new(
                &settings.matte,
                &settings.taa,
                size.0,
                self.frame_index,
                &cx.view,
            );
            self.taa.record(
                gpu,
                &mut enc,
                output_key,
                &io,
                |p| d.taa_follow(p),
                &dp,
                parity,
                self.timer.as_mut(),
            )?;
        }
        let shown = shown_buffers(
            t,
            &io,
            &self.display_buf,
            &self.no_accumulation,
            denoiser.is_some(),
            self.taa.output(),
        );
        if let (Some(target), Some(d)) = (target, self.display.as_mut()) {
            let _pass = crate::profile::scope(crate::passes::composite::DISPLAY);
            let (view, view_key) = view_texture(t, settings);
            d.record(
                gpu,
                &mut enc,
                BindKey { view: view_key, ..output_key },
                &shown,
                view,
                target.view,
                self.timer.as_mut(),
            )?;
        }
        if let (true, Some(p)) = (denoiser.is_some(), &t.previous) {
            p.record_copy(&mut enc, &t.gbuffer, size);
        }
        if let Some(timer) = self.timer.as_mut() {
            timer.resolve(&gpu.device, &mut enc, self.async_timings);
        }
        drop(encode);
        let _submit = crate::profile::scope("submit");
        if let Some(timer) = self.timer.as_mut() {
            timer.submitted_ns = puffin::now_ns();
        }
        gpu.queue.submit([enc.finish()]);
        if let Some(timer) = self.timer.as_mut() {
            timer.submitted();
        }
        self.prev_view_proj = Some(cam.view_proj);
        self.prev_jittered = Some((jittered, jitter));
        self.frame_index = self.frame_index.wrapping_add(1);
        Ok(())
    }

    /// Draw the last frame again into `target` (another view, a screenshot) without rendering.
    pub fn redisplay(
        &mut self,
        gpu: &Gpu,
        settings: &FrameSettings,
        target: &DisplayTarget,
    ) -> Result<()> {
        gpu.validated("displaying the frame", || {
            self.prepare_display(gpu, target, settings)?;
            // Only the exposure changes; the rest of the uniform is the last frame's.
            gpu.queue.write_buffer(
                &self.frame_buf,
                std::mem::offset_of!(FrameParams, exposure) as u64,
                bytemuck::bytes_of(&settings.exposure_scale()),
            );
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            let t = &self.targets;
            let io = t.io(&self.frame_buf, self.gpu_scene.objects.as_ref());
            let fb = shown_buffers(
                t,
                &io,
                &self.display_buf,
                &self.no_accumulation,
                self.denoised_last.is_some(),
                self.taa.output(),
            );
            let (view, view_key) = view_texture(t, settings);
            let key = BindKey { view: view_key, ..self.bind_key(self.denoised_last) };
            if let Some(d) = self.display.as_mut() {
                d.record(gpu, &mut enc, key, &fb, view, target.view, None)?;
            }
            gpu.queue.submit([enc.finish()]);
            Ok(())
        })
    }

    /// Make the display pass for `target`'s format and write its options (the view's map).
    fn prepare_display(
        &mut self,
        gpu: &Gpu,
        target: &DisplayTarget,
        settings: &FrameSettings,
    ) -> Result<()> {
        if self.display.as_ref().is_none_or(|d| d.format != target.format) {
            let t = &self.targets;
            let io = t.io(&self.frame_buf, self.gpu_scene.objects.as_ref());
            let fb = shown_buffers(t, &io, &self.display_buf, &self.no_accumulation, false, None);
            self.display = Some(
                DisplayPass::new(gpu, &fb, target.format).context("creating the display pass")?,
            );
        }
        let spec = match settings.view.is_final() {
            true => None,
            false => Some(
                settings
                    .view
                    .spec()
                    .with_context(|| format!("no view {:?}", settings.view.name()))?,
            ),
        };
        let (map, channel, param) = spec.map_or((0, 0, 0.0), |s| s.map.encode(self.targets.size.0));
        let srgb = !target.format.is_srgb() as u32;
        let options: [u32; 8] =
            [srgb, map, target.size.0, target.size.1, channel, param.to_bits(), 0, 0];
        gpu.queue.write_buffer(&self.display_buf, 0, bytemuck::cast_slice(&options));
        Ok(())
    }
}

/// The texture `settings.view` shows, if this frame has it (a denoiser's view is black until
/// the denoiser has run), and a key that changes with it.
fn view_texture<'a>(
    t: &'a Targets,
    settings: &FrameSettings,
) -> (Option<&'a wgpu::Texture>, usize) {
    let views = crate::settings::all_views();
    let Some(i) = views.iter().position(|v| v.name == settings.view.name()) else {
        return (None, 0);
    };
    match t.memory.find_texture(views[i].texture) {
        Some(tex) => (Some(tex), i + 1),
        None => (None, 0),
    }
}

/// What the display reads: the image after TAA when a denoiser ran, else the composite's.
fn shown_buffers<'a>(
    t: &'a Targets,
    io: &FrameIo<'a>,
    display: &'a wgpu::Buffer,
    no_accumulation: &'a wgpu::Buffer,
    denoised: bool,
    taa: Option<&'a wgpu::Buffer>,
) -> FrameBuffers<'a> {
    FrameBuffers {
        io: *io,
        shown: taa.filter(|_| denoised).unwrap_or(&t.hdr),
        accumulation: t.accumulation.as_ref().unwrap_or(no_accumulation),
        display,
        matte: None,
        glossy: None,
        direct: None,
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
