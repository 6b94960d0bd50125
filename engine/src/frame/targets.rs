//! The frame's per-pixel targets and uniforms: what a frame plan allocates and every stage
//! binds.

use super::FrameParams;
use crate::gpu::GpuScene;
use crate::gpu::{Gpu, GpuMemory};
use crate::passes::cache::CacheTargets;
use crate::passes::composite::FrameBuffers;
use crate::passes::gbuffer::GBufferTargets;
use crate::passes::io::{FrameIo, PreviousGBuffer};
use crate::passes::prefilter::PrefilterTargets;
use crate::passes::primaries::PrimaryTargets;
use crate::passes::reference::TraceParams;
use crate::passes::supersample::SupersampleTargets;
use crate::passes::trace::TraceTargets;
use crate::settings::FrameSettings;

/// Per-pixel targets of the frame, remade on resize.
pub(super) struct Targets {
    pub size: (u32, u32),
    pub gbuffer: GBufferTargets,
    pub trace: TraceTargets,
    pub hdr: wgpu::Buffer,
    pub accumulation: Option<wgpu::Buffer>,
    /// Made when a denoiser that reads the previous frame's G-buffer first runs.
    pub previous: Option<PreviousGBuffer>,
    /// Made for k > 1 samples per pixel (remade when k changes).
    pub supersample: Option<SupersampleTargets>,
    /// Made when a thin lens or a moving shutter is first rendered (traced primaries), and when
    /// the pre-filter first runs.
    pub primaries: Option<PrimaryTargets>,
    pub prefilter: Option<PrefilterTargets>,
    /// The radiance cache's per-pixel outputs, made when it first runs.
    pub cache: Option<CacheTargets>,
    /// Every per-pixel allocation, the denoisers' and TAA's included: bytes per pixel, and
    /// textures by label for readback.
    pub memory: GpuMemory,
    /// Which set of targets this is (one per size): stages allocate again when it changes.
    pub epoch: u64,
    /// Bumped whenever a target is added or replaced, so bind groups are remade.
    pub generation: u64,
}

