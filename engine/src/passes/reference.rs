//! `reference/trace`: the progressive reference path tracer (shaders/reference/trace.wgsl).

use crate::gpu::{Gpu, GpuMemory, GpuScene, PreparedScene, readback_buffer};
use crate::quality::Image;
use crate::scene::Camera;
use anyhow::{Result, bail};
use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};

pub const LABEL: &str = "reference/trace";

/// Mirror of `Params` in shaders/reference/params.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TraceParams {
    pub width: u32,
    pub height: u32,
    pub sample_index: u32,
    pub seed: u32,
    pub max_depth: i32,
    pub rr_depth: i32,
    pub num_lights: u32,
    pub num_emitters: u32,
    pub cam_pos: [f32; 4],
    pub cam_right: [f32; 4],
    pub cam_up: [f32; 4],
    pub cam_fwd: [f32; 4],
    pub env_radiance: [f32; 4],
    pub env_rot: [f32; 4],
    pub env_size: [u32; 4],
    /// Thin lens: aperture radius and focus distance in scene units (0: a pinhole), unused, unused.
    pub lens: [f32; 4],
    /// x: samples per pixel this dispatch traces (the reference tracer), from sample_index on;
    /// y, z, w unused.
    pub batch: [u32; 4],
    /// The camera at the shutter's open, as cam_pos .. cam_fwd hold it at the close (the same
    /// without motion blur).
    pub cam_open_pos: [f32; 4],
    pub cam_open_right: [f32; 4],
    pub cam_open_up: [f32; 4],
    pub cam_open_fwd: [f32; 4],
    /// x: 1 where the shutter is open for a while (each path a random time in it), 0 for an
    /// instant exposure (every ray at the close).
    pub shutter: [f32; 4],
    /// x: 1 where ray cones choose texture mip levels after the primary hit, 0: the finest.
    /// y: 1 where the real-time trace draws the light's point and the matte path's first
    /// direction from the screen's strata ([`crate::settings::FrameSettings::screen_strata`]).
    pub switches: [f32; 4],
}

/// What to render: the camera, image size and path settings.
#[derive(Clone, Copy, Debug)]
pub struct TraceView {
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    /// Mitsuba's max_depth (-1 = unbounded).
    pub max_depth: i32,
    pub seed: u32,
    /// Motion blur: the camera at the shutter's open (`camera` is at its close); objects move
    /// as [`PreparedScene::expose`] set them up.
    pub shutter_camera: Option<Camera>,
    /// Ray cones choose texture mip levels after the primary hit
    /// ([`crate::settings::FrameSettings::texture_lod`]).
    pub texture_lod: bool,
}

impl TraceView {
    /// A still view (no shutter) of `size` pixels through `camera`, ray cones on: the renders
    /// that do not animate start here.
    pub fn new(camera: Camera, (width, height): (u32, u32), max_depth: i32, seed: u32) -> Self {
        TraceView {
            camera,
            width,
            height,
            max_depth,
            seed,
            shutter_camera: None,
            texture_lod: true,
        }
    }
}

/// Russian roulette starts after this many segments (Mitsuba's rr_depth).
pub const RR_DEPTH: i32 = 5;

/// The mean image and what is known of its noise.
pub struct Accumulation {
    pub samples: u32,
    pub mean: Image,
    /// Per-pixel variance of the mean (sample variance / N), per channel.
    pub variance_of_mean: Image,
    /// Samples that came out NaN or Inf and were dropped (should be 0).
    pub nonfinite_samples: u64,
}

pub struct ReferenceTracer {
    pipeline: wgpu::ComputePipeline,
    bind_groups: Vec<wgpu::BindGroup>,
    params_buf: wgpu::Buffer,
    accum: wgpu::Buffer,
    params: TraceParams,
    pub samples: u32,
    pub memory: GpuMemory,
}

