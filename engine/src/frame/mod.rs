//! The real-time frame: G-buffer raster -> factored trace -> composite -> display, on one scene.
//! Which passes, bindings and buffers exist follows the scene's features (no glossy lobe: no
//! glossy path and no glossy buffers; no animation: no object motion buffer and no BVH rebuilds).

mod params;
mod reload;
mod views;

pub use params::{CameraSetup, FrameParams, random_jitter};
pub use views::View;

use crate::accel::BvhKind;
use crate::gpu::{Gpu, GpuMemory, GpuRequirements, GpuScene, GpuTimer, PreparedScene};
use crate::passes::composite::{CompositePass, DisplayPass, FrameBuffers};
use crate::passes::glossy::{GlossyChain, GlossyChainTargets, GlossyInputs, GlossyParams};
use crate::passes::matte::{ChainInputs, ChainView, DenoiseParams, MatteChain, MatteTargets};
use crate::settings::Denoiser;
use crate::passes::gbuffer::{self, GBufferPass, GBufferTargets};
use crate::passes::reference::{TraceParams, TraceView, make_params};
use crate::passes::trace::{TracePass, TraceTargets};
use crate::quality::Image;
use crate::scene::{Camera, Scene};
use crate::settings::FrameSettings;
use anyhow::{Context, Result, bail};
use glam::{Mat4, Vec2, Vec3};

/// Largest image side of the real-time frame.
pub const MAX_SIDE: u32 = 8192;

/// Passes that can write timestamps in one frame.
const TIMED_PASSES: u32 = 24;

/// Where the camera is and what time it is in the scene's animation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameInput {
    pub camera: Camera,
    /// Seconds into the scene's animation.
    pub time: f64,
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
    /// The denoiser's textures, made on its first use.
    matte: Option<MatteTargets>,
    /// The glossy chain's textures, made with the matte ones in scenes with a specular lobe.
    glossy_chain: Option<GlossyChainTargets>,
    memory: GpuMemory,
    generation: u64,
}