impl Targets {
    pub fn new(gpu: &Gpu, size: (u32, u32), glossy: bool, epoch: u64, generation: u64) -> Targets {
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
            cache: None,
            memory,
            epoch,
            generation,
        }
    }

    pub fn io<'a>(&'a self, frame: &'a wgpu::Buffer, scene: &'a GpuScene) -> FrameIo<'a> {
        FrameIo {
            size: self.size,
            frame,
            objects: scene.objects.as_ref(),
            vertices: scene.tri_prev_texels.as_ref().map(|t| (&scene.tri_texels.view, &t.view)),
            gbuffer: &self.gbuffer,
            previous: self.previous.as_ref(),
            trace: &self.trace,
            mixed: None,
            cache_prior: None,
            feature_uncertainty: None,
            hdr: &self.hdr,
            memory: &self.memory,
        }
    }

    /// The accumulation buffer of the accumulate mode (made on first use).
    pub fn ensure_accumulation(&mut self, gpu: &Gpu) {
        if self.accumulation.is_none() {
            let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
            let bytes = self.size.0 as u64 * self.size.1 as u64 * 16;
            let b = self.memory.buffer(&gpu.device, "composite/accumulation", bytes, usage);
            self.accumulation = Some(b);
            self.generation += 1;
        }
    }

    /// The previous frame's G-buffer copy a denoiser reads (made on first use).
    pub fn ensure_previous(&mut self, gpu: &Gpu) {
        if self.previous.is_none() {
            self.previous = Some(PreviousGBuffer::new(&gpu.device, &mut self.memory, self.size));
            self.generation += 1;
        }
    }

    /// The supersampling's targets for `k` samples per pixel (remade when k changes).
    pub fn ensure_supersample(&mut self, gpu: &Gpu, k: u32, glossy: bool) {
        if self.supersample.as_ref().is_some_and(|s| s.k == k && s.epoch == self.epoch) {
            return;
        }
        self.memory.forget(SupersampleTargets::PREFIX);
        let (d, size, epoch) = (&gpu.device, self.size, self.epoch);
        let t = SupersampleTargets::new(d, &mut self.memory, size, k, glossy, epoch);
        self.supersample = Some(t);
        self.generation += 1;
    }

    /// The traced primaries' targets, and with `prefilter` the pre-filter's.
    pub fn ensure_primaries(&mut self, gpu: &Gpu, prefilter: bool) {
        let (d, size, epoch) = (&gpu.device, self.size, self.epoch);
        if self.primaries.as_ref().is_none_or(|p| p.epoch != epoch) {
            self.memory.forget(PrimaryTargets::PREFIX);
            self.primaries = Some(PrimaryTargets::new(d, &mut self.memory, size, epoch));
            self.generation += 1;
        }
        if prefilter && self.prefilter.as_ref().is_none_or(|p| p.epoch != epoch) {
            self.memory.forget(PrefilterTargets::PREFIX);
            self.prefilter = Some(PrefilterTargets::new(d, &mut self.memory, size, epoch));
            self.generation += 1;
        }
    }

    /// The radiance cache's per-pixel outputs (made on first use).
    pub fn ensure_cache(&mut self, gpu: &Gpu) {
        if self.cache.as_ref().is_none_or(|c| c.epoch != self.epoch) {
            self.memory.forget(CacheTargets::PREFIX);
            self.cache =
                Some(CacheTargets::new(&gpu.device, &mut self.memory, self.size, self.epoch));
            self.generation += 1;
        }
    }

    /// The texture `settings.view` shows, among this frame's and `upscaler`'s (the upscaler's
    /// shown-size targets), if it has it (a denoiser's view is black until the denoiser has
    /// run), and its index in the view list + 1 (0: none), which the display's bind groups are
    /// keyed on.
    pub fn view_texture<'a>(
        &'a self,
        settings: &FrameSettings,
        upscaler: &'a GpuMemory,
    ) -> (Option<&'a wgpu::Texture>, usize) {
        let views = crate::settings::all_views();
        let Some(i) = views.iter().position(|v| v.name == settings.view.name()) else {
            return (None, 0);
        };
        let label = views[i].texture;
        match self.memory.find_texture(label).or_else(|| upscaler.find_texture(label)) {
            Some(tex) => (Some(tex), i + 1),
            None => (None, 0),
        }
    }
}

/// The frame's uniforms and the small buffers every frame binds.
pub(super) struct Uniforms {
    /// `TraceParams` (shaders/common/params.wgsl): the scene's camera and lights.
    pub params: wgpu::Buffer,
    /// `FrameParams` (shaders/realtime/frame.wgsl).
    pub frame: wgpu::Buffer,
    /// The display's options (the view's map, sRGB, target size).
    pub display: wgpu::Buffer,
    /// Bound where accumulation is off, so the composite's layout stays the same.
    pub no_accumulation: wgpu::Buffer,
    /// Their allocations (and TAA's parameters), for the report.
    pub memory: GpuMemory,
}

impl Uniforms {
    pub fn new(gpu: &Gpu) -> Uniforms {
        let mut memory = GpuMemory::default();
        let u = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        let d = &gpu.device;
        let params = memory.buffer(d, "frame/scene params", size_of::<TraceParams>() as u64, u);
        let frame = memory.buffer(d, "frame/params", size_of::<FrameParams>() as u64, u);
        let display = memory.buffer(d, "display/options", 32, u);
        let storage = wgpu::BufferUsages::STORAGE;
        let no_accumulation = memory.buffer(d, "composite/no accumulation", 16, storage);
        Uniforms { params, frame, display, no_accumulation, memory }
    }

    /// What the display reads: the image after TAA when a denoiser ran, else the composite's.
    pub fn shown<'a>(
        &'a self,
        t: &'a Targets,
        io: &FrameIo<'a>,
        after_taa: Option<&'a wgpu::Buffer>,
    ) -> FrameBuffers<'a> {
        FrameBuffers {
            io: *io,
            shown: after_taa.unwrap_or(&t.hdr),
            accumulation: t.accumulation.as_ref().unwrap_or(&self.no_accumulation),
            display: &self.display,
            matte: None,
            glossy: None,
            direct: None,
        }
    }
}
