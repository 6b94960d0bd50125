//! `gbuffer`: the raster pass that draws the primary surfaces (shaders/realtime/gbuffer.wgsl).
//!
//! Channels and their cost per pixel (36 bytes in all):
//! | channel | format | bytes | content |
//! |---|---|---|---|
//! | depth | Depth32Float | 4 | reversed infinite Z |
//! | normal | Rg16Float | 4 | octahedral shading normal (world), facing the camera |
//! | motion | Rg16Float | 4 | pixels to the surface's position in the previous frame |
//! | base_color | Rgba8UnormSrgb | 4 | base colour, metallic in alpha |
//! | specular | Rgba8Unorm | 4 | specular F0, roughness in alpha |
//! | emission | Rgba16Float | 8 | emitted radiance, Fresnel f90 in alpha |
//! | ids | Rg32Uint | 8 | object index, triangle slot (u32::MAX: no surface) |
//! Eight bits per channel suffice for colours and F0 because each frame stores one of the two
//! codes around the colour, chosen so that the frames average to it
//! (shaders/realtime/gbuffer_dither.wgsl): rounded to the nearest code, cornell_diffuse's white
//! stayed 0.27% dark and a dielectric's F0 of 0.04 2% low in every frame and every mean of them;
//! normals need more than 8 bits per octahedral coordinate for bilateral weights, motion more than
//! 8 bits for sub-pixel reprojection. The six colour targets cost 40 bytes per sample under
//! WebGPU's render-target accounting (8-bit RGBA counts 8), over its default of 32: the device
//! asks for 40, which every native backend grants.

use crate::gpu::{
    BindCache, BindKey, Bindings, Gpu, GpuMemory, GpuScene, Recorder, set_render_groups,
};
use crate::shader::{Reload, Reloadable};
use anyhow::Result;

pub const LABEL: &str = "gbuffer";
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
pub const COLOR_FORMATS: [(&str, wgpu::TextureFormat); 6] = [
    ("gbuffer/normal", wgpu::TextureFormat::Rg16Float),
    ("gbuffer/motion", wgpu::TextureFormat::Rg16Float),
    ("gbuffer/base_color", wgpu::TextureFormat::Rgba8UnormSrgb),
    ("gbuffer/specular", wgpu::TextureFormat::Rgba8Unorm),
    ("gbuffer/emission", wgpu::TextureFormat::Rgba16Float),
    ("gbuffer/ids", wgpu::TextureFormat::Rg32Uint),
];
/// Render-target bytes per sample of the colour attachments (WebGPU's accounting).
pub const COLOR_BYTES_PER_SAMPLE: u32 = 40;

/// A colour channel of the G-buffer, as [`COLOR_FORMATS`] orders them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    Normal = 0,
    Motion = 1,
    BaseColor = 2,
    Specular = 3,
    Emission = 4,
    Ids = 5,
}

pub struct GBufferTargets {
    pub depth: (wgpu::Texture, wgpu::TextureView),
    /// In the order of [`COLOR_FORMATS`].
    pub color: [(wgpu::Texture, wgpu::TextureView); COLOR_FORMATS.len()],
}

impl GBufferTargets {
    pub fn new(gpu: &Gpu, mem: &mut GpuMemory, size: (u32, u32)) -> GBufferTargets {
        Self::labelled(gpu, mem, size, "")
    }

    /// As [`GBufferTargets::new`], each label after `prefix` (a second G-buffer's).
    pub fn labelled(
        gpu: &Gpu,
        mem: &mut GpuMemory,
        size: (u32, u32),
        prefix: &str,
    ) -> GBufferTargets {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let mut t = |l: &str, f| mem.texture(&gpu.device, &format!("{prefix}{l}"), size, f, usage);
        let depth = t("gbuffer/depth", DEPTH_FORMAT);
        let color = COLOR_FORMATS.map(|(l, f)| t(l, f));
        GBufferTargets { depth, color }
    }

    pub fn view(&self, c: Channel) -> &wgpu::TextureView {
        &self.channel(c).1
    }

    pub fn channel(&self, c: Channel) -> &(wgpu::Texture, wgpu::TextureView) {
        &self.color[c as usize]
    }

