//! `view/display`: draws the tracer's running mean to the window.

use anyhow::Result;
use hush_engine::gpu::Gpu;
use hush_engine::passes::ReferenceTracer;

pub struct Display {
    pipeline: wgpu::RenderPipeline,
    bind_group: wgpu::BindGroup,
    params: wgpu::Buffer,
    encode_srgb: bool,
}

impl Display {
    pub fn new(gpu: &Gpu, format: wgpu::TextureFormat, tracer: &ReferenceTracer) -> Result<Display> {
        let program = hush_engine::shader::compose("view/display", "", &["view/display.wgsl"])?;
        let module = program.create(&gpu.device)?;
        let d = &gpu.device;
        let buf = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        };
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("view/display"),
            entries: &[buf(0, wgpu::BufferBindingType::Uniform), buf(1, wgpu::BufferBindingType::Storage { read_only: true })],
        });
        let params = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("view/display params"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("view/display"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: tracer.accumulation_buffer().as_entire_binding() },
            ],
        });
        let pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: Some("view/display"), bind_group_layouts: &[Some(&layout)], immediate_size: 0 });
        let pipeline = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("view/display"),
            layout: Some(&pl),
            vertex: wgpu::VertexState { module: &module, entry_point: Some("vs_main"), buffers: &[], compilation_options: Default::default() },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                targets: &[Some(format.into())],
                compilation_options: Default::default(),
            }),
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        Ok(Display { pipeline, bind_group, params, encode_srgb: !format.is_srgb() })
    }

    pub fn draw(&self, gpu: &Gpu, tracer: &ReferenceTracer, target: &wgpu::Texture) {
        let (w, h) = tracer.size();
        let p = [w, h, tracer.samples, self.encode_srgb as u32];
        gpu.queue.write_buffer(&self.params, 0, bytemuck::cast_slice(&p));
        let view = target.create_view(&Default::default());
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("view/display") });
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("view/display"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        gpu.queue.submit([enc.finish()]);
    }
}
