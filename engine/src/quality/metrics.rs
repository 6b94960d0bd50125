use super::{Image, ssim_luma};
use anyhow::{Context, Result, bail};
use glam::Vec3;
use serde::Serialize;

/// The oracle's metrics (README "Metrics"): x = test, y = reference, linear RGB.
#[derive(Clone, Debug, Serialize)]
pub struct Metrics {
    pub rmse: f64,
    pub relmse: f64,
    pub mae: f64,
    /// Per channel (mean x - mean y) / mean y.
    pub mean_rel_bias: [f64; 3],
    pub ssim: f64,
    pub flip: f64,
    pub nonfinite_pixels: usize,
}

pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Non-finite test pixels are zeroed before the other metrics (and counted).
fn sanitized(img: &Image) -> Image {
    let data = img.data.iter().map(|p| if p.is_finite() { *p } else { Vec3::ZERO }).collect();
    Image { data, ..*img }
}

fn check_sizes(x: &Image, y: &Image) -> Result<()> {
    if (x.width, x.height) != (y.width, y.height) {
        bail!("image sizes differ: {}x{} vs {}x{}", x.width, x.height, y.width, y.height);
    }
    if x.data.is_empty() {
        bail!("images are empty");
    }
    Ok(())
}

pub fn rmse(x: &Image, y: &Image) -> f64 {
    let s: f64 =
        x.data.iter().zip(&y.data).map(|(a, b)| (*a - *b).as_dvec3().length_squared()).sum();
    (s / (3 * x.data.len()) as f64).sqrt()
}

/// Rousselle et al. 2011: mean over pixels and channels of (x-y)^2 / (y^2 + 0.01).
pub fn relmse(x: &Image, y: &Image) -> f64 {
    let mut s = 0.0f64;
    for (a, b) in x.data.iter().zip(&y.data) {
        for k in 0..3 {
            let (a, b) = (a[k] as f64, b[k] as f64);
            s += (a - b) * (a - b) / (b * b + 0.01);
        }
    }
    s / (3 * x.data.len()) as f64
}

/// T(x) = clamp(x, 0, 1)^(1/2.2), the oracle's display transform for SSIM and FLIP.
pub fn display(c: f32) -> f32 {
    c.clamp(0.0, 1.0).powf(1.0 / 2.2)
}

/// LDR-FLIP (nv-flip, 67 pixels per degree) of T(x) against T(y).
pub fn flip_ldr(x: &Image, y: &Image) -> f64 {
    let err = flip_error(x, y);
    nv_flip::FlipPool::from_image(&err).mean() as f64
}

/// Per-pixel LDR-FLIP of T(x) against T(y), row-major (to score a region of the image).
pub fn flip_map(x: &Image, y: &Image) -> Vec<f32> {
    flip_error(x, y).to_vec()
}

/// Mean LDR-FLIP of x against y over the pixels where `region` is true (row-major), and how
/// many there are; None where the region is empty.
pub fn flip_over(x: &Image, y: &Image, region: &[bool]) -> Option<(f64, usize)> {
    if !region.iter().any(|r| *r) {
        return None;
    }
    region_mean(&flip_map(x, y), region)
}

/// Mean of a per-pixel map (as `flip_map` returns) over the pixels where `region` is true, and
/// how many there are; None where the region is empty.
pub fn region_mean(map: &[f32], region: &[bool]) -> Option<(f64, usize)> {
    let (sum, n) = map
        .iter()
        .zip(region)
        .filter(|(_, r)| **r)
        .fold((0.0f64, 0usize), |(s, n), (e, _)| (s + *e as f64, n + 1));
    (n > 0).then(|| (sum / n as f64, n))
}

/// The per-pixel LDR-FLIP of `x` against `y` in FLIP's magma colour map (black: no visible
/// difference), as FLIP's own tool draws it, written as a PNG.
pub fn save_flip_heatmap(x: &Image, y: &Image, path: &std::path::Path) -> Result<()> {
    check_sizes(x, y)?;
    let rgb = flip_error(x, y).apply_color_lut(&nv_flip::magma_lut());
    image::RgbImage::from_raw(x.width, x.height, rgb.to_vec())
        .ok_or_else(|| anyhow::anyhow!("FLIP map of {}x{} has the wrong size", x.width, x.height))?
        .save(path)
        .with_context(|| format!("writing {}", path.display()))
}