    /// A render pass writing every channel and the depth, cleared (ids to "no surface", depth to
    /// 0, reversed Z's far): the raster's, and the traced primaries' resolve.
    pub fn begin_pass<'e>(
        &self,
        rec: &'e mut Recorder,
        label: &'static str,
    ) -> wgpu::RenderPass<'e> {
        let clear_ids = wgpu::Color { r: u32::MAX as f64, g: u32::MAX as f64, b: 0.0, a: 0.0 };
        let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = self
            .color
            .iter()
            .enumerate()
            .map(|(i, (_, v))| {
                let clear =
                    if i == COLOR_FORMATS.len() - 1 { clear_ids } else { wgpu::Color::TRANSPARENT };
                Some(wgpu::RenderPassColorAttachment {
                    view: v,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(clear),
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect();
        let (enc, timestamp_writes) = rec.render_parts(label);
        enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth.1,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// A colour channel's format.
    pub fn format(c: Channel) -> wgpu::TextureFormat {
        COLOR_FORMATS[c as usize].1
    }
}

/// A pipeline that writes every G-buffer channel and the depth (entry points `vs_main` and
/// `fs_main`, both faces drawn), depth compared by `depth_compare`.
pub fn render_pipeline(
    d: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    depth_compare: wgpu::CompareFunction,
) -> wgpu::RenderPipeline {
    let formats: Vec<wgpu::TextureFormat> = COLOR_FORMATS.iter().map(|(_, f)| *f).collect();
    depth_pipeline(d, label, (module, layout), depth_compare, &formats)
}

/// A pipeline that writes colour targets of `formats` and a G-buffer depth (entry points
/// `vs_main` and `fs_main`, both faces drawn), depth compared by `depth_compare`.
pub fn depth_pipeline(
    d: &wgpu::Device,
    label: &str,
    (module, layout): (&wgpu::ShaderModule, &wgpu::PipelineLayout),
    depth_compare: wgpu::CompareFunction,
    formats: &[wgpu::TextureFormat],
) -> wgpu::RenderPipeline {
    let targets: Vec<Option<wgpu::ColorTargetState>> =
        formats.iter().map(|f| Some((*f).into())).collect();
    d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            front_face: wgpu::FrontFace::Ccw,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(depth_compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

pub struct GBufferPass {
    pub pipeline: Reloadable<wgpu::RenderPipeline>,
    groups: BindCache,
}

fn bindings<'a>(scene: &'a GpuScene, frame: &'a wgpu::Buffer) -> Bindings<'a> {
    scene.bindings().buffer("frame", frame)
}

impl GBufferPass {
    pub fn new(gpu: &Gpu, scene: &GpuScene, frame: &wgpu::Buffer) -> Result<GBufferPass> {
        let f = &scene.features;
        let mut modules = vec![
            "common/math.wgsl",
            // pcg_hash, for the stochastic transparency of blended materials (alpha_mask.wgsl) and
            // the material's dither (gbuffer_dither.wgsl).
            "common/rng.wgsl",
            "common/geometry.wgsl",
            "common/motion_none.wgsl",
            scene.instance_module(),
            "common/scene.wgsl",
            "common/bsdf.wgsl",
        ];
        modules.extend(scene.material_modules());
        modules.extend([
            "realtime/frame.wgsl",
            f.motion().module(),
            "realtime/gbuffer_dither.wgsl",
            "realtime/gbuffer.wgsl",
        ]);
        let visibility = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        // Reversed Z: larger is nearer.
        let pipeline = Reloadable::new(
            gpu,
            LABEL,
            "",
            &modules,
            visibility,
            &bindings(scene, frame),
            |d, module, pl| render_pipeline(d, LABEL, module, pl, wgpu::CompareFunction::Greater),
        )?;
        Ok(GBufferPass { pipeline, groups: BindCache::default() })
    }

    pub fn record(
        &mut self,
        rec: &mut Recorder,
        scene: &GpuScene,
        frame: &wgpu::Buffer,
        t: &GBufferTargets,
    ) -> Result<()> {
        let p = &self.pipeline;
        let groups = self.groups.get(
            BindKey { scene: scene.generation, ..BindKey::default() },
            p.builds(),
            (),
            |_| p.bind_groups(&rec.gpu.device, &bindings(scene, frame)),
        )?;
        let mut pass = t.begin_pass(rec, LABEL);
        pass.set_pipeline(p.get());
        set_render_groups(&mut pass, groups);
        if scene.draws.is_empty() {
            pass.draw(0..scene.triangle_count * 3, 0..1);
        } else {
            // World-space triangles around the prototypes (draw list entry 0), then each
            // prototype instanced.
            let protos = &scene.proto_slots;
            pass.draw(0..protos.start * 3, 0..1);
            pass.draw(protos.end * 3..scene.triangle_count * 3, 0..1);
            for d in &scene.draws {
                pass.draw(d.vertices.clone(), d.instances.clone());
            }
        }
        Ok(())
    }
}