/// Samples per pixel one dispatch traces at most, and the paths one dispatch traces at most
/// (whichever is fewer). Each invocation starts its pixel's next sample as soon as a path ends,
/// so a SIMD group waits for its longest path once per dispatch instead of once per sample, and
/// the per-dispatch cost is paid once. Reference tracer on the software driver, M samples/s at
/// 1, 8 and 32 samples a dispatch: cornell_diffuse 1.13 / 1.23 / 1.35, point_glossy 0.97 /
/// 1.03 / 1.09. The path cap keeps a dispatch short (about 2 s on the software driver, far less
/// on a GPU, whose driver may reset a dispatch that runs for seconds).
pub const BATCH: u32 = 32;
pub const BATCH_PATHS: u64 = 1 << 21;

/// Largest image side the tracer accepts (one dispatch covers it).
pub const MAX_SIDE: u32 = 16384;

impl ReferenceTracer {
    pub fn new(
        gpu: &Gpu,
        prepared: &PreparedScene,
        scene: &GpuScene,
        view: &TraceView,
    ) -> Result<ReferenceTracer> {
        let (w, h) = (view.width, view.height);
        if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
            bail!("image size {w}x{h} is out of range (1..={MAX_SIDE} per side)");
        }
        let mut modules = scene.shading_modules_for(prepared.shutter_moves());
        modules.push("reference/trace.wgsl");
        let mut memory = GpuMemory::default();
        let accum = memory.buffer(
            &gpu.device,
            "reference/accumulation",
            w as u64 * h as u64 * 32,
            wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
        );
        let params_buf = memory.buffer(
            &gpu.device,
            "reference/params",
            std::mem::size_of::<TraceParams>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let resources = scene.bindings().buffer("params", &params_buf).buffer("accum", &accum);
        let fixed = crate::shader::FixedCompute::new(
            gpu,
            LABEL,
            &scene.prelude(),
            &modules,
            &resources.names().collect::<Vec<_>>(),
        )?;
        let bind_groups = fixed.bind_groups(&gpu.device, &resources)?;
        let pipeline = fixed.pipeline;
        let params = make_params(prepared, view);
        Ok(ReferenceTracer { pipeline, bind_groups, params_buf, accum, params, samples: 0, memory })
    }

    /// Start over (new camera or settings).
    pub fn reset(&mut self, gpu: &Gpu, prepared: &PreparedScene, view: &TraceView) {
        let (w, h) = (self.params.width, self.params.height);
        self.params = make_params(prepared, view);
        self.params.width = w;
        self.params.height = h;
        self.samples = 0;
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&self.accum, 0, None);
        gpu.queue.submit([enc.finish()]);
    }

    /// Go on accumulating under a new camera or scene state (same size, same GPU scene buffers):
    /// the image becomes the mean over the states' samples, e.g. of stills over a shutter.
    pub fn set_view(&mut self, prepared: &PreparedScene, view: &TraceView) {
        let (w, h) = (self.params.width, self.params.height);
        self.params = make_params(prepared, view);
        self.params.width = w;
        self.params.height = h;
    }

    /// Record dispatches that add `count` samples per pixel; returns after submitting them. A
    /// dispatch traces up to [`BATCH`] samples per pixel and [`BATCH_PATHS`] paths.
    pub fn dispatch(&mut self, gpu: &Gpu, count: u32) {
        let pixels = self.params.width as u64 * self.params.height as u64;
        let most = (BATCH_PATHS / pixels).clamp(1, BATCH as u64) as u32;
        let mut left = count;
        while left > 0 {
            let batch = left.min(most);
            self.params.sample_index = self.samples;
            self.params.batch[0] = batch;
            gpu.queue.write_buffer(&self.params_buf, 0, bytemuck::bytes_of(&self.params));
            let mut enc = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(LABEL) });
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(LABEL),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.pipeline);
                crate::gpu::set_compute_groups(&mut pass, &self.bind_groups);
                pass.dispatch_workgroups(
                    self.params.width.div_ceil(8),
                    self.params.height.div_ceil(8),
                    1,
                );
            }
            gpu.queue.submit([enc.finish()]);
            self.samples += batch;
            left -= batch;
        }
    }

    /// The accumulation buffer (two vec4 per pixel: sum, sum of squares + dropped count).
    pub fn accumulation_buffer(&self) -> &wgpu::Buffer {
        &self.accum
    }

    pub fn size(&self) -> (u32, u32) {
        (self.params.width, self.params.height)
    }

    pub fn readback(&self, gpu: &Gpu) -> Result<Accumulation> {
        let (w, h) = self.size();
        let bytes =
            readback_buffer(&gpu.device, &gpu.queue, &self.accum, w as u64 * h as u64 * 32)?;
        let v: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let n = self.samples.max(1) as f32;
        let mut mean = Image::new(w, h);
        let mut var = Image::new(w, h);
        let mut bad = 0u64;
        for i in 0..(w * h) as usize {
            let s = Vec3::from_slice(&v[i * 2]);
            let s2 = Vec3::from_slice(&v[i * 2 + 1]);
            let m = s / n;
            mean.data[i] = m;
            let sample_var = ((s2 / n - m * m) * (n / (n - 1.0).max(1.0))).max(Vec3::ZERO);
            var.data[i] = sample_var / n;
            bad += v[i * 2 + 1][3] as u64;
        }
        Ok(Accumulation {
            samples: self.samples,
            mean,
            variance_of_mean: var,
            nonfinite_samples: bad,
        })
    }
}

