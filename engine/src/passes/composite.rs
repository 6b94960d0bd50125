//! `composite` (remodulate the light buffers with the material, shaders/realtime/composite.wgsl)
//! and `display` (exposure, ACES tone map, sRGB, debug views; shaders/realtime/display.wgsl).
//! Both read the whole G-buffer and the trace outputs through the same bindings.

use super::io::FrameIo;
use crate::gpu::scene::compute_pipeline;
use crate::gpu::{BindCache, Bindings, Gpu, GpuTimer, set_compute_groups, set_render_groups};
use crate::shader::{Reload, Reloadable};
use anyhow::Result;

pub const COMPOSITE: &str = "composite";
pub const DISPLAY: &str = "display";

/// What the composite and the display bind beside the frame's I/O.
pub struct FrameBuffers<'a> {
    pub io: FrameIo<'a>,
    /// For the display: the image after TAA when it ran, else the composite's (`io.hdr`).
    pub shown: &'a wgpu::Buffer,
    pub accumulation: &'a wgpu::Buffer,
    pub display: &'a wgpu::Buffer,
    /// The light the composite remodulates: the denoiser's output (None: the trace's).
    pub matte: Option<&'a wgpu::TextureView>,
    pub glossy: Option<&'a wgpu::TextureView>,
    /// The denoiser's intermediates, for the display's debug views (`dv_*`, `gv_*`).
    pub views: Bindings<'a>,
}

/// What the composite binds (`shown` as `hdr` for the display, `io.hdr` for the composite).
fn inputs<'a>(b: &FrameBuffers<'a>, hdr: &'a wgpu::Buffer) -> Bindings<'a> {
    let mut s = b.io.bindings();
    if let Some(m) = b.matte {
        s = s.texture("tr_matte", m);
    }
    if let (Some(g), true) = (b.glossy, b.io.trace.glossy.is_some()) {
        s = s.texture("tr_glossy", g);
    }
    s.buffer("hdr", hdr).buffer("accumulation", b.accumulation).buffer("display", b.display).with(&b.views)
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
    pub fn new(gpu: &Gpu, b: &FrameBuffers) -> Result<CompositePass> {
        let modules = modules(b.io.trace.glossy.is_some(), false, false, "realtime/composite.wgsl");
        let pipeline = Reloadable::new(gpu, COMPOSITE, "", &modules, wgpu::ShaderStages::COMPUTE, &inputs(b, b.io.hdr), |d, m, l| compute_pipeline(d, COMPOSITE, m, l, "main"))?;
        Ok(CompositePass { pipeline, groups: BindCache::default() })
    }

    #[allow(clippy::too_many_arguments)]
    /// `b(p)`: what it binds at history parity p (a denoiser's output may ping-pong).
    pub fn record<'a>(&mut self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, key: u64, b: impl Fn(usize) -> FrameBuffers<'a>, parity: usize, timer: Option<&mut GpuTimer>) -> Result<()> {
        let p = &self.pipeline;
        let size = b(parity).io.size;
        let groups = self.groups.get(key, p.builds(), 2, parity, |v| {
            let b = b(v);
            p.bind_groups(&gpu.device, &inputs(&b, b.io.hdr))
        })?;
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
    pub fn new(gpu: &Gpu, b: &FrameBuffers, format: wgpu::TextureFormat) -> Result<DisplayPass> {
        let (denoise, glossy_chain) = (b.views.get("dv_temporal").is_some(), b.views.get("gv_motion").is_some());
        let modules = modules(b.io.trace.glossy.is_some(), denoise, glossy_chain, "realtime/display.wgsl");
        let pipeline = Reloadable::new(gpu, DISPLAY, "", &modules, wgpu::ShaderStages::FRAGMENT, &inputs(b, b.shown), move |d, module, pl| {
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
        Ok(DisplayPass { pipeline, groups: BindCache::default(), format, with_denoise: denoise })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(&mut self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, key: u64, b: &FrameBuffers, target: &wgpu::TextureView, timer: Option<&mut GpuTimer>) -> Result<()> {
        let p = &self.pipeline;
        let groups = self.groups.get(key, p.builds(), 1, 0, |_| p.bind_groups(&gpu.device, &inputs(b, b.shown)))?;
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
