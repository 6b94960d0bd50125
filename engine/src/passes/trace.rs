//! `trace`: one factored sample per pixel at the G-buffer's surfaces (shaders/realtime/trace.wgsl).
//!
//! Outputs and their cost per pixel: matte light and direct light (Rgba16Float, 8 bytes each);
//! in scenes with a specular lobe also the glossy light with its secondary hit distance
//! (Rgba16Float, 8), the virtual position with that distance (Rgba32Float, 16: positions need
//! f32), the representative mirror direction (two snorm16 in R32Uint, 4) and what the glossy
//! path hit first: its reflectance and normal (Rg32Uint, 8), which the glossy chain uses behind
//! mirrors (Voorhuis §4.1). The last three (28 bytes) are written only while a stage reads them
//! ([`TraceTargets::set_reflections`]).

use super::gbuffer::{Channel, GBufferTargets};
pub use super::scene::SceneInputs;
use crate::gpu::{BindCache, Bindings, Gpu, GpuMemory, Recorder, set_compute_groups};
use crate::shader::compute_pipeline;
use anyhow::Result;

pub const LABEL: &str = "trace";
pub const MATTE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const REFLECTION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Octahedral direction packed as two snorm16 (Rg16 is not a storage format in core WebGPU).
pub const MIRROR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// Reflectance as rgba8 and normal as octahedral snorm16x2.
pub const MIRROR_HIT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;

pub struct TraceTargets {
    pub matte: (wgpu::Texture, wgpu::TextureView),
    pub direct: (wgpu::Texture, wgpu::TextureView),
    pub glossy: Option<GlossyTargets>,
    /// The matte light sample's reservoirs (shaders/realtime/reservoir.wgsl): two 32-byte slots
    /// a pixel, this frame's and the last frame's, made only while the frame reuses light
    /// samples ([`TraceTargets::set_reservoirs`]).
    pub reservoirs: Option<wgpu::Buffer>,
}

/// The label of [`TraceTargets::reservoirs`].
pub const RESERVOIRS_LABEL: &str = "trace/reservoirs";
/// Bytes a pixel of [`TraceTargets::reservoirs`]: two `Reservoir`s of 32.
pub const RESERVOIR_BYTES: u64 = 64;

pub struct GlossyTargets {
    pub light: (wgpu::Texture, wgpu::TextureView),
    /// What the glossy chains reproject and demodulate with (Voorhuis §4): made only while a
    /// stage reads them ([`TraceTargets::set_reflections`]).
    pub reflections: Option<Reflections>,
}

/// The glossy path's reflection data: the virtual position with the secondary hit distance,
/// the representative mirror direction and what the glossy path hit first (28 bytes a pixel).
pub struct Reflections {
    pub reflection: (wgpu::Texture, wgpu::TextureView),
    pub mirror: (wgpu::Texture, wgpu::TextureView),
    pub mirror_hit: (wgpu::Texture, wgpu::TextureView),
}

/// The labels of [`Reflections`]' textures.
pub const REFLECTION_LABELS: [&str; 3] = ["trace/reflection", "trace/mirror", "trace/mirror hit"];

fn usage() -> wgpu::TextureUsages {
    wgpu::TextureUsages::STORAGE_BINDING
        | wgpu::TextureUsages::TEXTURE_BINDING
        | wgpu::TextureUsages::COPY_SRC
}

impl TraceTargets {
    /// The trace's outputs for frames of `size`; with `glossy` the glossy light (the reflection
    /// data waits for a stage that reads it).
    pub fn new(gpu: &Gpu, mem: &mut GpuMemory, size: (u32, u32), glossy: bool) -> TraceTargets {
        let d = &gpu.device;
        TraceTargets {
            matte: mem.texture(d, "trace/matte", size, MATTE_FORMAT, usage()),
            direct: mem.texture(d, "trace/direct", size, MATTE_FORMAT, usage()),
            glossy: glossy.then(|| GlossyTargets {
                light: mem.texture(d, "trace/glossy", size, MATTE_FORMAT, usage()),
                reflections: None,
            }),
            reservoirs: None,
        }
    }

    /// Make (`on`) or drop the reservoirs; true if it changed. A new buffer is zeros: no
    /// reservoir (M = 0) for the first frame to reuse.
    pub fn set_reservoirs(
        &mut self,
        gpu: &Gpu,
        mem: &mut GpuMemory,
        size: (u32, u32),
        on: bool,
    ) -> bool {
        if self.reservoirs.is_some() == on {
            return false;
        }
        self.reservoirs = on.then(|| {
            let bytes = size.0 as u64 * size.1 as u64 * RESERVOIR_BYTES;
            mem.buffer(&gpu.device, RESERVOIRS_LABEL, bytes, wgpu::BufferUsages::STORAGE)
        });
        if !on {
            mem.forget_labels(&[RESERVOIRS_LABEL.to_string()]);
        }
        true
    }

