use crate::image_io::{decode_image, linear_to_srgb, srgb_to_linear};
use crate::limits::Budget;
use anyhow::Result;
use glam::{Affine2, Mat2, Vec2};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Wrap {
    Repeat,
    Clamp,
    Mirror,
}

/// An 8-bit RGBA image as the GPU samples it.
#[derive(Clone, Debug)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
    /// Colour data stored in sRGB (base colour, emissive); linear data otherwise.
    pub srgb: bool,
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
    /// The sampler's magFilter is NEAREST: texels are read unfiltered (pixel art, lookup
    /// tables); otherwise bilinear.
    pub nearest: bool,
}

/// A material's use of a texture: which texture, read at which of the mesh's texture
/// coordinate sets, through which affine map (glTF `textureInfo.texCoord` and
/// `KHR_texture_transform`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    pub index: u32,
    /// TEXCOORD_0 or TEXCOORD_1.
    pub set: u32,
    /// Applied to the coordinates before the lookup: KHR_texture_transform's
    /// offset x rotation x scale, identity without it.
    pub transform: Affine2,
}

impl TextureRef {
    /// Texture `index` at TEXCOORD_0, untransformed.
    pub fn new(index: u32) -> TextureRef {
        TextureRef { index, set: 0, transform: Affine2::IDENTITY }
    }

    /// Read at TEXCOORD_0 as stored: the shaders need no per-texture coordinate table for it.
    pub fn is_plain(&self) -> bool {
        self.set == 0 && self.transform == Affine2::IDENTITY
    }

    /// KHR_texture_transform's matrix, T x R x S as the extension's specification writes it:
    /// `rotation` radians counter-clockwise in UV space (the image turns clockwise).
    pub fn khr_transform(offset: Vec2, rotation: f32, scale: Vec2) -> Affine2 {
        let (s, c) = rotation.sin_cos();
        Affine2::from_mat2_translation(
            Mat2::from_cols(
                Vec2::new(c * scale.x, -s * scale.x),
                Vec2::new(s * scale.y, c * scale.y),
            ),
            offset,
        )
    }
}

/// Texels of a full mip chain from `w` x `h` down to 1 x 1, base level included.
pub fn mip_chain_texels(w: u32, h: u32) -> usize {
    let (mut w, mut h, mut n) = (w.max(1), h.max(1), 0usize);
    loop {
        n += w as usize * h as usize;
        if w == 1 && h == 1 {
            return n;
        }
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
    }
}

impl Texture {
    /// The mip levels below this one, each half the one above (at least one texel a side) down
    /// to 1 x 1: every texel the mean of the 2 x 2 texels it covers (the last row or column of
    /// an odd side counted into its neighbour's), averaged in linear light where the texture
    /// is sRGB, so that a coarse level has the mean colour of what it covers (the image
    /// crate's filters average the stored, encoded values).
    pub fn mips(&self) -> Vec<(u32, u32, Vec<u8>)> {
        let mut levels = vec![];
        if self.rgba8.len() != self.width as usize * self.height as usize * 4 {
            return levels;
        }
        let decode: Vec<f32> = (0..=255u8)
            .map(|v| v as f32 / 255.0)
            .map(|c| if self.srgb { srgb_to_linear(c) } else { c })
            .collect();
        let mut w = self.width as usize;
        let mut h = self.height as usize;
        let mut cur: Vec<f32> = self.rgba8.iter().map(|&v| decode[v as usize]).collect();
        // Alpha is linear in both encodings.
        if self.srgb {
            for (i, c) in cur.iter_mut().enumerate() {
                if i % 4 == 3 {
                    *c = self.rgba8[i] as f32 / 255.0;
                }
            }
        }
        while w > 1 || h > 1 {
            let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
            let mut next = vec![0f32; nw * nh * 4];
            for y in 0..h {
                let ny = (y / 2).min(nh - 1);
                for x in 0..w {
                    let nx = (x / 2).min(nw - 1);
                    for k in 0..4 {
                        next[(ny * nw + nx) * 4 + k] += cur[(y * w + x) * 4 + k];
                    }
                }
            }
            // How many texels fell into each: 2 x 2, more along an odd side's last row/column.
            for ny in 0..nh {
                let rows = if nh == 1 {
                    h
                } else if ny + 1 == nh {
                    h - 2 * ny
                } else {
                    2
                };
                for nx in 0..nw {
                    let cols = if nw == 1 {
                        w
                    } else if nx + 1 == nw {
                        w - 2 * nx
                    } else {
                        2
                    };
                    let inv = 1.0 / (rows * cols) as f32;
                    for k in 0..4 {
                        next[(ny * nw + nx) * 4 + k] *= inv;
                    }
                }
            }
            let bytes = next
                .iter()
                .enumerate()
                .map(|(i, &c)| {
                    let e = if self.srgb && i % 4 != 3 { linear_to_srgb(c) } else { c };
                    (e.clamp(0.0, 1.0) * 255.0).round() as u8
                })
                .collect();
            levels.push((nw as u32, nh as u32, bytes));
            (w, h, cur) = (nw, nh, next);
        }
        levels
    }

