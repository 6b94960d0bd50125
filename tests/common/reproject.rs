//! Eq. (11)'s reprojection distance on the CPU, as shaders/matte/common.wgsl measures it
//! (`world_from_depth`, `surface_frame`, `previous_distance`), for tests that check which pixels
//! the temporal stages keep or reset.

use glam::{Mat4, Vec3, Vec4};
use hush_engine::frame::CameraSetup;

/// One frame's depth buffer (Depth32Float texels read back) and its jittered inverse view-projection.
pub struct DepthFrame<'a> {
    pub depth: &'a [u8],
    pub inv_view_proj: Mat4,
    pub size: (u32, u32),
}

impl DepthFrame<'_> {
    /// The texel index of (x, y), None outside the frame.
    pub fn index(&self, x: i64, y: i64) -> Option<usize> {
        (x >= 0 && y >= 0 && x < self.size.0 as i64 && y < self.size.1 as i64)
            .then(|| (y * self.size.0 as i64 + x) as usize)
    }

    /// The rebased world position of the sample at (x, y); None outside the frame or without a surface.
    pub fn world(&self, x: i64, y: i64) -> Option<Vec3> {
        let i = self.index(x, y)?;
        let d = f32::from_le_bytes(self.depth[i * 4..i * 4 + 4].try_into().unwrap());
        if d <= 0.0 {
            return None;
        }
        let (w, h) = (self.size.0 as f32, self.size.1 as f32);
        let p = self.inv_view_proj
            * Vec4::new((x as f32 + 0.5) / w * 2.0 - 1.0, 1.0 - (y as f32 + 0.5) / h * 2.0, d, 1.0);
        Some(p.truncate() / p.w)
    }
}

/// A surface point with the frame eq. (11)'s distance is measured in: its normal, the pixel
/// footprint at its distance and how far the view's slant stretches it (at most 10x).
pub struct Surface {
    pub p: Vec3,
    pub n: Vec3,
    footprint: f32,
    stretch: f32,
}

impl Surface {
    pub fn new(p: Vec3, n: Vec3, camera: &CameraSetup, height: u32) -> Surface {
        let stretch = 1.0 / n.dot((camera.pos - p).normalize()).abs().max(0.1);
        let footprint = 2.0 * (p - camera.pos).dot(camera.fwd) * camera.up.length() / height as f32;
        Surface { p, n, footprint, stretch }
    }

    /// The distance to q in footprints: off the surface's plane as is, along it divided by the stretch.
    pub fn distance(&self, q: Vec3) -> f32 {
        let delta = q - self.p;
        let off_plane = self.n.dot(delta);
        off_plane.abs().max((delta - self.n * off_plane).length() / self.stretch) / self.footprint
    }
}

/// The 3x3 texels around (x, y) (the reprojection's search), in or out of the frame.
pub fn neighbours_3x3(x: i64, y: i64) -> impl Iterator<Item = (i64, i64)> {
    (-1..=1).flat_map(move |dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
}

/// The pixel position (x right, y down) of world point `p` under `view_proj`.
pub fn project(view_proj: &Mat4, p: Vec3, size: (u32, u32)) -> glam::Vec2 {
    let c = *view_proj * p.extend(1.0);
    let ndc = glam::Vec2::new(c.x, c.y) / c.w;
    glam::Vec2::new(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5)
        * glam::Vec2::new(size.0 as f32, size.1 as f32)
}

/// Where the ray through the centre of pixel (x, y) meets the plane of triangle `slot` of
/// `tris` (PreparedScene::tris): the exact hit the G-buffer rasterized there.
pub fn pixel_centre_hit(
    setup: &CameraSetup,
    size: (u32, u32),
    (x, y): (usize, usize),
    tris: &[Vec4],
    slot: u32,
) -> Vec3 {
    let ndc = glam::Vec2::new(
        (x as f32 + 0.5) / size.0 as f32 * 2.0 - 1.0,
        1.0 - (y as f32 + 0.5) / size.1 as f32 * 2.0,
    );
    let d = (setup.fwd + ndc.x * setup.right + ndc.y * setup.up).normalize();
    let v = |k: usize| tris[slot as usize * 3 + k].truncate();
    let n = (v(1) - v(0)).cross(v(2) - v(0));
    setup.pos + d * ((v(0) - setup.pos).dot(n) / d.dot(n))
}

/// A pixel with a surface in the frame after a step: its index, its surface for eq. (11), and
/// where its motion vector puts it in the previous frame (pixel coordinates, centres at +0.5).
pub struct Stepped {
    pub x: i64,
    pub y: i64,
    pub i: usize,
    pub surface: Surface,
    pub prev: (f32, f32),
}

/// Every pixel with a surface of `now`, from its G-buffer normal (octahedral half floats) and
/// motion vector (two half floats) read back.
pub fn stepped<'a>(
    now: &'a DepthFrame,
    normal: &'a [u8],
    motion: &'a [u8],
    camera: &'a CameraSetup,
) -> impl Iterator<Item = Stepped> + 'a {
    let (w, h) = (now.size.0 as i64, now.size.1 as i64);
    (0..h).flat_map(move |y| (0..w).map(move |x| (x, y))).filter_map(move |(x, y)| {
        let p = now.world(x, y)?;
        let i = now.index(x, y)?;
        let surface = Surface::new(p, crate::oct_normal(&normal[i * 4..]), camera, now.size.1);
        let prev = (
            x as f32 + 0.5 + crate::half(&motion[i * 4..]),
            y as f32 + 0.5 + crate::half(&motion[i * 4 + 2..]),
        );
        Some(Stepped { x, y, i, surface, prev })
    })
}

/// A camera step for the tests of what a move uncovers: the depth buffer `warm` still frames at
/// `from` left, then one frame at `to`, and both frames' jittered inverse view-projections.
pub struct CameraStep {
    pub depth0: Vec<u8>,
    pub inv0: Mat4,
    pub setup1: CameraSetup,
    pub inv1: Mat4,
}

/// Renders `warm` still frames at `from` and one at `to` with settings `s` (`warm` >= 1).
pub fn step_camera(
    r: &mut hush_engine::frame::Renderer,
    gpu: &hush_engine::gpu::Gpu,
    s: &hush_engine::settings::FrameSettings,
    (from, to): (hush_engine::scene::Camera, hush_engine::scene::Camera),
    warm: u32,
) -> CameraStep {
    use hush_engine::frame::{FrameInput, halton_jitter};
    let size = r.size();
    let render = |r: &mut hush_engine::frame::Renderer, camera| {
        r.render(gpu, &FrameInput { camera, time: 0.0, shutter: None }, s, None).unwrap()
    };
    for _ in 0..warm {
        render(r, from);
    }
    let (depth0, _) = r.read_texture(gpu, "gbuffer/depth").unwrap();
    render(r, to);
    let inv0 = r.camera_setup(&from).jittered(halton_jitter(warm - 1), size).inverse();
    let setup1 = r.camera_setup(&to);
    let inv1 = setup1.jittered(halton_jitter(warm), size).inverse();
    CameraStep { depth0, inv0, setup1, inv1 }
}
