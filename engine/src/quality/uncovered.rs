//! Which pixels a frame shows that the frame before did not: the CPU twin of
//! shaders/realtime/seen.wgsl (the radiance cache's prior and the trace's uncovered paths), from
//! the two frames' depth buffers. `hush-cli quality` scores these pixels, and the tests check
//! the GPU's choice against it.

use glam::{Mat4, Vec4};

/// A frame's depth buffer (reversed infinite Z, row-major, 0 where nothing was drawn) and the
/// unjittered view-projection it was drawn with.
pub struct DepthView<'a> {
    pub depth: &'a [f32],
    pub view_proj: Mat4,
}

/// What the frame before knew of a pixel's surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// The pixel shows no surface.
    Background,
    /// The previous depth holds the point's depth within 2% at one of the 3x3 texels it
    /// projects to.
    Seen,
    /// The point projects behind the previous camera or outside its image.
    OffScreen,
    /// The point projects into the previous image, where another depth was drawn.
    Hidden,
}

/// Per pixel of `now` (`size`): its surface was not seen by `before` (off screen or hidden).
pub fn uncovered(before: &DepthView, now: &DepthView, size: (u32, u32)) -> Vec<bool> {
    visibility(before, now, size)
        .into_iter()
        .map(|v| matches!(v, Visibility::OffScreen | Visibility::Hidden))
        .collect()
}

/// Per pixel of `now` (`size`), its [`Visibility`] in `before`: the pixel's point projected into
/// the previous camera, and the previous depth compared at each of the 3x3 texels there (both
/// depth buffers were drawn with a sub-pixel jitter, which on a grazing floor moves a texel's
/// depth by more than 2%; depth = clip z / w).
pub fn visibility(before: &DepthView, now: &DepthView, size: (u32, u32)) -> Vec<Visibility> {
    let (w, h) = (size.0 as i64, size.1 as i64);
    let inverse = now.view_proj.inverse();
    (0..(w * h) as usize)
        .map(|i| {
            let d = now.depth[i];
            if d <= 0.0 || !d.is_finite() {
                return Visibility::Background;
            }
            let (x, y) = ((i as i64 % w) as f32 + 0.5, (i as i64 / w) as f32 + 0.5);
            let ndc = Vec4::new(x / w as f32 * 2.0 - 1.0, 1.0 - y / h as f32 * 2.0, d, 1.0);
            let p = inverse * ndc;
            let c = before.view_proj * (p / p.w);
            if c.w <= 0.0 {
                return Visibility::OffScreen;
            }
            let tx = ((c.x / c.w + 1.0) * 0.5 * w as f32).floor() as i64;
            let ty = ((1.0 - c.y / c.w) * 0.5 * h as f32).floor() as i64;
            if tx < 0 || ty < 0 || tx >= w || ty >= h {
                return Visibility::OffScreen;
            }
            let expected = c.z / c.w;
            let seen =
                (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (tx + dx, ty + dy))).any(|(x, y)| {
                    let inside = x >= 0 && y >= 0 && x < w && y < h;
                    inside
                        && (before.depth[(y * w + x) as usize] - expected).abs() <= 0.02 * expected
                });
            if seen { Visibility::Seen } else { Visibility::Hidden }
        })
        .collect()
}