    /// Half the resolution in each direction (a box-filtered mip level); None if the texels do
    /// not fill width x height.
    pub fn halved(&self) -> Option<Texture> {
        let img = image::RgbaImage::from_raw(self.width, self.height, self.rgba8.clone())?;
        let (w, h) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let img = image::imageops::resize(&img, w, h, image::imageops::FilterType::Triangle);
        Some(Texture {
            width: w,
            height: h,
            rgba8: img.into_raw(),
            name: self.name.clone(),
            ..*self
        })
    }

    /// Decode a PNG/JPEG, shrinking it (by halving) until neither side exceeds `max_size`, so
    /// scenes with many 4K textures fit a GPU's storage-buffer limits. The size comes from the
    /// image's header and is checked against `budget` (4 bytes a pixel) before anything is
    /// decoded; the decoder is held to that size.
    pub fn decode(
        name: &str,
        bytes: &[u8],
        srgb: bool,
        max_size: u32,
        budget: &mut Budget,
    ) -> Result<Texture> {
        let img = decode_image(name, bytes, budget)?;
        let mut img = img.to_rgba8();
        while img.width().max(img.height()) > max_size.max(1) {
            let (w, h) = ((img.width() / 2).max(1), (img.height() / 2).max(1));
            img = image::imageops::resize(&img, w, h, image::imageops::FilterType::Triangle);
        }
        Ok(Texture {
            name: name.to_string(),
            width: img.width(),
            height: img.height(),
            rgba8: img.into_raw(),
            srgb,
            wrap_s: Wrap::Repeat,
            wrap_t: Wrap::Repeat,
            nearest: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(w: u32, h: u32, rgba8: Vec<u8>, srgb: bool) -> Texture {
        Texture {
            name: "t".into(),
            width: w,
            height: h,
            rgba8,
            srgb,
            wrap_s: Wrap::Repeat,
            wrap_t: Wrap::Repeat,
            nearest: false,
        }
    }

    #[test]
    fn mips_halve_to_one_texel_and_count_what_the_packer_allocates() {
        let t = texture(5, 3, vec![9; 5 * 3 * 4], false);
        let sizes: Vec<(u32, u32)> = t.mips().iter().map(|(w, h, _)| (*w, *h)).collect();
        assert_eq!(sizes, [(2, 1), (1, 1)]);
        let texels: usize = 15 + t.mips().iter().map(|(w, h, _)| (w * h) as usize).sum::<usize>();
        assert_eq!(mip_chain_texels(5, 3), texels);
        // A constant stays constant, odd rows and columns folded in.
        assert!(t.mips().iter().all(|(_, _, b)| b.iter().all(|&v| v == 9)));
    }

    #[test]
    fn srgb_mips_average_light_not_code_values() {
        // Black and white: the mean light is 0.5, which sRGB stores as 188, not 128.
        let t = texture(2, 1, vec![0, 0, 0, 0, 255, 255, 255, 255], true);
        let level = &t.mips()[0].2;
        assert_eq!(&level[..3], &[188, 188, 188]);
        // Alpha is linear: the mean of 0 and 255.
        assert_eq!(level[3], 128);
        let linear = texture(2, 1, vec![0, 0, 0, 0, 255, 255, 255, 255], false);
        assert_eq!(&linear.mips()[0].2[..], &[128, 128, 128, 128]);
    }
}
