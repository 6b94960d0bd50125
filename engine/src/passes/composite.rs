//! `composite` (remodulate the light buffers with the material, shaders/realtime/composite.wgsl)
//! and `display` (exposure, ACES tone map, sRGB, debug views; shaders/realtime/display.wgsl).
//! Both read the whole G-buffer and the trace outputs through the same bindings.

use super::io::FrameIo;
use crate::gpu::{
    BindCache, Bindings, Gpu, Parity, Recorder, set_compute_groups, set_render_groups,
};
use crate::shader::compute_pipeline;
use crate::shader::{Reload, Reloadable};
use anyhow::Result;

pub const COMPOSITE: &str = "composite";
pub const DISPLAY: &str = "display";
/// The remodulation of the light bound as `tr_*` (the composite's, and the still-view mean's of
/// the trace's own light).
pub const REMODULATE: &str = "realtime/remodulate.wgsl";

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
    pub direct: Option<&'a wgpu::TextureView>,
}

/// What the composite binds (`shown` as `hdr` for the display, `io.hdr` for the composite).
fn inputs<'a>(b: &FrameBuffers<'a>, hdr: &'a wgpu::Buffer) -> Bindings<'a> {
    let mut s = b.io.bindings();
    if let Some(m) = b.matte {
        s = s.texture("tr_matte", m);
    }
    if let Some(d) = b.direct {
        s = s.texture("tr_direct", d);
    }
    if let (Some(g), true) = (b.glossy, b.io.trace.glossy.is_some()) {
        s = s.texture("tr_glossy", g);
    }
    s.buffer("hdr", hdr).buffer("accumulation", b.accumulation).buffer("display", b.display)
}

/// The modules every stage that reads the G-buffer and the trace's light through the frame's
/// bindings starts with, then `last`.
pub fn modules(glossy: bool, last: &[&'static str]) -> Vec<&'static str> {
    let mut m = vec![
        "common/math.wgsl",
        "common/rng.wgsl",
        "realtime/frame.wgsl",
        "realtime/gbuffer_in.wgsl",
        if glossy { "realtime/glossy_in.wgsl" } else { "realtime/glossy_in_none.wgsl" },
    ];
    m.extend_from_slice(last);
    m
}

pub struct CompositePass {
    pub pipeline: Reloadable<wgpu::ComputePipeline>,
    groups: BindCache<Parity>,
}

impl CompositePass {
    pub fn new(gpu: &Gpu, b: &FrameBuffers) -> Result<CompositePass> {
        let modules =
            modules(b.io.trace.glossy.is_some(), &[REMODULATE, "realtime/composite.wgsl"]);
        let pipeline = Reloadable::new(
            gpu,
            COMPOSITE,
            "",
            &modules,
            wgpu::ShaderStages::COMPUTE,
            &inputs(b, b.io.hdr),
            |d, m, l| compute_pipeline(d, COMPOSITE, m, l, "main"),
        )?;
        Ok(CompositePass { pipeline, groups: BindCache::default() })
    }

    /// `b(p)`: what it binds at history parity p (a denoiser's output may ping-pong).
    pub fn record<'a>(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        b: impl Fn(Parity) -> FrameBuffers<'a>,
        parity: Parity,
    ) -> Result<()> {
        let p = &self.pipeline;
        let size = b(parity).io.size;
        let groups = self.groups.get(key, p.builds(), parity, |v| {
            let b = b(v);
            p.bind_groups(&rec.gpu.device, &inputs(&b, b.io.hdr))
        })?;
        let mut pass = rec.compute_pass(COMPOSITE);
        pass.set_pipeline(p.get());
        set_compute_groups(&mut pass, groups);
        pass.dispatch_workgroups(size.0.div_ceil(8), size.1.div_ceil(8), 1);
        Ok(())
    }
}

/// Where a debug view's texture is bound (display.wgsl's `view_float` or `view_uint`); depth
/// is read from the G-buffer's own binding.
fn view_slot(format: wgpu::TextureFormat) -> Option<&'static str> {
    match format.sample_type(None, None) {
        _ if format.is_depth_stencil_format() => None,
        Some(wgpu::TextureSampleType::Uint) => Some("view_uint"),
        Some(wgpu::TextureSampleType::Float { .. }) => Some("view_float"),
        _ => None,
    }
}

pub struct DisplayPass {
    pub pipeline: Reloadable<wgpu::RenderPipeline>,
    groups: BindCache,
    pub format: wgpu::TextureFormat,
    /// One zero texel each, bound in the view slot the shown texture does not use.
    zero_float: (wgpu::Texture, wgpu::TextureView),
    zero_uint: (wgpu::Texture, wgpu::TextureView),
}

impl DisplayPass {
    pub fn new(gpu: &Gpu, b: &FrameBuffers, format: wgpu::TextureFormat) -> Result<DisplayPass> {
        let mut mem = crate::gpu::GpuMemory::default();
        let usage = wgpu::TextureUsages::TEXTURE_BINDING;
        let zero_float = mem.texture(
            &gpu.device,
            "display/no float view",
            (1, 1),
            wgpu::TextureFormat::Rgba16Float,
            usage,
        );
        let zero_uint = mem.texture(
            &gpu.device,
            "display/no uint view",
            (1, 1),
            wgpu::TextureFormat::R32Uint,
            usage,
        );
        let offered = inputs(b, b.shown)
            .texture("view_float", &zero_float.1)
            .texture("view_uint", &zero_uint.1);
        let modules = modules(b.io.trace.glossy.is_some(), &["realtime/display.wgsl"]);
        let pipeline = Reloadable::new(
            gpu,
            DISPLAY,
            "",
            &modules,
            wgpu::ShaderStages::FRAGMENT,
            &offered,
            move |d, module, pl| {
                d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(DISPLAY),
                    layout: Some(pl),
                    vertex: wgpu::VertexState {
                        module,
                        entry_point: Some("vs_main"),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    primitive: Default::default(),
                    depth_stencil: None,
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module,
                        entry_point: Some("fs_main"),
                        compilation_options: Default::default(),
                        targets: &[Some(format.into())],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            },
        )?;
        Ok(DisplayPass { pipeline, groups: BindCache::default(), format, zero_float, zero_uint })
    }

    /// `view`: the texture the debug view shows (None for the image); `key` must change with it.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        b: &FrameBuffers,
        view: Option<&wgpu::Texture>,
        target: &wgpu::TextureView,
    ) -> Result<()> {
        let p = &self.pipeline;
        let (zf, zu) = (&self.zero_float.1, &self.zero_uint.1);
        let groups = self.groups.get(key, p.builds(), (), |_| {
            let shown = view.map(|t| (view_slot(t.format()), t.create_view(&Default::default())));
            let mut r = inputs(b, b.shown).texture("view_float", zf).texture("view_uint", zu);
            if let Some((Some(slot), v)) = &shown {
                r = r.texture(slot, v);
            }
            p.bind_groups(&rec.gpu.device, &r)
        })?;
        let (enc, timestamp_writes) = rec.render_parts(DISPLAY);
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(DISPLAY),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(p.get());
        set_render_groups(&mut pass, groups);
        pass.draw(0..3, 0..1);
        Ok(())
    }
}