fn flip_error(x: &Image, y: &Image) -> nv_flip::FlipImageFloat {
    let to8 = |img: &Image| -> Vec<u8> {
        img.data
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .map(|c| (display(if c.is_finite() { c } else { 0.0 }) * 255.0 + 0.5) as u8)
            .collect()
    };
    let t = nv_flip::FlipImageRgb8::with_data(x.width, x.height, &to8(x));
    let r = nv_flip::FlipImageRgb8::with_data(y.width, y.height, &to8(y));
    nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE)
}

pub fn compare(test: &Image, reference: &Image) -> Result<Metrics> {
    Ok(metrics(test, reference)?.0)
}

/// `compare`, and the per-pixel FLIP map it averaged (as `flip_map`), for scoring a region of
/// the same frame without computing FLIP twice.
pub fn compare_with_flip_map(test: &Image, reference: &Image) -> Result<(Metrics, Vec<f32>)> {
    let (m, flip) = metrics(test, reference)?;
    Ok((m, flip.to_vec()))
}

fn metrics(test: &Image, reference: &Image) -> Result<(Metrics, nv_flip::FlipImageFloat)> {
    check_sizes(test, reference)?;
    let nonfinite_pixels = test.nonfinite_pixels();
    let x = sanitized(test);
    let y = sanitized(reference);
    let n = x.data.len() as f64;
    let mae = x
        .data
        .iter()
        .zip(&y.data)
        .map(|(a, b)| (*a - *b).abs().as_dvec3().element_sum())
        .sum::<f64>()
        / (3.0 * n);
    let (mx, my) = (x.mean().as_dvec3(), y.mean().as_dvec3());
    let bias = [0, 1, 2].map(|k| if my[k] != 0.0 { (mx[k] - my[k]) / my[k] } else { 0.0 });
    let flip = flip_error(&x, &y);
    let metrics = Metrics {
        rmse: rmse(&x, &y),
        relmse: relmse(&x, &y),
        mae,
        mean_rel_bias: bias,
        ssim: ssim_luma(&x, &y),
        flip: nv_flip::FlipPool::from_image(&flip).mean() as f64,
        nonfinite_pixels,
    };
    Ok((metrics, flip))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(w: u32, h: u32, mut f: impl FnMut(u32, u32) -> Vec3) -> Image {
        let mut i = Image::new(w, h);
        for y in 0..h {
            for x in 0..w {
                i.data[(y * w + x) as usize] = f(x, y);
            }
        }
        i
    }

    #[test]
    fn identical_images_score_perfectly() {
        let a = img(32, 24, |x, y| Vec3::new(x as f32 / 32.0, y as f32 / 24.0, 0.5));
        let m = compare(&a, &a).unwrap();
        assert_eq!(m.rmse, 0.0);
        assert_eq!(m.relmse, 0.0);
        assert!((m.ssim - 1.0).abs() < 1e-9, "ssim {}", m.ssim);
        assert!(m.flip < 1e-6, "flip {}", m.flip);
    }

    #[test]
    fn relmse_matches_hand_computation() {
        let a = img(2, 1, |x, _| Vec3::splat(if x == 0 { 1.0 } else { 0.0 }));
        let b = img(2, 1, |_, _| Vec3::splat(0.5));
        // Each channel: (0.5^2)/(0.25+0.01) for both pixels.
        let want = 0.25 / 0.26;
        assert!((relmse(&a, &b) - want).abs() < 1e-9);
        assert!((rmse(&a, &b) - 0.5).abs() < 1e-9);
    }

    #[test]
    fn nonfinite_pixels_are_counted_and_zeroed() {
        let mut a = img(16, 16, |_, _| Vec3::splat(0.3));
        a.data[5] = Vec3::new(f32::NAN, 0.0, 0.0);
        a.data[6] = Vec3::splat(f32::INFINITY);
        let b = img(16, 16, |_, _| Vec3::splat(0.3));
        let m = compare(&a, &b).unwrap();
        assert_eq!(m.nonfinite_pixels, 2);
        assert!(m.rmse.is_finite() && m.relmse.is_finite() && m.ssim.is_finite());
    }

    #[test]
    fn noise_lowers_ssim_and_raises_flip() {
        let a = img(64, 64, |x, y| Vec3::splat(((x / 8 + y / 8) % 2) as f32 * 0.8));
        let mut s = 1u32;
        let b = img(64, 64, |x, y| {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            a.at(x, y) + Vec3::splat((s >> 8) as f32 / (1u32 << 24) as f32 * 0.4 - 0.2)
        });
        let m = compare(&b, &a).unwrap();
        assert!(m.ssim < 0.9 && m.ssim > 0.0, "ssim {}", m.ssim);
        assert!(m.flip > 0.02, "flip {}", m.flip);
    }
}
