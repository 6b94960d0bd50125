//! Images as Hush reads and writes them: the linear RGB [`Image`] the metrics compare, EXR and
//! PNG files, the sRGB curves, and the bounded decoding of PNG and JPEG that textures and
//! references share. Below both `scene` and `quality`, which each use it.

use anyhow::{Context, Result, anyhow, bail};
use glam::Vec3;
use std::path::Path;

/// A linear HDR RGB image, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub data: Vec<Vec3>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Image {
        Image { width, height, data: vec![Vec3::ZERO; (width * height) as usize] }
    }

    pub fn at(&self, x: u32, y: u32) -> Vec3 {
        self.data[(y * self.width + x) as usize]
    }

    /// An EXR (linear) or PNG/JPEG (sRGB, linearised) file, read within the default budgets
    /// ([`crate::limits::Limits`]): a regular file of bounded size whose header's size is checked
    /// before its pixels are decoded.
    pub fn load(path: &Path) -> Result<Image> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_lowercase();
        let limits = crate::limits::Limits::default();
        let bytes = crate::limits::read_regular_file(path, limits.file_bytes)?;
        let mut budget = crate::limits::Budget::new(limits);
        let name = path.display().to_string();
        if ext == "exr" {
            let (width, height, data) = decode_exr(&name, &bytes, &mut budget)?;
            return Ok(Image { width, height, data });
        }
        let img = decode_image(&name, &bytes, &mut budget)?.to_rgb32f();
        // 8-bit files hold display values: undo the sRGB curve so metrics compare radiance.
        let data = img
            .pixels()
            .map(|p| Vec3::new(srgb_to_linear(p[0]), srgb_to_linear(p[1]), srgb_to_linear(p[2])))
            .collect();
        Ok(Image { width: img.width(), height: img.height(), data })
    }

    pub fn save(&self, path: &Path) -> Result<()> {
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_lowercase()).as_deref() {
            Some("exr") => write_exr(path, self),
            Some("png") => write_png(path, self),
            _ => bail!("{}: output must end in .exr or .png", path.display()),
        }
    }

    /// Mean of `factor` x `factor` blocks (a box filter): how a low-resolution render of the same
    /// view relates to a high-resolution reference.
    pub fn box_downsample(&self, factor: u32) -> Result<Image> {
        if factor == 0 || !self.width.is_multiple_of(factor) || !self.height.is_multiple_of(factor)
        {
            bail!("cannot box-downsample {}x{} by {factor}", self.width, self.height);
        }
        let (w, h) = (self.width / factor, self.height / factor);
        let mut out = Image::new(w, h);
        let inv = 1.0 / (factor * factor) as f32;
        for y in 0..h {
            for x in 0..w {
                let mut s = Vec3::ZERO;
                for j in 0..factor {
                    for i in 0..factor {
                        s += self.at(x * factor + i, y * factor + j);
                    }
                }
                out.data[(y * w + x) as usize] = s * inv;
            }
        }
        Ok(out)
    }

    /// The image resampled to `width` x `height` bilinearly between pixel centres, edges
    /// clamped: a frame rendered at a resolution scale as the display's linear sampler
    /// stretches it over the full-size window. Written here because the `image` crate's resize
    /// clamps 32-bit float pixels to [0, 1], which would cut off HDR light.
    pub fn resized(&self, width: u32, height: u32) -> Result<Image> {
        if (width, height) == (self.width, self.height) {
            return Ok(self.clone());
        }
        if width == 0 || height == 0 || self.width == 0 || self.height == 0 {
            bail!("cannot resize {}x{} to {width}x{height}", self.width, self.height);
        }
        // Source coordinate of a destination pixel centre, and its two neighbours and weight.
        let taps = |dst: u32, src: u32| -> Vec<(u32, u32, f32)> {
            (0..dst)
                .map(|i| {
                    let x = ((i as f32 + 0.5) * src as f32 / dst as f32 - 0.5)
                        .clamp(0.0, (src - 1) as f32);
                    let x0 = x.floor() as u32;
                    (x0, (x0 + 1).min(src - 1), x - x0 as f32)
                })
                .collect()
        };
        let (xs, ys) = (taps(width, self.width), taps(height, self.height));
        let mut out = Image::new(width, height);
        for (y, &(y0, y1, fy)) in ys.iter().enumerate() {
            for (x, &(x0, x1, fx)) in xs.iter().enumerate() {
                let top = self.at(x0, y0).lerp(self.at(x1, y0), fx);
                let bottom = self.at(x0, y1).lerp(self.at(x1, y1), fx);
                out.data[y * width as usize + x] = top.lerp(bottom, fy);
            }
        }
        Ok(out)
    }

    pub fn nonfinite_pixels(&self) -> usize {
        self.data.iter().filter(|p| !p.is_finite()).count()
    }

    pub fn mean(&self) -> Vec3 {
        let s: glam::DVec3 = self.data.iter().map(|p| p.as_dvec3()).sum();
        (s / self.data.len().max(1) as f64).as_vec3()
    }
}

