//! `cache/*`: the radiance cache, a world-space hash table of the matte light on surfaces
//! (shaders/cache/*.wgsl; the design of NVIDIA's SHaRC and Bevy Solari's world cache, written for
//! Hush's frame). It runs between the trace and the denoiser:
//!
//! 1. `cache/gather`, per pixel: for a pixel the last frame did not see, its prior (its cell's
//!    mean as the frames before left it, and how many frames' worth of samples it stands for,
//!    where the cell's centroid is in sight of the pixel) into `cache/prior`, then the pixel's
//!    own matte sample added to its cell.
//! 2. `cache/secondary`, per tile: one cosine ray from a pixel's surface, and at the surface it
//!    hits one estimate of the matte light added to that surface's cell, so that cells behind
//!    what the camera sees fill before a move uncovers them.
//! 3. `cache/resolve`, per cell: the frame's samples folded into each cell's running mean; cells
//!    without a sample for `max_age_frames` frames are freed.
//!
//! A denoiser's temporal stage reads `cache_prior` (cache/prior.wgsl) where a pixel's matte
//! history restarts: the pixel then starts from its cell's mean weighted as that many frames,
//! instead of from one sample. The table lives across resizes (its cells are in world space);
//! it is cleared when the cache starts again after frames without it.
//!
//! Memory: [`CELL_BYTES`] per cell (65536 cells by default: 4.75 MiB), and 16 bytes per pixel
//! (the prior, Rgba16Float; its samples' mean squared luminance, R32Float; the cell's slot,
//! R32Uint, which the tests read).

use super::io::FrameIo;
use super::scene::SceneInputs;
use crate::gpu::{BindCache, BindKey, Bindings, Gpu, GpuMemory, Recorder, Tex, set_compute_groups};
use crate::settings::{CacheSettings, MAX_CELLS_LOG2};
use crate::shader::{Reload, Reloadable, compute_pipeline};
use anyhow::Result;
use bytemuck::{Pod, Zeroable};

pub const GATHER: &str = "cache/gather";
pub const SECONDARY: &str = "cache/secondary";
pub const RESOLVE: &str = "cache/resolve";
pub const PRIOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const PRIOR_M2_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
pub const CELL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// A cell's bytes: its key (4), this frame's fixed-point sums of light, light-weighted position,
/// squared luminance and light weight and its count (36), its mean and sample count (16), its
/// centroid and mean squared luminance (16) and its age (4).
pub const CELL_BYTES: u64 = 76;
/// The slot `cache/cell` holds for a pixel without a cell (shaders/cache/cells.wgsl).
pub const NO_CELL: u32 = u32::MAX;
/// Fixed-point units per unit of displayed white, and the clamp of one sample in displayed
/// whites (shaders/cache/cells.wgsl): 2^18 units a sample, so 2^14 samples fit a cell's frame.
const FIXED_PER_WHITE: f32 = 4096.0;
const CLAMP_WHITES: f32 = 64.0;
const RESOLVE_GROUP: u32 = 256;

/// Mirror of `CacheParams` in shaders/cache/cells.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CacheParams {
    pub capacity: u32,
    pub cell_pixels: f32,
    pub max_samples: f32,
    pub max_age: u32,
    pub prior_frames: f32,
    pub update_tile: u32,
    pub fixed_scale: f32,
    pub sample_clamp: f32,
    pub path_end_samples: f32,
    pub path_end_error: f32,
    pub pad: [f32; 2],
}

impl CacheParams {
    /// The settings for a table of 2^`log2` cells; `exposure` (2^EV) sets the fixed point's unit
    /// so that it is a fixed fraction of the displayed white whatever the scene's units.
    pub fn new(s: &CacheSettings, log2: u32, exposure: f32) -> CacheParams {
        let exposure = if exposure.is_finite() && exposure > 0.0 { exposure } else { 1.0 };
        CacheParams {
            capacity: 1 << log2,
            cell_pixels: s.cell_pixels.clamp(1.0, 32.0),
            max_samples: s.max_samples.clamp(1.0, 65536.0),
            max_age: s.max_age_frames.max(1),
            prior_frames: s.prior_frames.clamp(0.0, 256.0),
            update_tile: s.update_tile.min(64),
            fixed_scale: FIXED_PER_WHITE * exposure,
            sample_clamp: CLAMP_WHITES / exposure,
            path_end_samples: s.path_end_samples.clamp(0.0, 65536.0),
            path_end_error: s.path_end_error.clamp(0.0, 100.0),
            pad: [0.0; 2],
        }
    }
}

/// The table's buffers (not per pixel: they live across resizes).
pub struct CacheCells {
    pub log2: u32,
    pub params: wgpu::Buffer,
    pub keys: wgpu::Buffer,
    pub sums: wgpu::Buffer,
    pub cells: wgpu::Buffer,
    pub centroids: wgpu::Buffer,
    pub ages: wgpu::Buffer,
    pub memory: GpuMemory,
}

