//! `frame/rescale`: the frame's histories carried across a change of its size (the governor's
//! resolution scale, a window resize) instead of restarted (shaders/realtime/rescale*.wgsl).
//!
//! After a resize the frame keeps its old per-pixel targets until its next frame has allocated
//! the new ones. Then every texture of the old set that the new set has under the same label and
//! format, and that a compute pass can write, is resampled into it: float textures bilinearly
//! from the old texels on the nearest one's surface (their last-frame depths within 2%), integer
//! ones from the nearest texel. The last frame's G-buffer (depth, normal, ids), which the
//! reprojections test against, is taken from the nearest texel by a render pass (a depth
//! texture is no storage texture). The frame's cameras stay, so the next frame reprojects into
//! the resampled histories as into the old ones: the same texture coordinate holds the same
//! view ray at either size.
//!
//! Written here rather than taken from a crate: it resamples the frame's own labelled textures
//! with the frame's depth, which no general-purpose image crate sees (they run on the CPU).
//!
//! A resampled history is blurred by the resampling: on that frame the temporal stages count it
//! as at most `FrameSettings::resample_history_frames` (`frame.rescaled_frames` and
//! `rescaled_length` in realtime/frame.wgsl), and TAA as one history resampled between texels,
//! so that the new size's samples replace it within a few frames.

use super::io::PreviousGBuffer;
use crate::gpu::{Bindings, GpuMemory, Recorder, set_compute_groups, set_render_groups};
use crate::shader::{Reload, Reloadable, compute_pipeline};
use anyhow::{Context, Result};
use std::collections::HashMap;

pub const LABEL: &str = "frame/rescale";
const GBUFFER_LABEL: &str = "frame/rescale gbuffer";

/// The WGSL storage format of a texture a compute pass can resample, and whether it holds
/// integers (then the nearest texel is taken). None: not resampled.
fn storage_format(f: wgpu::TextureFormat) -> Option<(&'static str, bool)> {
    use wgpu::TextureFormat as F;
    Some(match f {
        F::Rgba32Float => ("rgba32float", false),
        F::Rgba16Float => ("rgba16float", false),
        F::Rg32Float => ("rg32float", false),
        F::R32Float => ("r32float", false),
        F::Rgba8Unorm => ("rgba8unorm", false),
        F::R32Uint => ("r32uint", true),
        F::Rg32Uint => ("rg32uint", true),
        F::Rgba32Uint => ("rgba32uint", true),
        _ => return None,
    })
}

/// What one resampling did, for the tests and the profile.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Rescaled {
    /// Labels of the textures resampled (the previous G-buffer's included).
    pub textures: Vec<String>,
    /// Labels of storage textures in both sets whose format the passes do not write.
    pub skipped: Vec<String>,
}

/// The resampling passes, made on first use (one compute program per storage format).
#[derive(Default)]
pub struct Rescale {
    compute: HashMap<wgpu::TextureFormat, Reloadable<wgpu::ComputePipeline>>,
    gbuffer: Option<Reloadable<wgpu::RenderPipeline>>,
    /// A 1x1 depth bound where the old set kept no previous G-buffer (every tap then counts).
    no_depth: Option<(wgpu::Texture, wgpu::TextureView)>,
}

