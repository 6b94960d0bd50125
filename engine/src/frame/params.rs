//! The per-frame uniform (mirror of `Frame` in shaders/realtime/frame.wgsl) and the camera
//! matrices behind it.

use crate::passes::io::ChainView;
use crate::scene::Camera;
use bytemuck::{Pod, Zeroable};
use glam::{DMat4, DVec3, Mat4, Vec2, Vec3};

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameParams {
    pub view_proj: [[f32; 4]; 4],
    pub unjittered_view_proj: [[f32; 4]; 4],
    pub prev_view_proj: [[f32; 4]; 4],
    pub cam_pos: [f32; 4],
    pub cam_right: [f32; 4],
    pub cam_up: [f32; 4],
    pub cam_fwd: [f32; 4],
    pub jitter: [f32; 2],
    pub size: [u32; 2],
    pub index: u32,
    pub exposure: f32,
    pub accumulated: u32,
    pub paths: u32,
    /// Glossy surfaces below this roughness also trace their representative (mirror) ray for
    /// the glossy chain's reflection motion vectors (0: none do).
    pub representative_roughness: f32,
    /// Samples per pixel k (Voorhuis §5): the raster's guide and k - 1 traced ones.
    pub samples: u32,
    /// Frames between two samples of a pixel, 1 / f (1: every pixel every frame; passes/schedule.rs).
    pub period: u32,
    /// Primary samples per pixel k of the traced primaries (realtime/primaries.wgsl), where a
    /// thin lens makes the primary hit random; 0: the raster's G-buffer.
    pub primary_samples: u32,
    /// On the first frame after a change of size whose histories were resampled to it
    /// (passes/rescale.rs): the most frames a history may count; 0 on every other frame.
    pub rescaled_frames: f32,
    /// Paths per pixel where the pixel's surface was not on screen last frame
    /// (`FrameSettings::uncovered_paths`); 0 where there is no history to restart or nothing
    /// moved.
    pub uncovered_paths: u32,
    /// Where in its pixels the last frame's raster sampled (its `jitter`): its depth texel t
    /// holds the surface at pixel position t + this (realtime/uncovered.wgsl).
    pub prev_jitter_x: f32,
    pub prev_jitter_y: f32,
    /// [`ChainView::inv_view_proj`], [`ChainView::prev_inv_view_proj`]: what every temporal
    /// stage reprojects with.
    pub inv_view_proj: [[f32; 4]; 4],
    pub prev_inv_view_proj: [[f32; 4]; 4],
    /// [`ChainView::jitter_shift`].
    pub jitter_shift: [f32; 2],
    /// [`ChainView::history_valid`].
    pub history_valid: u32,
    /// [`ChainView::static_view`].
    pub static_view: u32,
    /// [`crate::settings::ReprojectionSettings::d0_px`] and `d1_px` (d1 above d0).
    pub d0_px: f32,
    pub d1_px: f32,
    /// [`crate::settings::FrameSettings::inject_nonfinite`].
    pub inject_nonfinite: u32,
    /// [`crate::settings::FrameSettings::light_candidates`] (1: no resampling).
    pub light_candidates: u32,
}

impl FrameParams {
    /// The two frames' cameras and history state as the temporal stages read them.
    pub fn set_view(&mut self, view: &ChainView) {
        self.inv_view_proj = view.inv_view_proj.to_cols_array_2d();
        self.prev_inv_view_proj = view.prev_inv_view_proj.to_cols_array_2d();
        self.jitter_shift = view.jitter_shift.to_array();
        self.history_valid = view.history_valid as u32;
        self.static_view = view.static_view as u32;
    }