impl CacheCells {
    fn new(gpu: &Gpu, log2: u32) -> CacheCells {
        let log2 = log2.clamp(10, MAX_CELLS_LOG2);
        let n = 1u64 << log2;
        let mut memory = GpuMemory::default();
        let d = &gpu.device;
        let storage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        let uniform = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        let params = memory.buffer(d, "cache/params", size_of::<CacheParams>() as u64, uniform);
        let keys = memory.buffer(d, "cache/keys", n * 4, storage);
        let sums = memory.buffer(d, "cache/sums", n * 36, storage);
        let cells = memory.buffer(d, "cache/cells", n * 16, storage);
        let centroids = memory.buffer(d, "cache/centroids", n * 16, storage);
        let ages = memory.buffer(d, "cache/ages", n * 4, storage);
        CacheCells { log2, params, keys, sums, cells, centroids, ages, memory }
    }

    /// The table's buffers by the names shaders/cache/cells.wgsl declares.
    pub fn bindings<'a>(&'a self, b: Bindings<'a>) -> Bindings<'a> {
        b.buffer("cache", &self.params)
            .buffer("cache_keys", &self.keys)
            .buffer("cache_sums", &self.sums)
            .buffer("cache_cells", &self.cells)
            .buffer("cache_centroids", &self.centroids)
            .buffer("cache_ages", &self.ages)
    }

    fn clear(&self, enc: &mut wgpu::CommandEncoder) {
        for b in [&self.keys, &self.sums, &self.cells, &self.centroids, &self.ages] {
            enc.clear_buffer(b, 0, None);
        }
    }
}

/// The cache's per-pixel outputs, in the frame's targets (remade on resize).
pub struct CacheTargets {
    pub prior: Tex,
    pub prior_m2: Tex,
    pub cell: Tex,
    pub epoch: u64,
}

impl CacheTargets {
    pub const PREFIX: &str = "cache/";

    pub fn new(d: &wgpu::Device, mem: &mut GpuMemory, size: (u32, u32), epoch: u64) -> Self {
        let usage = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        CacheTargets {
            prior: mem.texture(d, "cache/prior", size, PRIOR_FORMAT, usage),
            prior_m2: mem.texture(d, "cache/prior m2", size, PRIOR_M2_FORMAT, usage),
            cell: mem.texture(d, "cache/cell", size, CELL_FORMAT, usage),
            epoch,
        }
    }
}

/// One of the cache's passes: its pipeline and bind groups.
struct Pass {
    label: &'static str,
    pipeline: Reloadable<wgpu::ComputePipeline>,
    groups: BindCache,
}

impl Pass {
    fn new(label: &'static str, pipeline: Reloadable<wgpu::ComputePipeline>) -> Pass {
        Pass { label, pipeline, groups: BindCache::default() }
    }

    /// Dispatch `groups` workgroups with what `offered` binds.
    fn record(
        &mut self,
        rec: &mut Recorder,
        key: BindKey,
        offered: &Bindings,
        groups: (u32, u32),
    ) -> Result<()> {
        let _scope = crate::profile::scope(self.label);
        let p = &self.pipeline;
        let device = &rec.gpu.device;
        let g = self.groups.get(key, p.builds(), (), |_| p.bind_groups(device, offered))?;
        let mut pass = rec.compute_pass(self.label);
        pass.set_pipeline(p.get());
        set_compute_groups(&mut pass, g);
        pass.dispatch_workgroups(groups.0, groups.1, 1);
        Ok(())
    }
}

/// The gather and secondary programs (the trace's scene program with the cache's entries).
struct Programs {
    gather: Pass,
    secondary: Pass,
}

/// The radiance cache stage: its table and its programs (made on first use).
#[derive(Default)]
pub struct RadianceCache {
    cells: Option<CacheCells>,
    /// Static and moving-shutter programs.
    programs: [Option<Programs>; 2],
    resolve: Option<Pass>,
    /// The frame the cache last ran in: a gap means its cells are stale.
    last_frame: Option<u32>,
}

/// What the gather and secondary passes read and write.
pub struct CacheInputs<'a> {
    pub scene: SceneInputs<'a>,
    pub io: &'a FrameIo<'a>,
    pub targets: &'a CacheTargets,
}

fn scene_bindings<'a>(i: &CacheInputs<'a>, cells: &'a CacheCells) -> Bindings<'a> {
    let matte = i.io.mixed.map_or(&i.io.trace.matte.1, |m| &m.matte.1);
    let b = i
        .scene
        .bindings()
        .texture("gb_ids", i.io.gbuffer.view(super::gbuffer::Channel::Ids))
        .texture("tr_matte", matte)
        .texture_opt("prev_depth", i.io.previous.map(|p| &p.depth.1))
        .texture("out_prior", &i.targets.prior.1)
        .texture("out_prior_m2", &i.targets.prior_m2.1)
        .texture("out_cell", &i.targets.cell.1);
    cells.bindings(b)
}