/// The first RGBA layer of an EXR held in memory, as linear RGB. Every layer's size is read
/// from the headers and charged to `budget` (12 bytes a pixel) before any pixel is allocated:
/// a header can declare 100000 x 50000 pixels in a few bytes.
pub fn decode_exr(
    name: &str,
    bytes: &[u8],
    budget: &mut crate::limits::Budget,
) -> Result<(u32, u32, Vec<Vec3>)> {
    use exr::prelude::*;
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| anyhow!("reading EXR {name}: {e}"))?;
    let largest = meta
        .headers
        .iter()
        .map(|h| h.layer_size)
        .max_by_key(|s| s.width().saturating_mul(s.height()));
    let size = largest.ok_or_else(|| anyhow!("reading EXR {name}: no layers"))?;
    budget.image(size.width() as u64, size.height() as u64, 12, format_args!("EXR {name}"))?;
    if size.width() > u32::MAX as usize || size.height() > u32::MAX as usize {
        bail!("reading EXR {name}: {}x{} pixels", size.width(), size.height());
    }
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |res, _| (res.width(), vec![Vec3::ZERO; res.width() * res.height()]),
            |(w, px): &mut (usize, Vec<Vec3>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * *w + pos.x()] = Vec3::new(r, g, b);
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| anyhow!("reading EXR {name}: {e}"))?;
    let size = img.layer_data.size;
    let (_, data) = img.layer_data.channel_data.pixels;
    Ok((size.width() as u32, size.height() as u32, data))
}

/// Linear HDR RGB, 32-bit float.
pub fn write_exr(path: &Path, img: &Image) -> Result<()> {
    let w = img.width as usize;
    exr::prelude::write_rgb_file(path, w, img.height as usize, |x, y| {
        let p = img.data[y * w + x];
        (p.x, p.y, p.z)
    })
    .map_err(|e| anyhow!("writing EXR {}: {e}", path.display()))
}

/// Tone-mapped sRGB PNG (see [`tonemap_srgb8`]).
pub fn write_png(path: &Path, img: &Image) -> Result<()> {
    let buf = image::RgbImage::from_raw(img.width, img.height, tonemap_srgb8(img))
        .ok_or_else(|| anyhow!("image size mismatch"))?;
    buf.save(path).with_context(|| format!("writing PNG {}", path.display()))
}

/// ACES filmic curve (Narkowicz 2015 fit) then the sRGB transfer function. Non-finite pixels
/// become black.
pub fn tonemap_srgb8(img: &Image) -> Vec<u8> {
    let aces = |x: f32| {
        let x = if x.is_finite() { x.max(0.0) } else { 0.0 };
        ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
    };
    img.data
        .iter()
        .flat_map(|p| [p.x, p.y, p.z])
        .map(|c| (linear_to_srgb(aces(c)) * 255.0 + 0.5) as u8)
        .collect()
}

pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// The sRGB transfer function's inverse (IEC 61966-2-1): an encoded value in [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// A PNG or JPEG decoded within `budget`: its header's size is charged (4 bytes a pixel, what
/// is kept) before decoding, and the decoder may allocate no more than that image at 16 bytes
/// a pixel (16-bit RGBA and its conversion), so a header that lies cannot make it allocate more.
pub fn decode_image(
    name: &str,
    bytes: &[u8],
    budget: &mut crate::limits::Budget,
) -> Result<image::DynamicImage> {
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .with_context(|| format!("reading image {name}"))
    };
    let (w, h) = reader()?.into_dimensions().with_context(|| format!("decoding image {name}"))?;
    budget.image(w as u64, h as u64, 4, format_args!("image {name}"))?;
    let mut r = reader()?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(w);
    limits.max_image_height = Some(h);
    limits.max_alloc = Some((w as u64 * h as u64 * 16).max(1 << 20));
    r.limits(limits);
    r.decode().with_context(|| format!("decoding image {name}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resizing_keeps_a_flat_image_and_interpolates_a_ramp() {
        let mut img = Image::new(4, 2);
        for (i, p) in img.data.iter_mut().enumerate() {
            *p = Vec3::splat((i % 4) as f32);
        }
        let up = img.resized(8, 4).unwrap();
        assert_eq!((up.width, up.height), (8, 4));
        // Rows stay identical, columns rise monotonically from the first value to the last.
        let row: Vec<f32> = (0..8).map(|x| up.at(x, 1).x).collect();
        assert!(row.windows(2).all(|w| w[1] >= w[0]), "{row:?}");
        assert!(row[0] >= 0.0 && row[7] <= 3.0 && row[7] > row[0], "{row:?}");
        let flat = Image { width: 3, height: 3, data: vec![Vec3::new(0.5, 1.0, 2.0); 9] };
        assert!(
            flat.resized(7, 5)
                .unwrap()
                .data
                .iter()
                .all(|p| (*p - Vec3::new(0.5, 1.0, 2.0)).abs().max_element() < 1e-6)
        );
        assert!(img.resized(0, 4).is_err());
    }
}
