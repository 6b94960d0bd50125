use crate::limits::Budget;
use anyhow::{Context, Result};
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

impl Texture {
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

/// A PNG or JPEG decoded within `budget`: its header's size is charged (4 bytes a pixel, what
/// is kept) before decoding, and the decoder may allocate no more than that image at 16 bytes
/// a pixel (16-bit RGBA and its conversion), so a header that lies cannot make it allocate more.
pub fn decode_image(name: &str, bytes: &[u8], budget: &mut Budget) -> Result<image::DynamicImage> {
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
