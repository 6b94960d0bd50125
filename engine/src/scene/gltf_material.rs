//! glTF materials and their textures: metallic-roughness, `KHR_materials_specular`,
//! `KHR_materials_emissive_strength`, alpha modes, samplers; each image decoded once per colour
//! space under the load budget.

use super::files::{read_uri, short};
use super::gltf_importer::{Importer, TextureSlots};
use super::{Material, Texture, TextureRef, Wrap};
use crate::limits::is_over_budget;
use anyhow::Result;
use glam::{Vec3, Vec4};
use std::collections::HashMap;

impl Importer<'_> {
    /// Decode every texture a material uses, each image once per colour space. A texture that
    /// cannot be read is a warning and a neutral fallback (the material renders with its factors
    /// alone); one over a budget is an error.
    pub(super) fn load_textures(
        &mut self,
        doc: &gltf::Document,
        buffers: &[Vec<u8>],
    ) -> Result<(Vec<Texture>, TextureSlots)> {
        // Which textures are colour (sRGB) and which are data.
        let mut uses: Vec<(usize, bool)> = vec![];
        for m in doc.materials() {
            let pbr = m.pbr_metallic_roughness();
            let mut add = |t: Option<gltf::Texture>, srgb: bool| {
                if let Some(t) = t
                    && !uses.contains(&(t.index(), srgb))
                {
                    uses.push((t.index(), srgb));
                }
            };
            add(pbr.base_color_texture().map(|i| i.texture()), true);
            add(pbr.metallic_roughness_texture().map(|i| i.texture()), false);
            add(m.normal_texture().map(|i| i.texture()), false);
            add(m.emissive_texture().map(|i| i.texture()), true);
        }
        let mut textures: Vec<Texture> = vec![];
        let mut map = HashMap::new();
        // (image, sRGB) -> its first texture: an image shared by textures is decoded once, and
        // copied only for a texture that samples it with other wrap modes.
        let mut first: HashMap<(usize, bool), Option<usize>> = HashMap::new();
        let mut placed: HashMap<(usize, bool, Wrap, Wrap), usize> = HashMap::new();
        let wrap = |w: gltf::texture::WrappingMode| match w {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let all: Vec<gltf::Texture> = doc.textures().collect();
        for (ti, srgb) in uses {
            let Some(t) = all.get(ti) else { continue };
            let img = t.source();
            let key = (img.index(), srgb);
            let decoded = match first.get(&key) {
                Some(slot) => *slot,
                None => {
                    let slot = self.decode_image(&img, buffers, srgb)?.map(|tex| {
                        textures.push(tex);
                        textures.len() - 1
                    });
                    first.insert(key, slot);
                    slot
                }
            };
            let Some(decoded) = decoded else { continue };
            let (ws, wt) = (wrap(t.sampler().wrap_s()), wrap(t.sampler().wrap_t()));
            let index = match placed.get(&(key.0, key.1, ws, wt)) {
                Some(&i) => i,
                None if !placed.keys().any(|k| (k.0, k.1) == key) => {
                    textures[decoded].wrap_s = ws;
                    textures[decoded].wrap_t = wt;
                    decoded
                }
                None => {
                    let copy = Texture { wrap_s: ws, wrap_t: wt, ..textures[decoded].clone() };
                    self.budget.decode(copy.rgba8.len() as u64, format_args!("textures[{ti}]"))?;
                    textures.push(copy);
                    textures.len() - 1
                }
            };
            placed.insert((key.0, key.1, ws, wt), index);
            map.insert((ti, srgb), index as u32);
        }
        Ok((textures, map))
    }

    /// One image decoded, or None with a warning where it cannot be read (a budget overrun is an
    /// error: the scene would render, but not as its author meant, and the user can raise it).
    fn decode_image(
        &mut self,
        img: &gltf::Image,
        buffers: &[Vec<u8>],
        srgb: bool,
    ) -> Result<Option<Texture>> {
        let limit = self.budget.limits.file_bytes;
        let (label, bytes) = match img.source() {
            gltf::image::Source::Uri { uri, .. } => {
                (short(uri), read_uri(self.files, uri, limit).map_err(|e| format!("{e:#}")))
            }
            gltf::image::Source::View { view, .. } => {
                let b =
                    buffers.get(view.buffer().index()).map(|b| b.as_slice()).unwrap_or_default();
                let r = view
                    .offset()
                    .checked_add(view.length())
                    .and_then(|end| b.get(view.offset()..end));
                (
                    format!("images[{}]", img.index()),
                    r.map(|s| s.to_vec()).ok_or("its bufferView runs past its buffer".into()),
                )
            }
        };
        let bytes = match bytes {
            Ok(b) => b,
            Err(e) => {
                self.warn(format!("texture {label}: {e}; rendering without it"));
                return Ok(None);
            }
        };
        match Texture::decode(&label, &bytes, srgb, self.max_texture_size, &mut self.budget) {
            Ok(t) => Ok(Some(t)),
            Err(e) if is_over_budget(&e) => Err(e),
            Err(e) => {
                self.warn(format!("texture {label}: {e:#}; rendering without it"));
                Ok(None)
            }
        }
    }

    fn tex(
        &mut self,
        map: &HashMap<(usize, bool), u32>,
        t: Option<(gltf::Texture, u32)>,
        srgb: bool,
    ) -> Option<TextureRef> {
        let (t, set) = t?;
        if set != 0 {
            self.warn(format!(
                "textures[{}] is used with TEXCOORD_{set}; only TEXCOORD_0 is supported",
                t.index()
            ));
        }
        map.get(&(t.index(), srgb)).map(|&index| TextureRef { index })
    }

    pub(super) fn material(
        &mut self,
        m: &gltf::Material,
        tex: &HashMap<(usize, bool), u32>,
    ) -> Material {
        let pbr = m.pbr_metallic_roughness();
        let (specular_factor, specular_color) = match m.specular() {
            Some(s) => {
                if s.specular_texture().is_some() || s.specular_color_texture().is_some() {
                    self.warn(format!(
                        "material {:?}: specular textures are not supported",
                        m.name()
                    ));
                }
                (s.specular_factor(), Vec3::from(s.specular_color_factor()))
            }
            None => (1.0, Vec3::ONE),
        };
        let alpha_mode = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => super::AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => {
                super::AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5))
            }
            gltf::material::AlphaMode::Blend => {
                // A path tracer has no draw order; blending is rendered as a 50% cut-out.
                self.warn(format!("material {:?}: alpha BLEND is rendered as MASK 0.5", m.name()));
                super::AlphaMode::Mask(0.5)
            }
        };
        let strength = m.emissive_strength().unwrap_or(1.0);
        let clamp01 = |x: f32| if x.is_finite() { x.clamp(0.0, 1.0) } else { 0.0 };
        let fin = |v: Vec3| if v.is_finite() { v.max(Vec3::ZERO) } else { Vec3::ZERO };
        let base = Vec4::from(pbr.base_color_factor());
        // glTF bounds these factors; a value outside is clamped, and said so.
        let in01 = |x: f32| (0.0..=1.0).contains(&x);
        let emission = Vec3::from(m.emissive_factor()) * strength;
        let out_of_range: Vec<&str> = [
            ("baseColorFactor", base.to_array().iter().all(|&x| in01(x))),
            ("metallicFactor", in01(pbr.metallic_factor())),
            ("roughnessFactor", in01(pbr.roughness_factor())),
            ("emission", emission.is_finite() && emission.min_element() >= 0.0),
            ("specularFactor", in01(specular_factor)),
            (
                "specularColorFactor",
                specular_color.is_finite() && specular_color.min_element() >= 0.0,
            ),
        ]
        .into_iter()
        .filter(|(_, ok)| !ok)
        .map(|(name, _)| name)
        .collect();
        if !out_of_range.is_empty() {
            self.warn(format!(
                "materials[{}] ({:?}): {} out of range; clamped",
                m.index().unwrap_or(0),
                m.name().unwrap_or(""),
                out_of_range.join(", ")
            ));
        }
        Material {
            name: m.name().unwrap_or("").to_string(),
            base_color: if base.is_finite() {
                base.clamp(Vec4::ZERO, Vec4::ONE)
            } else {
                Vec4::ONE
            },
            base_color_texture: self.tex(
                tex,
                pbr.base_color_texture().map(|i| (i.texture(), i.tex_coord())),
                true,
            ),
            metallic: clamp01(pbr.metallic_factor()),
            roughness: clamp01(pbr.roughness_factor()),
            metallic_roughness_texture: self.tex(
                tex,
                pbr.metallic_roughness_texture().map(|i| (i.texture(), i.tex_coord())),
                false,
            ),
            normal_texture: self.tex(
                tex,
                m.normal_texture().map(|i| (i.texture(), i.tex_coord())),
                false,
            ),
            normal_scale: m
                .normal_texture()
                .map(|n| n.scale())
                .filter(|s| s.is_finite())
                .unwrap_or(1.0),
            emission: fin(emission),
            emissive_texture: self.tex(
                tex,
                m.emissive_texture().map(|i| (i.texture(), i.tex_coord())),
                true,
            ),
            specular_factor: clamp01(specular_factor),
            specular_color: fin(specular_color),
            alpha_mode,
            double_sided: m.double_sided(),
        }
    }
}
