//! The frame's inputs and outputs as every stage after the trace sees them: the frame uniform,
//! the G-buffer of this frame and the previous one, the trace's signals and the composite's
//! image, offered by the names the WGSL binds them by. A stage adds its own resources on top.

use super::gbuffer::{Channel, GBufferTargets};
use super::trace::TraceTargets;
use crate::gpu::{Bindings, GpuMemory};

/// The module that gives a stage `defocus_sigma`: realtime/uncertainty.wgsl where the frame
/// offers the pre-filter's statistics (`uncertain`), else realtime/uncertainty_none.wgsl (no
/// binding).
pub fn uncertainty_module(uncertain: bool) -> &'static str {
    if uncertain { "realtime/uncertainty.wgsl" } else { "realtime/uncertainty_none.wgsl" }
}

/// What every temporal stage needs to know of this frame's camera and the previous one's (the
/// frame uploads it in its uniform, `FrameParams`).
#[derive(Clone, Copy, Debug)]
pub struct ChainView {
    /// Rebased world from clip, this frame and the previous one (both with their jitter, as
    /// their depth buffers were rasterised).
    pub inv_view_proj: glam::Mat4,
    pub prev_inv_view_proj: glam::Mat4,
    /// The previous frame's sub-pixel jitter minus this frame's, pixels: what separates the two
    /// frames' samples of one pixel in a still view.
    pub jitter_shift: glam::Vec2,
    /// False when there is no usable history (first denoised frame, resize, denoiser paused).
    pub history_valid: bool,
    /// Neither the camera nor any object moved since the last frame: every surface, and
    /// everything seen in a reflection, stands where it stood.
    pub static_view: bool,
}

/// A reprojection's normal test as a cosine: 180 degrees or more passes every normal.
pub fn normal_test_cos(degrees: f32) -> f32 {
    if degrees >= 180.0 { -2.0 } else { degrees.max(0.0).to_radians().cos() }
}

/// What the frame offers a stage (all borrowed from the frame for one recording).
#[derive(Clone, Copy)]
pub struct FrameIo<'a> {
    pub size: (u32, u32),
    /// `FrameParams` (shaders/realtime/frame.wgsl).
    pub frame: &'a wgpu::Buffer,
    /// Per object, previous-from-current transforms (animated scenes only).
    pub objects: Option<&'a wgpu::Buffer>,
    /// A deforming scene's triangle vertices now and at the previous frame
    /// (realtime/motion_vertices.wgsl).
    pub vertices: Option<(&'a wgpu::TextureView, &'a wgpu::TextureView)>,
    pub gbuffer: &'a GBufferTargets,
    /// The previous frame's G-buffer depth, normal and object ids, where a stage asked for them
    /// ([`crate::denoise::Denoiser::needs_previous_gbuffer`]).
    pub previous: Option<&'a PreviousGBuffer>,
    pub trace: &'a TraceTargets,
    /// With supersampling (k > 1), the guides' light after eq. (7): offered as the trace's.
    pub mixed: Option<&'a MixedLight>,
    /// The radiance cache's prior per pixel and its samples' mean squared luminance
    /// (passes/cache.rs), where the cache ran this frame.
    pub cache_prior: Option<(&'a wgpu::TextureView, &'a wgpu::TextureView)>,
    /// The pre-filter's per-pixel statistics (`prefilter/view`: z the world positions' spread
    /// in pixels), where it ran this frame: offered as `gb_uncertainty`
    /// (realtime/uncertainty.wgsl; [`FrameIo::uncertainty_module`]).
    pub feature_uncertainty: Option<&'a wgpu::TextureView>,
    /// The composite's linear HDR image, one vec4 per pixel.
    pub hdr: &'a wgpu::Buffer,
    /// Every per-pixel allocation of the frame, textures findable by label.
    pub memory: &'a GpuMemory,
}