impl Rescale {
    /// Record the resampling of `old` (a set of targets of another size) into `new`; `old_prev`
    /// and `new_prev` are the sets' last-frame G-buffers where they keep one.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        (old, old_prev): (&GpuMemory, Option<&PreviousGBuffer>),
        (new, new_prev): (&GpuMemory, Option<&PreviousGBuffer>),
    ) -> Result<Rescaled> {
        let _scope = crate::profile::scope(LABEL);
        let gpu = rec.gpu;
        let no_depth = self.no_depth.get_or_insert_with(|| {
            GpuMemory::default().texture(
                &gpu.device,
                "frame/rescale no depth",
                (1, 1),
                super::gbuffer::DEPTH_FORMAT,
                wgpu::TextureUsages::TEXTURE_BINDING,
            )
        });
        let old_depth = old_prev.map_or(&no_depth.1, |p| &p.depth.1);
        let prev_labels: Vec<String> = old_prev
            .iter()
            .flat_map(|p| [&p.depth.0, &p.normal.0, &p.ids.0])
            .filter_map(|t| old.textures.iter().find(|(_, o)| o == t).map(|(l, _)| l.clone()))
            .collect();
        let mut done = Rescaled::default();
        let mut jobs = vec![];
        for (label, from) in &old.textures {
            let Some(to) = new.find_texture(label) else { continue };
            // Textures no compute pass writes (the raster's G-buffer, copies) are rewritten
            // whole every frame.
            let writable = to.usage().contains(wgpu::TextureUsages::STORAGE_BINDING)
                && from.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING);
            if prev_labels.contains(label) || to.format() != from.format() || !writable {
                continue;
            }
            match storage_format(to.format()) {
                Some(f) => jobs.push((label, from, to, f)),
                None => done.skipped.push(label.clone()),
            }
        }
        let mut groups = vec![];
        for (label, from, to, (wgsl, integer)) in &jobs {
            let from_view = from.create_view(&Default::default());
            let to_view = to.create_view(&Default::default());
            let offered = Bindings::new()
                .texture("old_depth", old_depth)
                .texture("old", &from_view)
                .texture("dst", &to_view);
            let pipeline = match self.compute.entry(to.format()) {
                std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
                std::collections::hash_map::Entry::Vacant(e) => {
                    let prelude = format!("alias Dst = texture_storage_2d<{wgsl}, write>;\n");
                    let main = if *integer {
                        "realtime/rescale_uint.wgsl"
                    } else {
                        "realtime/rescale_float.wgsl"
                    };
                    let p = Reloadable::new(
                        gpu,
                        LABEL,
                        &prelude,
                        &[
                            "common/bilinear.wgsl",
                            "realtime/rescale.wgsl",
                            main,
                            "realtime/rescale_main.wgsl",
                        ],
                        wgpu::ShaderStages::COMPUTE,
                        &offered,
                        |d, m, l| compute_pipeline(d, LABEL, m, l, "main"),
                    )
                    .with_context(|| format!("making the resampling program for {wgsl}"))?;
                    e.insert(p)
                }
            };
            let g = pipeline
                .bind_groups(&gpu.device, &offered)
                .with_context(|| format!("resampling {label}"))?;
            groups.push((to.format(), (to.width(), to.height()), g));
            done.textures.push(label.to_string());
        }
        {
            let mut pass = rec.compute_pass(LABEL);
            for (format, size, g) in &groups {
                pass.set_pipeline(self.compute[format].get());
                set_compute_groups(&mut pass, g);
                pass.dispatch_workgroups(size.0.div_ceil(8), size.1.div_ceil(8), 1);
            }
        }
        if let (Some(o), Some(n)) = (old_prev, new_prev) {
            self.record_gbuffer(rec, o, n)?;
            done.textures.extend(prev_labels);
        }
        Ok(done)
    }

    /// The previous G-buffer's nearest texels, drawn into the new one.
    fn record_gbuffer(
        &mut self,
        rec: &mut Recorder,
        old: &PreviousGBuffer,
        new: &PreviousGBuffer,
    ) -> Result<()> {
        let gpu = rec.gpu;
        let size = (new.depth.0.width(), new.depth.0.height());
        let target = GpuMemory::default().buffer_init(
            &gpu.device,
            "frame/rescale target",
            bytemuck::cast_slice(&[size.0, size.1, 0, 0]),
            wgpu::BufferUsages::UNIFORM,
        );
        let offered = Bindings::new()
            .texture("old_depth", &old.depth.1)
            .texture("old_normal", &old.normal.1)
            .texture("old_ids", &old.ids.1)
            .buffer("rescale_target", &target);
        let formats = [new.normal.0.format(), new.ids.0.format()];
        let pipeline = super::chain::made(&mut self.gbuffer, || {
            Reloadable::new(
                gpu,
                GBUFFER_LABEL,
                "",
                &["common/bilinear.wgsl", "realtime/rescale.wgsl", "realtime/rescale_gbuffer.wgsl"],
                wgpu::ShaderStages::FRAGMENT,
                &offered,
                move |d, module, layout| {
                    let always = wgpu::CompareFunction::Always;
                    super::gbuffer::depth_pipeline(
                        d,
                        GBUFFER_LABEL,
                        (module, layout),
                        always,
                        &formats,
                    )
                },
            )
        })?;
        let groups = pipeline.bind_groups(&gpu.device, &offered)?;
        let (enc, timestamp_writes) = rec.render_parts(GBUFFER_LABEL);
        let attachment = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })
        };
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(GBUFFER_LABEL),
            color_attachments: &[attachment(&new.normal.1), attachment(&new.ids.1)],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &new.depth.1,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline.get());
        set_render_groups(&mut pass, &groups);
        pass.draw(0..3, 0..1);
        Ok(())
    }

    /// Its pipelines, for hot reload.
    pub fn pipelines(&mut self) -> Vec<&mut dyn Reload> {
        let mut v: Vec<&mut dyn Reload> = vec![];
        for p in self.compute.values_mut() {
            v.push(p);
        }
        if let Some(g) = self.gbuffer.as_mut() {
            v.push(g);
        }
        v
    }
}