impl Targets {
    fn new(gpu: &Gpu, size: (u32, u32), glossy: bool, generation: u64) -> Targets {
        let mut memory = GpuMemory::default();
        let gbuffer = GBufferTargets::new(gpu, &mut memory, size);
        let trace = TraceTargets::new(gpu, &mut memory, size, glossy);
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let hdr = memory.buffer(&gpu.device, "composite/hdr", size.0 as u64 * size.1 as u64 * 16, usage);
        Targets { size, gbuffer, trace, hdr, accumulation: None, matte: None, glossy_chain: None, memory, generation }
    }
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
    chain: Option<MatteChain>,
    glossy_chain: Option<GlossyChain>,
    denoise_buf: wgpu::Buffer,
    glossy_buf: wgpu::Buffer,
    /// Whether the last frame went through the denoiser (its image is then TAA's output).
    denoised_last: bool,
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
        r.max_color_attachment_bytes_per_sample = gbuffer::COLOR_BYTES_PER_SAMPLE;
        // matte, direct, and with a glossy lobe glossy, reflection, mirror and mirror hit.
        r.max_storage_textures_per_shader_stage = if self.features.glossy { 6 } else { 2 };
        // The display reads the G-buffer (7), trace outputs (2, +4 glossy) and the chains'
        // intermediates (5 matte, +5 glossy): 23 in a glossy scene (WebGPU's default is 16;
        // desktop Vulkan, Metal and D3D12 adapters offer far more).
        r.max_sampled_textures_per_shader_stage = if self.features.glossy { 23 } else { 14 };
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
        let prepared = PreparedScene::new(&scene, kind).with_context(|| format!("preparing scene {:?}", scene.name))?;
        let gpu = Gpu::headless(&prepared.realtime_requirements(size))?;
        let r = Renderer::new(&gpu, scene, prepared, size)?;
        Ok((gpu, r))
    }

    pub fn new(gpu: &Gpu, scene: Scene, prepared: PreparedScene, size: (u32, u32)) -> Result<Renderer> {
        check_size(size)?;
        gpu.validated("creating the real-time frame", || Self::create(gpu, scene, prepared, size))
    }

    fn create(gpu: &Gpu, scene: Scene, prepared: PreparedScene, size: (u32, u32)) -> Result<Renderer> {
        let gpu_scene = prepared.upload(gpu);
        let glossy = prepared.features.glossy;
        let targets = Targets::new(gpu, size, glossy, 0);
        let mut memory = GpuMemory::default();
        let u = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        let d = &gpu.device;
        let params_buf = memory.buffer(d, "frame/scene params", size_of::<TraceParams>() as u64, u);
        let frame_buf = memory.buffer(d, "frame/params", size_of::<FrameParams>() as u64, u);
        let display_buf = memory.buffer(d, "display/options", 16, u);
        let no_accumulation = memory.buffer(d, "composite/no accumulation", 16, wgpu::BufferUsages::STORAGE);
        let denoise_buf = memory.buffer(d, "matte/params", size_of::<DenoiseParams>() as u64, u);
        let glossy_buf = memory.buffer(d, "glossy/params", size_of::<GlossyParams>() as u64, u);
        let gbuffer = GBufferPass::new(gpu, &gpu_scene, &frame_buf).context("creating the G-buffer pass")?;
        let trace = TracePass::new(gpu, &gpu_scene, &params_buf, &frame_buf, &targets.gbuffer, &targets.trace).context("creating the trace pass")?;
        let fb = FrameBuffers { frame: &frame_buf, hdr: &targets.hdr, accumulation: &no_accumulation, display: &display_buf, matte: &targets.trace.matte.1, glossy: None, denoise: None, glossy_chain: None };
        let composite = CompositePass::new(gpu, &targets.gbuffer, &targets.trace, &fb).context("creating the composite pass")?;
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
            chain: None,
            glossy_chain: None,
            denoise_buf,
            glossy_buf,
            denoised_last: false,
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
        let buffers = self.targets.memory.allocations.iter().map(|(l, b)| format!("{l}={b}")).collect::<Vec<_>>().join(" ");
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
        let g = self.targets.generation + 1;
        self.targets = Targets::new(gpu, size, self.prepared.features.glossy, g);
        self.prev_view_proj = None;
        self.prev_jittered = None;
        self.denoised_last = false;
        self.accumulated = 0;
        self.accumulated_state = None;
        Ok(())
    }

    /// Near plane: 2^-14 of the scene's extent (reversed Z keeps depth precise far beyond it).
    fn near(&self) -> f32 {
        (self.prepared.extent * 2f64.powi(-14)) as f32
    }

    /// The camera as the raster and the tracer see it at the current size.
    pub fn camera_setup(&self, camera: &Camera) -> CameraSetup {
        CameraSetup::new(camera, self.prepared.origin, self.targets.size, self.near())
    }

    /// Render one frame; with `target`, also tone-map (or show `settings.view`) into it.
    pub fn render(&mut self, gpu: &Gpu, input: &FrameInput, settings: &FrameSettings, target: Option<&DisplayTarget>) -> Result<()> {
        gpu.validated("rendering a frame", || self.record_frame(gpu, input, settings, target))
    }

    fn record_frame(&mut self, gpu: &Gpu, input: &FrameInput, settings: &FrameSettings, target: Option<&DisplayTarget>) -> Result<()> {
        puffin::profile_function!();
        let mut moved = false;
        if self.prepared.features.animated {
            puffin::profile_scope!("animate");
            moved = self.prepared.animate(&self.scene, input.time);
            self.gpu_scene.update_geometry(gpu, &self.prepared, moved);
        }
        let size = self.targets.size;
        let cam = self.camera_setup(&input.camera);

        // Accumulation restarts whenever anything that changes the image changes.
        if settings.accumulate {
            let same = self.accumulated_state.as_ref().is_some_and(|(i, s)| i == input && s.max_depth == settings.max_depth && s.seed == settings.seed);
            self.accumulated = if same { self.accumulated + 1 } else { 1 };
            self.accumulated_state = Some((*input, settings.clone()));
            if self.targets.accumulation.is_none() {
                let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
                self.targets.accumulation = Some(self.targets.memory.buffer(&gpu.device, "composite/accumulation", size.0 as u64 * size.1 as u64 * 16, usage));
                self.targets.generation += 1;
            }
        } else {
            self.accumulated = 0;
            self.accumulated_state = None;
        }
        let denoise = settings.denoiser == Denoiser::Mara && !settings.accumulate;
        if denoise && self.targets.matte.is_none() {
            self.targets.matte = Some(MatteTargets::new(gpu, &mut self.targets.memory, size));
            if self.prepared.features.glossy {
                self.targets.glossy_chain = Some(GlossyChainTargets::new(gpu, &mut self.targets.memory, size));
            }
            self.targets.generation += 1;
        }
        let setup = crate::profile::scope("upload");
        if denoise && self.chain.is_none() {
            let inputs = self.chain_inputs();
            self.chain = Some(MatteChain::new(gpu, &inputs, self.prepared.features.animated).context("creating the matte chain")?);
        }
        if denoise
            && self.glossy_chain.is_none()
            && let Some(inputs) = self.glossy_inputs()
        {
            self.glossy_chain = Some(GlossyChain::new(gpu, &inputs, self.prepared.features.animated).context("creating the glossy chain")?);
        }
        let jitter = if settings.accumulate {
            random_jitter(self.frame_index, settings.seed)
        } else if denoise && settings.matte.taa {
            halton_jitter(self.frame_index)
        } else {
            Vec2::splat(0.5)
        };
        let prev = self.prev_view_proj.unwrap_or(cam.view_proj);
        let jittered = cam.jittered(jitter, size);
        if denoise {
            let history_valid = self.denoised_last && self.prev_jittered.is_some();
            let (prev_jittered, prev_jitter) = self.prev_jittered.unwrap_or((jittered, jitter));
            let static_view = !moved && self.prev_view_proj == Some(cam.view_proj);
            let view = ChainView { inv_view_proj: jittered.inverse(), prev_inv_view_proj: prev_jittered.inverse(), jitter_shift: prev_jitter - jitter, history_valid, static_view };
            let dp = DenoiseParams::new(&settings.matte, size.0, self.frame_index, &view);
            gpu.queue.write_buffer(&self.denoise_buf, 0, bytemuck::bytes_of(&dp));
            let gp = GlossyParams::new(&settings.glossy, self.prepared.extent as f32, static_view);
            gpu.queue.write_buffer(&self.glossy_buf, 0, bytemuck::bytes_of(&gp));
        }
        let fp = FrameParams {
            view_proj: jittered.to_cols_array_2d(),
            unjittered_view_proj: cam.view_proj.to_cols_array_2d(),
            prev_view_proj: prev.to_cols_array_2d(),
            cam_pos: cam.pos.extend(self.prepared.ray_epsilon()).to_array(),
            cam_right: cam.right.extend(0.0).to_array(),
            cam_up: cam.up.extend(0.0).to_array(),
            cam_fwd: cam.fwd.extend(0.0).to_array(),
            jitter: jitter.to_array(),
            size: [size.0, size.1],
            index: self.frame_index,
            view: settings.view as u32,
            exposure: settings.exposure_scale(),
            accumulated: self.accumulated,
            paths: settings.paths_per_pixel.clamp(1, 64),
            representative_roughness: if denoise && settings.glossy.trace_representative_ray && settings.glossy.reflection_mv != crate::settings::ReflectionMv::Primary { settings.glossy.roughness_threshold } else { 0.0 },
            _pad: [0; 2],
        };
        let view = TraceView { camera: input.camera, width: size.0, height: size.1, max_depth: settings.max_depth, seed: settings.seed };
        let tp = make_params(&self.prepared, &view);
        gpu.queue.write_buffer(&self.params_buf, 0, bytemuck::bytes_of(&tp));
        gpu.queue.write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(&fp));

        self.denoised_last = denoise;
        if let Some(target) = target {
            self.prepare_display(gpu, target)?;
        }

        drop(setup);
        let encode = crate::profile::scope("encode");
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        if let Some(t) = self.timer.as_mut() {
            t.begin_frame();
        }
        let key = (self.gpu_scene.generation, self.targets.generation);
        let parity = (self.frame_index % 2) as usize;
        let pass = crate::profile::scope(gbuffer::LABEL);
        self.gbuffer.record(gpu, &mut enc, &self.gpu_scene, &self.frame_buf, &self.targets.gbuffer, self.timer.as_mut())?;
        drop(pass);
        let t = &self.targets;
        let pass = crate::profile::scope(crate::passes::trace::LABEL);
        self.trace.record(gpu, &mut enc, key, &self.gpu_scene, &self.params_buf, &self.frame_buf, &t.gbuffer, &t.trace, size, self.timer.as_mut())?;
        drop(pass);
        // The chain's bind groups depend on the scene only through the object-motion buffer.
        let chain_key = key.0 * 1_000_003 + key.1;
        let inputs = t.matte.as_ref().filter(|_| denoise).map(|m| ChainInputs {
            frame: &self.frame_buf,
            params: &self.denoise_buf,
            objects: self.gpu_scene.objects.as_ref(),
            hdr: &t.hdr,
            gbuffer: &t.gbuffer,
            trace: &t.trace,
            matte: m,
            glossy: t.glossy_chain.as_ref().map(|g| (g, &self.glossy_buf)),
        });
        let denoised_matte = t.matte.as_ref().filter(|_| denoise).map(|m| &m.denoised.1);
        if let (Some(inputs), Some(chain)) = (&inputs, self.chain.as_mut()) {
            chain.record(gpu, &mut enc, chain_key, inputs, parity, size, false, self.timer.as_mut())?;
        }
        let glossy_inputs = glossy_inputs(t, &self.frame_buf, &self.denoise_buf, &self.glossy_buf, self.gpu_scene.objects.as_ref()).filter(|_| denoise);
        if let (Some(inputs), Some(chain)) = (&glossy_inputs, self.glossy_chain.as_mut()) {
            chain.record(gpu, &mut enc, chain_key, inputs, parity, size, &settings.glossy, self.timer.as_mut())?;
        }
        let denoised_glossy = t.glossy_chain.as_ref().filter(|_| denoise).map(|g| &g.denoised.1);
        let fb = FrameBuffers {
            frame: &self.frame_buf,
            hdr: &t.hdr,
            accumulation: t.accumulation.as_ref().unwrap_or(&self.no_accumulation),
            display: &self.display_buf,
            matte: denoised_matte.unwrap_or(&t.trace.matte.1),
            glossy: denoised_glossy,
            denoise: None,
            glossy_chain: None,
        };
        let pass = crate::profile::scope(crate::passes::composite::COMPOSITE);
        self.composite.record(gpu, &mut enc, t.generation * 2 + denoise as u64, &t.gbuffer, &t.trace, &fb, size, self.timer.as_mut())?;
        drop(pass);
        if let (Some(inputs), Some(chain)) = (&inputs, self.chain.as_mut()) {
            chain.record(gpu, &mut enc, chain_key, inputs, parity, size, true, self.timer.as_mut())?;
        }
        let shown = shown_buffers(t, &self.frame_buf, &self.display_buf, &self.no_accumulation, denoise);
        if let (Some(target), Some(d)) = (target, self.display.as_mut()) {
            let _pass = crate::profile::scope(crate::passes::composite::DISPLAY);
            d.record(gpu, &mut enc, t.generation * 2 + denoise as u64, &t.gbuffer, &t.trace, &shown, target.view, self.timer.as_mut())?;
        }
        if let (true, Some(m)) = (denoise, &t.matte) {
            let extent = wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 };
            enc.copy_texture_to_texture(t.gbuffer.depth.0.as_image_copy(), m.prev_depth.0.as_image_copy(), extent);
            enc.copy_texture_to_texture(t.gbuffer.color[0].0.as_image_copy(), m.prev_normal.0.as_image_copy(), extent);
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

    fn chain_inputs(&self) -> ChainInputs<'_> {
        let t = &self.targets;
        ChainInputs {
            frame: &self.frame_buf,
            params: &self.denoise_buf,
            objects: self.gpu_scene.objects.as_ref(),
            hdr: &t.hdr,
            gbuffer: &t.gbuffer,
            trace: &t.trace,
            matte: t.matte.as_ref().expect("matte targets exist before the chain"),
            glossy: t.glossy_chain.as_ref().map(|g| (g, &self.glossy_buf)),
        }
    }

    fn glossy_inputs(&self) -> Option<GlossyInputs<'_>> {
        glossy_inputs(&self.targets, &self.frame_buf, &self.denoise_buf, &self.glossy_buf, self.gpu_scene.objects.as_ref())
    }

    /// Draw the last frame again into `target` (another view, a screenshot) without rendering.
    pub fn redisplay(&mut self, gpu: &Gpu, settings: &FrameSettings, target: &DisplayTarget) -> Result<()> {
        gpu.validated("displaying the frame", || {
            self.prepare_display(gpu, target)?;
            // Only the view and exposure change; the rest of the uniform is the last frame's.
            gpu.queue.write_buffer(&self.frame_buf, std::mem::offset_of!(FrameParams, view) as u64, bytemuck::bytes_of(&(settings.view as u32)));
            gpu.queue.write_buffer(&self.frame_buf, std::mem::offset_of!(FrameParams, exposure) as u64, bytemuck::bytes_of(&settings.exposure_scale()));
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            let t = &self.targets;
            let fb = shown_buffers(t, &self.frame_buf, &self.display_buf, &self.no_accumulation, self.denoised_last);
            if let Some(d) = self.display.as_mut() {
                d.record(gpu, &mut enc, t.generation * 2 + self.denoised_last as u64, &t.gbuffer, &t.trace, &fb, target.view, None)?;
            }
            gpu.queue.submit([enc.finish()]);
            Ok(())
        })
    }

    /// The display's image of the last frame (tone-mapped or the chosen debug view) as 8-bit sRGB.
    pub fn display_image(&mut self, gpu: &Gpu, settings: &FrameSettings) -> Result<image::RgbaImage> {
        let (w, h) = self.targets.size;
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let tex = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("display image"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = tex.create_view(&Default::default());
        self.redisplay(gpu, settings, &DisplayTarget { view: &view, format, size: (w, h) })?;
        let bytes = crate::gpu::readback_texture(gpu, &tex)?;
        image::RgbaImage::from_raw(w, h, bytes).context("display image has the wrong size")
    }

    /// Make the display pass for `target`'s format (again when the denoiser's views appeared)
    /// and write its options.
    fn prepare_display(&mut self, gpu: &Gpu, target: &DisplayTarget) -> Result<()> {
        if self.display.as_ref().is_none_or(|d| d.format != target.format || d.with_denoise != self.targets.matte.is_some()) {
            let fb = shown_buffers(&self.targets, &self.frame_buf, &self.display_buf, &self.no_accumulation, self.denoised_last);
            self.display = Some(DisplayPass::new(gpu, &self.targets.gbuffer, &self.targets.trace, &fb, target.format).context("creating the display pass")?);
        }
        let srgb = !target.format.is_srgb() as u32;
        gpu.queue.write_buffer(&self.display_buf, 0, bytemuck::cast_slice(&[srgb, 0, target.size.0, target.size.1]));
        Ok(())
    }

    /// GPU milliseconds per pass of the last frame (blocks until it finished); empty without
    /// timestamp queries.
    pub fn pass_times(&self, gpu: &Gpu) -> Result<Vec<(&'static str, f64)>> {
        Ok(self.pass_spans(gpu)?.into_iter().map(|s| (s.label, s.ms)).collect())
    }

    /// Each pass of the last frame with its start and duration (blocks until it finished); when
    /// puffin's scopes are on, also reported as the frame's GPU timeline.
    pub fn pass_spans(&self, gpu: &Gpu) -> Result<Vec<crate::profile::PassSpan>> {
        let Some(t) = &self.timer else { return Ok(vec![]) };
        let spans = t.read_spans(gpu)?;
        crate::profile::report_gpu(t.submitted_ns, &spans);
        Ok(spans)
    }

    /// Keep per-pass times for [`Renderer::poll_pass_spans`] instead of [`Renderer::pass_spans`]
    /// (the viewer: reading times back never waits for the GPU).
    pub fn set_async_timings(&mut self, on: bool) {
        self.async_timings = on;
    }

    /// The passes of the oldest frame that finished since the last call, without waiting
    /// (frames with async timings on); reported to puffin as that frame's GPU timeline.
    pub fn poll_pass_spans(&mut self, gpu: &Gpu) -> Option<Vec<crate::profile::PassSpan>> {
        let (submitted, spans) = self.timer.as_mut()?.poll(gpu)?;
        crate::profile::report_gpu(submitted, &spans);
        Some(spans)
    }

    /// Frames summed in accumulate mode (0 when off).
    pub fn accumulated(&self) -> u32 {
        self.accumulated
    }

    /// The last frame's linear HDR image (after composite), or in accumulate mode the mean.
    pub fn read_hdr(&self, gpu: &Gpu) -> Result<Image> {
        let (w, h) = self.targets.size;
        let n = w as u64 * h as u64 * 16;
        let shown = self.targets.matte.as_ref().filter(|_| self.denoised_last).map_or(&self.targets.hdr, |m| &m.final_image);
        let (buf, scale) = match (&self.targets.accumulation, self.accumulated) {
            (Some(a), k) if k > 0 => (a, 1.0 / k as f32),
            _ => (shown, 1.0),
        };
        let bytes = crate::gpu::readback_buffer(&gpu.device, &gpu.queue, buf, n)?;
        let v: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let mut img = Image::new(w, h);
        for (d, s) in img.data.iter_mut().zip(v) {
            *d = Vec3::new(s[0], s[1], s[2]) * scale;
        }
        Ok(img)
    }

    /// Read a G-buffer or trace texture back as raw bytes, rows tightly packed.
    pub fn read_texture(&self, gpu: &Gpu, name: &str) -> Result<(Vec<u8>, wgpu::TextureFormat)> {
        let t = &self.targets;
        let tex = match name {
            "gbuffer/depth" => &t.gbuffer.depth.0,
            "trace/matte" => &t.trace.matte.0,
            "trace/direct" => &t.trace.direct.0,
            n if n.starts_with("matte/") || n.starts_with("taa/") => {
                let m = t.matte.as_ref().with_context(|| format!("no texture {n}: the denoiser has not run"))?;
                match n {
                    "matte/history 0" => &m.history[0].0,
                    "matte/history 1" => &m.history[1].0,
                    "matte/temporal" => &m.temporal.0,
                    "matte/reason" => &m.reason.0,
                    "matte/radius" => &m.radius.0,
                    "matte/firefly" => &m.median.0,
                    "matte/bilateral" => &m.denoised.0,
                    "taa/history 0" => &m.taa_history[0].0,
                    "taa/history 1" => &m.taa_history[1].0,
                    "taa/material 0" => &m.taa_material[0].0,
                    "taa/material 1" => &m.taa_material[1].0,
                    "taa/residual 0" => &m.taa_residual[0].0,
                    "taa/residual 1" => &m.taa_residual[1].0,
                    "taa/glossy 0" => &m.taa_glossy[0].0,
                    "taa/glossy 1" => &m.taa_glossy[1].0,
                    _ => bail!("no texture {n}"),
                }
            }
            n if n.starts_with("glossy/") => {
                let g = t.glossy_chain.as_ref().with_context(|| format!("no texture {n}: the glossy chain has not run"))?;
                match n {
                    "glossy/hit 0" => &g.hit[0].0,
                    "glossy/hit 1" => &g.hit[1].0,
                    "glossy/motion" => &g.motion.0,
                    "glossy/search" => &g.search.0,
                    "glossy/neighbourhood" => &g.neighbourhood.0,
                    "glossy/scratch" => &g.scratch.0,
                    "glossy/history 0" => &g.history[0].0,
                    "glossy/history 1" => &g.history[1].0,
                    "glossy/info" => &g.info.0,
                    "glossy/denoised" => &g.denoised.0,
                    _ => bail!("no texture {n}"),
                }
            }
            n if n.starts_with("gbuffer/") => &t.gbuffer.color[gbuffer::COLOR_FORMATS.iter().position(|(l, _)| *l == n).with_context(|| format!("no texture {n}"))?].0,
            n => {
                let g = t.trace.glossy.as_ref().with_context(|| format!("no texture {n}: the scene has no glossy buffers"))?;
                match n {
                    "trace/glossy" => &g.light.0,
                    "trace/reflection" => &g.reflection.0,
                    "trace/mirror" => &g.mirror.0,
                    "trace/mirror hit" => &g.mirror_hit.0,
                    _ => bail!("no texture {n}"),
                }
            }
        };
        Ok((crate::gpu::readback_texture(gpu, tex)?, tex.format()))
    }
}