impl<'a> FrameIo<'a> {
    /// The module that gives a stage `defocus_sigma` ([`uncertainty_module`]).
    pub fn uncertainty_module(&self) -> &'static str {
        uncertainty_module(self.feature_uncertainty.is_some())
    }

    /// The frame's resources by WGSL name: `frame`, the G-buffer (`gb_*`, realtime/gbuffer_in.wgsl),
    /// the trace's light (`tr_*`, raw; a stage that filters offers its own `tr_matte` on top),
    /// object motion, the radiance cache's prior (`cache_prior`), and the previous depth, normal and object ids where they exist.
    pub fn bindings(&self) -> Bindings<'a> {
        let g = self.gbuffer;
        let t = self.trace;
        let mut b = Bindings::new()
            .buffer("frame", self.frame)
            .buffer_opt("prev_from_current", self.objects)
            .texture_opt("tri_now_texels", self.vertices.map(|v| v.0))
            .texture_opt("tri_prev_texels", self.vertices.map(|v| v.1))
            .texture("gb_depth", &g.depth.1)
            .texture("gb_normal", g.view(Channel::Normal))
            .texture("gb_motion", g.view(Channel::Motion))
            .texture("gb_base_color", g.view(Channel::BaseColor))
            .texture("gb_specular", g.view(Channel::Specular))
            .texture("gb_emission", g.view(Channel::Emission))
            .texture("gb_object", g.view(Channel::Ids))
            .texture("tr_matte", &t.matte.1)
            .texture("tr_direct", &t.direct.1)
            .texture_opt("cache_prior", self.cache_prior.map(|p| p.0))
            .texture_opt("cache_prior_m2", self.cache_prior.map(|p| p.1))
            .texture_opt("gb_uncertainty", self.feature_uncertainty);
        if let Some(gl) = &t.glossy {
            b = b.texture("tr_glossy", &gl.light.1);
            if let Some(r) = &gl.reflections {
                b = b
                    .texture("tr_reflection", &r.reflection.1)
                    .texture("tr_mirror", &r.mirror.1)
                    .texture("tr_mirror_hit", &r.mirror_hit.1);
            }
        }
        if let Some(m) = self.mixed {
            b = b.texture("tr_matte", &m.matte.1).texture("tr_direct", &m.direct.1);
            if let Some(g) = &m.glossy {
                b = b.texture("tr_glossy", &g.1);
            }
        }
        if let Some(p) = self.previous {
            b = b
                .texture("prev_depth", &p.depth.1)
                .texture("prev_normal", &p.normal.1)
                .texture("prev_object", &p.ids.1);
        }
        b
    }
}

/// With k > 1 samples per pixel (Voorhuis §5), the guide light after eq. (7): what the denoiser
/// and the composite read as `tr_matte`, `tr_direct` and `tr_glossy` in place of the trace's.
pub struct MixedLight {
    pub matte: crate::gpu::Tex,
    pub direct: crate::gpu::Tex,
    pub glossy: Option<crate::gpu::Tex>,
}

/// The previous frame's depth, normal and object ids: copied from the G-buffer after each frame
/// that a stage needing them ran in (16 bytes per pixel), made on first use.
pub struct PreviousGBuffer {
    pub depth: (wgpu::Texture, wgpu::TextureView),
    /// Octahedral normals, for the reprojections' normal test.
    pub normal: (wgpu::Texture, wgpu::TextureView),
    /// Object index and triangle slot, for SVGF's object test.
    pub ids: (wgpu::Texture, wgpu::TextureView),
}

impl PreviousGBuffer {
    pub fn new(device: &wgpu::Device, mem: &mut GpuMemory, size: (u32, u32)) -> PreviousGBuffer {
        // RENDER_ATTACHMENT: a change of size draws the old one's nearest texels into it
        // (passes/rescale.rs).
        let usage = wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::RENDER_ATTACHMENT;
        PreviousGBuffer {
            depth: mem.texture(
                device,
                "gbuffer/previous depth",
                size,
                super::gbuffer::DEPTH_FORMAT,
                usage,
            ),
            normal: mem.texture(
                device,
                "gbuffer/previous normal",
                size,
                GBufferTargets::format(Channel::Normal),
                usage,
            ),
            ids: mem.texture(
                device,
                "gbuffer/previous ids",
                size,
                GBufferTargets::format(Channel::Ids),
                usage,
            ),
        }
    }

    /// Record the copy of this frame's depth, normal and ids, after every stage read the previous.
    pub fn record_copy(
        &self,
        enc: &mut wgpu::CommandEncoder,
        g: &GBufferTargets,
        size: (u32, u32),
    ) {
        let extent = wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 };
        enc.copy_texture_to_texture(
            g.depth.0.as_image_copy(),
            self.depth.0.as_image_copy(),
            extent,
        );
        for (from, to) in [(Channel::Normal, &self.normal), (Channel::Ids, &self.ids)] {
            enc.copy_texture_to_texture(
                g.channel(from).0.as_image_copy(),
                to.0.as_image_copy(),
                extent,
            );
        }
    }
}