    /// Make (`on`) or drop the reflection data; true if it changed. Only Mara's and SVGF's
    /// glossy chains (and TAA following their glossy light) read it, so the raw frame and the
    /// progressive filter neither write nor keep it.
    pub fn set_reflections(
        &mut self,
        gpu: &Gpu,
        mem: &mut GpuMemory,
        size: (u32, u32),
        on: bool,
    ) -> bool {
        let Some(g) = self.glossy.as_mut() else { return false };
        if g.reflections.is_some() == on {
            return false;
        }
        if on {
            let [r, m, h] = REFLECTION_LABELS;
            let d = &gpu.device;
            g.reflections = Some(Reflections {
                reflection: mem.texture(d, r, size, REFLECTION_FORMAT, usage()),
                mirror: mem.texture(d, m, size, MIRROR_FORMAT, usage()),
                mirror_hit: mem.texture(d, h, size, MIRROR_HIT_FORMAT, usage()),
            });
        } else {
            g.reflections = None;
            mem.forget_labels(&REFLECTION_LABELS.map(str::to_string));
        }
        true
    }

    /// Whether the trace writes the reflection data this frame.
    pub fn has_reflections(&self) -> bool {
        self.glossy.as_ref().is_some_and(|g| g.reflections.is_some())
    }
}

/// The trace's programs, made on first use: static or moving shutter (motion blur), with or
/// without matte paths that end in the radiance cache (shaders/cache/path_end.wgsl), and with
/// or without the previous depth that tells which pixels a move uncovered
/// (shaders/realtime/uncovered.wgsl).
#[derive(Default)]
pub struct TracePass {
    programs: Vec<(TraceProgram, crate::shader::Reloadable<wgpu::ComputePipeline>, BindCache)>,
}

/// What a trace program is made for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct TraceProgram {
    /// Objects move during the shutter.
    moving: bool,
    /// Matte paths end in the radiance cache.
    cache: bool,
    /// The previous depth tells which pixels a move uncovered.
    previous_depth: bool,
    /// It writes the glossy path's reflection data ([`Reflections`]).
    reflections: bool,
    /// It reuses the matte light samples' reservoirs ([`TraceTargets::reservoirs`]).
    reservoirs: bool,
}

impl TraceProgram {
    fn of(inputs: &TraceInputs) -> TraceProgram {
        TraceProgram {
            moving: inputs.scene.moving,
            cache: inputs.cache.is_some(),
            previous_depth: inputs.previous_depth.is_some(),
            reflections: inputs.t.has_reflections(),
            reservoirs: inputs.t.reservoirs.is_some(),
        }
    }
}

/// The module that writes the glossy outputs: all of them where a stage reads the reflection
/// data, the light alone where none does, nothing in a scene without a specular lobe.
pub fn glossy_module(glossy: bool, reflections: bool) -> &'static str {
    match (glossy, reflections) {
        (true, true) => "realtime/trace_glossy.wgsl",
        (true, false) => "realtime/trace_glossy_light.wgsl",
        (false, _) => "realtime/trace_glossy_none.wgsl",
    }
}

fn program(
    gpu: &Gpu,
    inputs: &TraceInputs,
    moving: bool,
) -> Result<crate::shader::Reloadable<wgpu::ComputePipeline>> {
    let scene = inputs.scene.scene;
    let mut modules = scene.shading_modules_for(moving);
    if inputs.cache.is_some() {
        modules = super::cache::with_path_ends(modules);
    }
    modules.push("realtime/frame.wgsl");
    modules.push("realtime/lens.wgsl");
    modules.push("realtime/area_light.wgsl");
    modules.push(glossy_module(scene.features.glossy, inputs.t.has_reflections()));
    if inputs.previous_depth.is_some() {
        modules.extend(["realtime/seen.wgsl", "realtime/uncovered.wgsl"]);
    } else {
        modules.push("realtime/uncovered_none.wgsl");
    }
    modules.push(if inputs.t.reservoirs.is_some() {
        "realtime/reservoir.wgsl"
    } else {
        "realtime/reservoir_none.wgsl"
    });
    modules.push("realtime/trace.wgsl");
    crate::shader::Reloadable::new(
        gpu,
        LABEL,
        &scene.prelude(),
        &modules,
        wgpu::ShaderStages::COMPUTE,
        &inputs.bindings(),
        |d, m, l| compute_pipeline(d, LABEL, m, l, "main"),
    )
}