    /// `jittered`: this frame's view-projection with `jitter` (the raster's); `prev`: the last
    /// frame's without jitter (motion vectors compare it with `cam.view_proj`).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        cam: &CameraSetup,
        jittered: Mat4,
        prev: Mat4,
        jitter: Vec2,
        size: (u32, u32),
        index: u32,
        settings: &crate::settings::FrameSettings,
        accumulated: u32,
        ray_epsilon: f32,
        representative_roughness: f32,
    ) -> FrameParams {
        let r = &settings.reprojection;
        FrameParams {
            view_proj: jittered.to_cols_array_2d(),
            unjittered_view_proj: cam.view_proj.to_cols_array_2d(),
            prev_view_proj: prev.to_cols_array_2d(),
            cam_pos: cam.pos.extend(ray_epsilon).to_array(),
            cam_right: cam.right.extend(0.0).to_array(),
            cam_up: cam.up.extend(0.0).to_array(),
            cam_fwd: cam.fwd.extend(0.0).to_array(),
            jitter: jitter.to_array(),
            size: [size.0, size.1],
            index,
            exposure: settings.exposure_scale(),
            accumulated,
            paths: settings.paths_per_pixel.clamp(1, crate::settings::MAX_PATHS_PER_PIXEL),
            representative_roughness,
            samples: if accumulated > 0 {
                1
            } else {
                settings.samples_per_pixel.clamp(1, crate::settings::MAX_SAMPLES_PER_PIXEL)
            },
            period: if accumulated > 0 { 1 } else { settings.sample_fraction.period() },
            primary_samples: 0,
            rescaled_frames: 0.0,
            uncovered_paths: 0,
            prev_jitter_x: jitter.x,
            prev_jitter_y: jitter.y,
            inv_view_proj: jittered.inverse().to_cols_array_2d(),
            prev_inv_view_proj: jittered.inverse().to_cols_array_2d(),
            jitter_shift: [0.0; 2],
            history_valid: 0,
            static_view: 0,
            d0_px: r.d0_px.max(0.0),
            d1_px: r.d1_px.max(r.d0_px + 1e-3),
            inject_nonfinite: settings.inject_nonfinite as u32,
            light_candidates: settings
                .light_candidates
                .clamp(1, crate::settings::MAX_LIGHT_CANDIDATES),
        }
    }
}

/// A camera in the GPU scene's rebased space, as both the raster and the tracer see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSetup {
    pub pos: Vec3,
    pub right: Vec3,
    pub up: Vec3,
    pub fwd: Vec3,
    /// World -> clip, reversed infinite Z, no jitter.
    pub view_proj: Mat4,
}

impl CameraSetup {
    /// `near`: the near plane in scene units (reversed Z keeps precision far beyond it).
    pub fn new(camera: &Camera, origin: DVec3, size: (u32, u32), near: f32) -> CameraSetup {
        let m = DMat4::from_translation(-origin) * camera.world;
        let pos = m.w_axis.truncate().as_vec3();
        let x = m.transform_vector3(DVec3::X).normalize_or(DVec3::X).as_vec3();
        let y = m.transform_vector3(DVec3::Y).normalize_or(DVec3::Y).as_vec3();
        let z = m.transform_vector3(DVec3::Z).normalize_or(DVec3::Z).as_vec3();
        // The same field of view clamp as the reference tracer (passes/reference.rs).
        let fov = if camera.yfov.is_finite() { camera.yfov.clamp(1e-4, 3.1) } else { 0.8 };
        let th = (fov * 0.5).tan();
        let aspect = size.0 as f32 / size.1 as f32;
        let view =
            Mat4::from_cols(x.extend(0.0), y.extend(0.0), z.extend(0.0), pos.extend(1.0)).inverse();
        // Right-handed, depth in [0, 1] reversed (1 at `near`, 0 at infinity): float depth then
        // keeps its precision with distance.
        let f = 1.0 / th;
        let proj = Mat4::from_cols(
            glam::Vec4::new(f / aspect, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, f, 0.0, 0.0),
            glam::Vec4::new(0.0, 0.0, 0.0, -1.0),
            glam::Vec4::new(0.0, 0.0, near, 0.0),
        );
        CameraSetup { pos, right: x * th * aspect, up: y * th, fwd: -z, view_proj: proj * view }
    }

    /// The projection shifted so that pixel centres sample `jitter` (in [0, 1)^2) of each pixel.
    pub fn jittered(&self, jitter: Vec2, size: (u32, u32)) -> Mat4 {
        let o = Vec2::new(
            (0.5 - jitter.x) * 2.0 / size.0 as f32,
            -(0.5 - jitter.y) * 2.0 / size.1 as f32,
        );
        Mat4::from_translation(o.extend(0.0)) * self.view_proj
    }
}

/// Uniform in [0, 1)^2 from (frame, seed): the accumulate mode's pixel sample positions.
pub fn random_jitter(frame: u32, seed: u32) -> Vec2 {
    let h = |v: u32| {
        let s = v.wrapping_mul(747796405).wrapping_add(2891336453);
        let w = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277803737);
        (w >> 22) ^ w
    };
    let a = h(frame ^ h(seed ^ 0x9e3779b9));
    let b = h(a);
    Vec2::new((a >> 8) as f32 / 16777216.0, (b >> 8) as f32 / 16777216.0)
}