fn scene_program(
    gpu: &Gpu,
    i: &CacheInputs,
    cells: &CacheCells,
    label: &'static str,
    entry: &'static str,
) -> Result<Reloadable<wgpu::ComputePipeline>> {
    let scene = i.scene.scene;
    let mut modules = with_path_ends(scene.shading_modules_for(i.scene.moving));
    modules.extend([
        "realtime/frame.wgsl",
        "realtime/lens.wgsl",
        "realtime/area_light.wgsl",
        "realtime/seen.wgsl",
        "cache/update.wgsl",
    ]);
    Reloadable::new(
        gpu,
        label,
        &scene.prelude(),
        &modules,
        wgpu::ShaderStages::COMPUTE,
        &scene_bindings(i, cells),
        move |d, m, l| compute_pipeline(d, label, m, l, entry),
    )
}

impl RadianceCache {
    /// The table for `settings`, made (or remade for another size) before the frame records;
    /// true when it was, so that the frame's bind groups are made again.
    pub fn prepare(&mut self, gpu: &Gpu, settings: &CacheSettings, exposure: f32) -> bool {
        let log2 = settings.cells_log2.clamp(10, MAX_CELLS_LOG2);
        let remade = self.cells.as_ref().is_none_or(|c| c.log2 != log2);
        if remade {
            self.cells = Some(CacheCells::new(gpu, log2));
            self.last_frame = None;
        }
        if let Some(c) = &self.cells {
            let p = CacheParams::new(settings, c.log2, exposure);
            gpu.queue.write_buffer(&c.params, 0, bytemuck::bytes_of(&p));
        }
        remade
    }

    /// The table's buffers, once made.
    pub fn cells(&self) -> Option<&CacheCells> {
        self.cells.as_ref()
    }

    /// The table as frame `index` may read it before the cache records (the trace's path
    /// ends): only where the cache ran in the frame before, since a gap leaves stale cells,
    /// which the cache clears when it records.
    pub fn live_cells(&self, index: u32) -> Option<&CacheCells> {
        self.cells.as_ref().filter(|_| self.last_frame == Some(index.wrapping_sub(1)))
    }

    /// Record gather, secondary and resolve for frame `index`.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        key: BindKey,
        i: &CacheInputs,
        settings: &CacheSettings,
        index: u32,
    ) -> Result<()> {
        let Some(cells) = self.cells.as_ref() else { return Ok(()) };
        if self.last_frame != Some(index.wrapping_sub(1)) {
            cells.clear(rec.enc);
        }
        self.last_frame = Some(index);
        let gpu = rec.gpu;
        let moving = i.scene.moving as usize;
        let p = super::chain::made(&mut self.programs[moving], || {
            Ok(Programs {
                gather: Pass::new(GATHER, scene_program(gpu, i, cells, GATHER, "gather")?),
                secondary: Pass::new(
                    SECONDARY,
                    scene_program(gpu, i, cells, SECONDARY, "secondary")?,
                ),
            })
        })?;
        let size = i.io.size;
        let offered = scene_bindings(i, cells);
        p.gather.record(rec, key, &offered, (size.0.div_ceil(8), size.1.div_ceil(8)))?;
        let tile = settings.update_tile.min(64);
        if tile > 0 {
            let tiles = (size.0.div_ceil(tile), size.1.div_ceil(tile));
            p.secondary.record(rec, key, &offered, (tiles.0.div_ceil(8), tiles.1.div_ceil(8)))?;
        }
        let offered = cells.bindings(Bindings::new());
        let resolve = super::chain::made(&mut self.resolve, || {
            let modules =
                ["common/math.wgsl", "common/rng.wgsl", "cache/cells.wgsl", "cache/resolve.wgsl"];
            let r = Reloadable::new(
                gpu,
                RESOLVE,
                "",
                &modules,
                wgpu::ShaderStages::COMPUTE,
                &offered,
                |d, m, l| compute_pipeline(d, RESOLVE, m, l, "resolve"),
            )?;
            Ok(Pass::new(RESOLVE, r))
        })?;
        resolve.record(rec, key, &offered, ((1u32 << cells.log2).div_ceil(RESOLVE_GROUP), 1))?;
        Ok(())
    }

    /// Its pipelines, for hot reload.
    pub fn pipelines(&mut self) -> Vec<&mut dyn Reload> {
        let mut v: Vec<&mut dyn Reload> = vec![];
        for p in self.programs.iter_mut().flatten() {
            v.push(&mut p.gather.pipeline);
            v.push(&mut p.secondary.pipeline);
        }
        if let Some(r) = self.resolve.as_mut() {
            v.push(&mut r.pipeline);
        }
        v
    }
}

/// Shading modules whose paths may end in the cache: cache/path_end.wgsl (with the cells it
/// reads) in the place of [`crate::gpu::PATH_END_NONE`].
pub fn with_path_ends(mut modules: Vec<&'static str>) -> Vec<&'static str> {
    modules.retain(|m| *m != crate::gpu::PATH_END_NONE);
    modules.extend(["cache/cells.wgsl", "cache/path_end.wgsl"]);
    modules
}

/// The module a denoiser's temporal stage reads the prior from: cache/prior.wgsl where the frame
/// offers one, else cache/prior_none.wgsl (no binding, a prior of nothing).
pub fn prior_module(io: &FrameIo) -> &'static str {
    if io.cache_prior.is_some() { "cache/prior.wgsl" } else { "cache/prior_none.wgsl" }
}