/// What the trace reads and writes: the scene, the G-buffer and its own outputs, the radiance
/// cache's table where matte paths may end in it, and the previous frame's depth where a
/// denoiser keeps histories (uncovered pixels trace `FrameSettings::uncovered_paths`).
#[derive(Clone, Copy)]
pub struct TraceInputs<'a> {
    pub scene: SceneInputs<'a>,
    pub g: &'a GBufferTargets,
    pub t: &'a TraceTargets,
    pub cache: Option<&'a super::cache::CacheCells>,
    pub previous_depth: Option<&'a wgpu::TextureView>,
}

impl<'a> TraceInputs<'a> {
    /// What the trace (and the supersampling's samples pass, which shades as it does) binds.
    pub fn bindings(&self) -> Bindings<'a> {
        let b = bindings(self.scene, self.g, self.t).texture_opt("prev_depth", self.previous_depth);
        match self.cache {
            Some(c) => c.bindings(b),
            None => b,
        }
    }
}

fn bindings<'a>(s: SceneInputs<'a>, g: &'a GBufferTargets, t: &'a TraceTargets) -> Bindings<'a> {
    let mut b = s
        .bindings()
        .texture("gb_ids", g.view(Channel::Ids))
        .texture("tr_mean_normal", g.view(Channel::Normal))
        .texture("tr_mean_base", g.view(Channel::BaseColor))
        .texture("tr_mean_specular", g.view(Channel::Specular))
        .texture("tr_mean_emission", g.view(Channel::Emission))
        .texture("out_matte", &t.matte.1)
        .texture("out_direct", &t.direct.1)
        .buffer_opt("reservoirs", t.reservoirs.as_ref());
    if let Some(gl) = &t.glossy {
        b = b.texture("out_glossy", &gl.light.1);
        if let Some(r) = &gl.reflections {
            b = b
                .texture("out_reflection", &r.reflection.1)
                .texture("out_mirror", &r.mirror.1)
                .texture("out_mirror_hit", &r.mirror_hit.1);
        }
    }
    b
}

impl TracePass {
    /// The pass with its common program (static shutter, no cache) made now, so that a scene
    /// the trace cannot compile fails here.
    pub fn new(gpu: &Gpu, inputs: &TraceInputs) -> Result<TracePass> {
        let scene = SceneInputs { moving: false, ..inputs.scene };
        let common = TraceInputs { scene, cache: None, previous_depth: None, ..*inputs };
        // The frame's first targets have no reflection data yet: this program is the raw
        // frame's.
        let (what, p) = (TraceProgram::of(&common), program(gpu, &common, false)?);
        Ok(TracePass { programs: vec![(what, p, BindCache::default())] })
    }

    /// `key`: bind groups are rebuilt when it changes. `period`: 1 / f, the frames between two
    /// samples of a pixel.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        inputs: &TraceInputs,
        size: (u32, u32),
        period: u32,
    ) -> Result<()> {
        use crate::shader::Reload;
        let what = TraceProgram::of(inputs);
        let i = match self.programs.iter().position(|(w, _, _)| *w == what) {
            Some(i) => i,
            None => {
                let p = program(rec.gpu, inputs, what.moving)?;
                self.programs.push((what, p, BindCache::default()));
                self.programs.len() - 1
            }
        };
        let (_, p, cache) = &mut self.programs[i];
        let groups = cache
            .get(key, p.builds(), (), |_| p.bind_groups(&rec.gpu.device, &inputs.bindings()))?;
        let mut pass = rec.compute_pass(LABEL);
        pass.set_pipeline(p.get());
        set_compute_groups(&mut pass, groups);
        // Below one sample per pixel one thread per tile (passes/schedule.rs), so the cost falls as f.
        let (tw, th) = super::schedule::tile(period);
        pass.dispatch_workgroups(
            size.0.div_ceil(tw).div_ceil(8),
            size.1.div_ceil(th).div_ceil(8),
            1,
        );
        Ok(())
    }

    /// Its pipelines, for hot reload.
    pub fn pipelines(&mut self) -> Vec<&mut dyn crate::shader::Reload> {
        let mut v: Vec<&mut dyn crate::shader::Reload> = vec![];
        for (_, p, _) in self.programs.iter_mut() {
            v.push(p);
        }
        v
    }
}