pub(crate) fn make_params(p: &PreparedScene, view: &TraceView) -> TraceParams {
    let aspect = view.width as f32 / view.height as f32;
    let (pos, right, up, fwd) = camera_frame(p, &view.camera, aspect);
    let open = view.shutter_camera.map_or((pos, right, up, fwd), |c| camera_frame(p, &c, aspect));
    let moving = view.shutter_camera.is_some_and(|c| c != view.camera) || p.shutter_moves();
    let rot = p.env_rotation_y_degrees.to_radians();
    let cam = &view.camera;
    let e = p.ray_epsilon();
    TraceParams {
        width: view.width,
        height: view.height,
        sample_index: 0,
        seed: view.seed,
        max_depth: view.max_depth,
        rr_depth: RR_DEPTH,
        num_lights: p.lights.len() as u32,
        num_emitters: p.emitter_slots.len() as u32,
        cam_pos: pos.extend(e).to_array(),
        cam_right: right.extend(0.0).to_array(),
        cam_up: up.extend(0.0).to_array(),
        cam_fwd: fwd.extend(0.0).to_array(),
        env_radiance: p.env_radiance.extend(0.0).to_array(),
        env_rot: [rot.cos(), rot.sin(), p.env_pdf_norm, 0.0],
        env_size: p.env_size,
        lens: cam.lens.map_or([0.0; 4], |l| [l.aperture_radius, l.focus_distance, 0.0, 0.0]),
        batch: [1, 0, 0, 0],
        cam_open_pos: open.0.extend(e).to_array(),
        cam_open_right: open.1.extend(0.0).to_array(),
        cam_open_up: open.2.extend(0.0).to_array(),
        cam_open_fwd: open.3.extend(0.0).to_array(),
        shutter: [moving as u32 as f32, 0.0, 0.0, 0.0],
        switches: [view.texture_lod as u32 as f32, 0.0, 0.0, 0.0],
    }
}

/// A camera's position and ray frame in the GPU scene's rebased space: a pixel's direction is
/// fwd + x right + y up for x, y in [-1, 1].
fn camera_frame(p: &PreparedScene, cam: &Camera, aspect: f32) -> (Vec3, Vec3, Vec3, Vec3) {
    let m = cam.world;
    let pos = (m.transform_point3(DVec3::ZERO) - p.origin).as_vec3();
    let x = m.transform_vector3(DVec3::X).normalize_or_zero().as_vec3();
    let y = m.transform_vector3(DVec3::Y).normalize_or_zero().as_vec3();
    let z = m.transform_vector3(DVec3::Z).normalize_or_zero().as_vec3();
    let fov = if cam.yfov.is_finite() { cam.yfov.clamp(1e-4, 3.1) } else { 0.8 };
    let th = (fov * 0.5).tan();
    (pos, x * th * aspect, y * th, -z)
}
