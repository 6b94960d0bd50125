//! `composite` (remodulate the light buffers with the material, shaders/realtime/composite.wgsl)
//! and `display` (exposure, ACES tone map, sRGB, debug views; shaders/realtime/display.wgsl).
//! Both read the whole G-buffer and the trace outputs through the same bindings.

use super::gbuffer::GBufferTargets;
use super::trace::TraceTargets;
use crate::gpu::scene::compute_pipeline;
use crate::gpu::{BindCache, Bindings, Gpu, GpuTimer, set_compute_groups, set_render_groups};
use crate::shader::{Reload, Reloadable};
use anyhow::Result;

pub const COMPOSITE: &str = "composite";
pub const DISPLAY: &str = "display";

/// The HDR image (and the accumulation sum) as storage buffers: one vec4 (16 bytes) per pixel.
pub struct FrameBuffers<'a> {
    pub frame: &'a wgpu::Buffer,
    /// The composite's output; for the display, the image after TAA when the denoiser ran.
    pub hdr: &'a wgpu::Buffer,
    pub accumulation: &'a wgpu::Buffer,
    pub display: &'a wgpu::Buffer,
    /// The matte light the composite remodulates: raw, or the matte chain's output.
    pub matte: &'a wgpu::TextureView,
    /// The glossy light the composite remodulates: the glossy chain's output (None: raw).
    pub glossy: Option<&'a wgpu::TextureView>,
    /// The chains' intermediates, for the display's debug views.
    pub denoise: Option<&'a super::matte::MatteTargets>,
    pub glossy_chain: Option<&'a super::glossy::GlossyChainTargets>,
}

/// What the composite and the display bind (the display also the chains' intermediates).
fn inputs<'a>(g: &'a GBufferTargets, t: &'a TraceTargets, b: &FrameBuffers<'a>) -> Bindings<'a> {
    let mut s = super::matte::gbuffer_inputs(Bindings::new().buffer("frame", b.frame), g, t, b.matte);
    if let Some(gl) = &t.glossy {
        s = super::glossy::glossy_trace_inputs(s, t, b.glossy.unwrap_or(&gl.light.1));
    }
    s = s.buffer("hdr", b.hdr).buffer("accumulation", b.accumulation).buffer("display", b.display);
    if let Some(m) = b.denoise {
        s = s.texture("dv_temporal", &m.temporal.1).texture("dv_reason", &m.reason.1).texture("dv_radius", &m.radius.1).texture("dv_firefly", &m.median.1).texture("dv_denoised", &m.denoised.1);
    }
    if let Some(g) = b.glossy_chain {
        s = s.texture("gv_motion", &g.motion.1).texture("gv_search", &g.search.1).texture("gv_info", &g.info.1).texture("gv_sigma", &g.scratch.1).texture("gv_denoised", &g.denoised.1);
    }
    s
}

fn modules(glossy: bool, denoise: bool, glossy_chain: bool, last: &'static str) -> Vec<&'static str> {
    let mut m = vec![
        "common/math.wgsl",
        "common/rng.wgsl",
        "realtime/frame.wgsl",
        "realtime/gbuffer_in.wgsl",
        if glossy { "realtime/glossy_in.wgsl" } else { "realtime/glossy_in_none.wgsl" },
    ];
    if last == "realtime/display.wgsl" {
        m.push(if denoise { "realtime/denoise_views.wgsl" } else { "realtime/denoise_views_none.wgsl" });
        if denoise {
            m.push(if glossy_chain { "glossy/views.wgsl" } else { "glossy/views_none.wgsl" });
        }
    }
    m.push(last);
    m
}

pub struct CompositePass {
    pub pipeline: Reloadable<wgpu::ComputePipeline>,
    groups: BindCache,
}

impl CompositePass {
    pub fn new(gpu: &Gpu, g: &GBufferTargets, t: &TraceTargets, b: &FrameBuffers) -> Result<CompositePass> {
        let modules = modules(t.glossy.is_some(), false, false, "realtime/composite.wgsl");
        let pipeline = Reloadable::new(gpu, COMPOSITE, "", &modules, wgpu::ShaderStages::COMPUTE, &inputs(g, t, b), |d, m, l| compute_pipeline(d, COMPOSITE, m, l, "main"))?;
        Ok(CompositePass { pipeline, groups: BindCache::default() })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(&mut self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, key: u64, g: &GBufferTargets, t: &TraceTargets, b: &FrameBuffers, size: (u32, u32), timer: Option<&mut GpuTimer>) -> Result<()> {
        let p = &self.pipeline;
        let groups = self.groups.get(key, p.builds(), 1, 0, |_| p.bind_groups(&gpu.device, &inputs(g, t, b)))?;
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(COMPOSITE), timestamp_writes: timer.and_then(|t| t.compute(COMPOSITE)) });
        pass.set_pipeline(p.get());
        set_compute_groups(&mut pass, groups);
        pass.dispatch_workgroups(size.0.div_ceil(8), size.1.div_ceil(8), 1);
        Ok(())
    }
}

pub struct DisplayPass {
    pub pipeline: Reloadable<wgpu::RenderPipeline>,
    groups: BindCache,
    pub format: wgpu::TextureFormat,
    /// Whether it shows the denoiser's views (its layout binds their textures).
    pub with_denoise: bool,
}

impl DisplayPass {
    pub fn new(gpu: &Gpu, g: &GBufferTargets, t: &TraceTargets, b: &FrameBuffers, format: wgpu::TextureFormat) -> Result<DisplayPass> {
        let modules = modules(t.glossy.is_some(), b.denoise.is_some(), b.glossy_chain.is_some(), "realtime/display.wgsl");
        let pipeline = Reloadable::new(gpu, DISPLAY, "", &modules, wgpu::ShaderStages::FRAGMENT, &inputs(g, t, b), move |d, module, pl| {
            d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(DISPLAY),
                layout: Some(pl),
                vertex: wgpu::VertexState { module, entry_point: Some("vs_main"), compilation_options: Default::default(), buffers: &[] },
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState { module, entry_point: Some("fs_main"), compilation_options: Default::default(), targets: &[Some(format.into())] }),
                multiview_mask: None,
                cache: None,
            })
        })?;
        Ok(DisplayPass { pipeline, groups: BindCache::default(), format, with_denoise: b.denoise.is_some() })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(&mut self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, key: u64, g: &GBufferTargets, t: &TraceTargets, b: &FrameBuffers, target: &wgpu::TextureView, timer: Option<&mut GpuTimer>) -> Result<()> {
        let p = &self.pipeline;
        let groups = self.groups.get(key, p.builds(), 1, 0, |_| p.bind_groups(&gpu.device, &inputs(g, t, b)))?;
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(DISPLAY),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment { view: target, depth_slice: None, resolve_target: None, ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store } })],
            depth_stencil_attachment: None,
            timestamp_writes: timer.and_then(|t| t.render(DISPLAY)),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(p.get());
        set_render_groups(&mut pass, groups);
        pass.draw(0..3, 0..1);
        Ok(())
    }
}