/// What the display reads: the image after TAA when the denoiser ran, else the composite's;
/// the raw matte light; the denoiser's intermediates for its views.
fn shown_buffers<'a>(t: &'a Targets, frame: &'a wgpu::Buffer, display: &'a wgpu::Buffer, no_accumulation: &'a wgpu::Buffer, denoised: bool) -> FrameBuffers<'a> {
    FrameBuffers {
        frame,
        hdr: t.matte.as_ref().filter(|_| denoised).map_or(&t.hdr, |m| &m.final_image),
        accumulation: t.accumulation.as_ref().unwrap_or(no_accumulation),
        display,
        matte: &t.trace.matte.1,
        glossy: None,
        denoise: t.matte.as_ref(),
        glossy_chain: t.glossy_chain.as_ref(),
    }
}

/// What the glossy chain binds, when its targets exist.
fn glossy_inputs<'a>(t: &'a Targets, frame: &'a wgpu::Buffer, denoise: &'a wgpu::Buffer, params: &'a wgpu::Buffer, objects: Option<&'a wgpu::Buffer>) -> Option<GlossyInputs<'a>> {
    Some(GlossyInputs { frame, denoise, params, objects, gbuffer: &t.gbuffer, trace: &t.trace, matte: t.matte.as_ref()?, glossy: t.glossy_chain.as_ref()? })
}

/// Halton (2, 3) sub-pixel positions, 64 per cycle: the TAA jitter. A still pixel averages up
/// to `taa_still_frames` (64) of them, so the cycle is that long: the first 16 points cover a
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
