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
        let mut placed: HashMap<(usize, bool, Wrap, Wrap, bool), usize> = HashMap::new();
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
            let nearest = t.sampler().mag_filter() == Some(gltf::texture::MagFilter::Nearest);
            let index = match placed.get(&(key.0, key.1, ws, wt, nearest)) {
                Some(&i) => i,
                None if !placed.keys().any(|k| (k.0, k.1) == key) => {
                    textures[decoded].wrap_s = ws;
                    textures[decoded].wrap_t = wt;
                    textures[decoded].nearest = nearest;
                    decoded
                }
                None => {
                    let copy =
                        Texture { wrap_s: ws, wrap_t: wt, nearest, ..textures[decoded].clone() };
                    self.budget.decode(copy.rgba8.len() as u64, format_args!("textures[{ti}]"))?;
                    textures.push(copy);
                    textures.len() - 1
                }
            };
            placed.insert((key.0, key.1, ws, wt, nearest), index);
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

    /// A material's use of a texture: the texture (if it loaded), its TEXCOORD set and its
    /// KHR_texture_transform (whose texCoord overrides the set).
    fn tex(
        &mut self,
        map: &HashMap<(usize, bool), u32>,
        t: Option<(gltf::Texture, u32, Option<&serde_json::Value>)>,
        srgb: bool,
    ) -> Option<TextureRef> {
        let (t, mut set, ext) = t?;
        let mut transform = glam::Affine2::IDENTITY;
        if let Some(ext) = ext {
            match texture_transform(ext) {
                Ok((m, over)) => {
                    transform = m;
                    set = over.unwrap_or(set);
                }
                Err(e) => self.warn(format!(
                    "textures[{}]: KHR_texture_transform {e}; the texture is read untransformed",
                    t.index()
                )),
            }
        }
        if set > 1 {
            self.warn(format!(
                "textures[{}] is read at TEXCOORD_{set}; Hush reads TEXCOORD_0 and TEXCOORD_1, and uses TEXCOORD_0",
                t.index()
            ));
            set = 0;
        }
        map.get(&(t.index(), srgb)).map(|&index| TextureRef { index, set, transform })
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
            gltf::material::AlphaMode::Blend => super::AlphaMode::Blend,
        };
        // KHR_materials_ior: 1 or more (glTF's 0, "infinite", and anything else out of range is
        // read as the default 1.5, with a warning).
        let ior = match m
            .extension_value("KHR_materials_ior")
            .map(|e| e.get("ior").and_then(|v| v.as_f64()))
        {
            None | Some(None) => 1.5,
            Some(Some(v)) if v.is_finite() && v >= 1.0 => v as f32,
            Some(Some(v)) => {
                self.warn(format!(
                    "materials[{}] ({:?}): KHR_materials_ior {v} is not an index of 1 or more; 1.5 is used",
                    m.index().unwrap_or(0),
                    m.name().unwrap_or("")
                ));
                1.5
            }
        };
        let glass = self.glass(m);
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
                pbr.base_color_texture()
                    .as_ref()
                    .map(|i| (i.texture(), i.tex_coord(), i.extension_value(TRANSFORM))),
                true,
            ),
            metallic: clamp01(pbr.metallic_factor()),
            roughness: clamp01(pbr.roughness_factor()),
            metallic_roughness_texture: self.tex(
                tex,
                pbr.metallic_roughness_texture()
                    .as_ref()
                    .map(|i| (i.texture(), i.tex_coord(), i.extension_value(TRANSFORM))),
                false,
            ),
            normal_texture: self.tex(
                tex,
                m.normal_texture()
                    .as_ref()
                    .map(|i| (i.texture(), i.tex_coord(), i.extension_value(TRANSFORM))),
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
                m.emissive_texture()
                    .as_ref()
                    .map(|i| (i.texture(), i.tex_coord(), i.extension_value(TRANSFORM))),
                true,
            ),
            specular_factor: clamp01(specular_factor),
            specular_color: fin(specular_color),
            ior,
            transmission: glass.transmission,
            thickness: glass.thickness,
            attenuation_color: glass.attenuation_color,
            attenuation_distance: glass.attenuation_distance,
            alpha_mode,
            double_sided: m.double_sided(),
        }
    }
}

/// What KHR_materials_transmission and KHR_materials_volume say of a material.
struct Glass {
    transmission: f32,
    thickness: f32,
    attenuation_color: Vec3,
    attenuation_distance: f32,
}

impl Importer<'_> {
    /// KHR_materials_transmission and KHR_materials_volume. Values out of the extensions' range
    /// are clamped with a warning; their textures are not read (the factors apply alone).
    fn glass(&mut self, m: &gltf::Material) -> Glass {
        let mut g = Glass {
            transmission: 0.0,
            thickness: 0.0,
            attenuation_color: Vec3::ONE,
            attenuation_distance: f32::INFINITY,
        };
        let number = |e: &serde_json::Value, key: &str| e.get(key).and_then(|v| v.as_f64());
        let mut problems = vec![];
        if let Some(e) = m.extension_value("KHR_materials_transmission") {
            let t = number(e, "transmissionFactor").unwrap_or(0.0);
            if !(0.0..=1.0).contains(&t) {
                problems.push("transmissionFactor out of [0, 1]");
            }
            g.transmission = if t.is_finite() { t.clamp(0.0, 1.0) as f32 } else { 0.0 };
            if e.get("transmissionTexture").is_some() {
                problems.push("transmissionTexture is not read");
            }
        }
        if let Some(e) = m.extension_value("KHR_materials_volume") {
            let t = number(e, "thicknessFactor").unwrap_or(0.0);
            if !(t.is_finite() && t >= 0.0) {
                problems.push("thicknessFactor below 0");
            }
            g.thickness = if t.is_finite() { t.max(0.0) as f32 } else { 0.0 };
            if let Some(d) = number(e, "attenuationDistance") {
                if d.is_finite() && d > 0.0 {
                    g.attenuation_distance = d as f32;
                } else {
                    problems.push("attenuationDistance not above 0");
                }
            }
            if let Some(c) = e.get("attenuationColor").and_then(|v| v.as_array()) {
                let c: Vec<f32> = c.iter().filter_map(|x| x.as_f64()).map(|x| x as f32).collect();
                if c.len() == 3 && c.iter().all(|x| (0.0..=1.0).contains(x)) {
                    g.attenuation_color = Vec3::new(c[0], c[1], c[2]);
                } else {
                    problems.push("attenuationColor not 3 numbers in [0, 1]");
                }
            }
            if e.get("thicknessTexture").is_some() {
                problems.push("thicknessTexture is not read");
            }
        }
        if !problems.is_empty() {
            self.warn(format!(
                "materials[{}] ({:?}): {}",
                m.index().unwrap_or(0),
                m.name().unwrap_or(""),
                problems.join("; ")
            ));
        }
        g
    }
}

const TRANSFORM: &str = "KHR_texture_transform";

/// KHR_texture_transform's matrix and its texCoord override, from the extension's JSON.
fn texture_transform(v: &serde_json::Value) -> Result<(glam::Affine2, Option<u32>), String> {
    let pair = |key: &str, default: [f32; 2]| -> Result<glam::Vec2, String> {
        match v.get(key) {
            None => Ok(default.into()),
            Some(a) => {
                let xs: Vec<f32> = a
                    .as_array()
                    .filter(|a| a.len() == 2)
                    .map(|a| a.iter().filter_map(|x| x.as_f64()).map(|x| x as f32).collect())
                    .unwrap_or_default();
                match xs[..] {
                    [x, y] if x.is_finite() && y.is_finite() => Ok(glam::Vec2::new(x, y)),
                    _ => Err(format!("{key} is not two finite numbers")),
                }
            }
        }
    };
    let rotation = match v.get("rotation") {
        None => 0.0,
        Some(r) => match r.as_f64().map(|r| r as f32) {
            Some(r) if r.is_finite() => r,
            _ => return Err("rotation is not a finite number".into()),
        },
    };
    let set = match v.get("texCoord") {
        None => None,
        Some(s) => Some(
            s.as_u64().and_then(|s| u32::try_from(s).ok()).ok_or("texCoord is not a set index")?,
        ),
    };
    let m =
        TextureRef::khr_transform(pair("offset", [0.0; 2])?, rotation, pair("scale", [1.0; 2])?);
    Ok((m, set))
}

/// Whether a texture of `m` is read at TEXCOORD_1 (the mesh then keeps that set), and whether
/// its normal map is (its tangents then follow TEXCOORD_1).
pub(super) fn texcoord1_uses(m: &gltf::Material) -> (bool, bool) {
    let set = |s: u32, ext: Option<&serde_json::Value>| {
        ext.and_then(|e| e.get("texCoord")).and_then(|s| s.as_u64()).unwrap_or(s as u64) == 1
    };
    let pbr = m.pbr_metallic_roughness();
    let normal =
        m.normal_texture().is_some_and(|i| set(i.tex_coord(), i.extension_value(TRANSFORM)));
    let any = normal
        || [pbr.base_color_texture(), pbr.metallic_roughness_texture(), m.emissive_texture()]
            .iter()
            .flatten()
            .any(|i| set(i.tex_coord(), i.extension_value(TRANSFORM)));
    (any, normal)
}

#[cfg(test)]
mod tests {
    use super::texture_transform;
    use glam::Vec2;
    use serde_json::json;

    #[test]
    fn texture_transforms_follow_the_extension_and_refuse_malformed_values() {
        let half_turn = std::f32::consts::FRAC_PI_2;
        let (m, set) = texture_transform(
            &json!({"offset": [0.5, 0.0], "rotation": half_turn, "scale": [2.0, 1.0], "texCoord": 1}),
        )
        .unwrap();
        // T R S (1, 0): scaled to (2, 0), turned to (0, -2) (R = [cos sin; -sin cos]), offset.
        let p = m.transform_point2(Vec2::X);
        assert!((p - Vec2::new(0.5, -2.0)).length() < 1e-6, "{p}");
        assert_eq!(set, Some(1));
        let (m, set) = texture_transform(&json!({})).unwrap();
        assert_eq!((m, set), (glam::Affine2::IDENTITY, None));
        for bad in [
            json!({"offset": [1.0]}),
            json!({"scale": "large"}),
            json!({"rotation": [1.0]}),
            json!({"texCoord": -1}),
        ] {
            assert!(texture_transform(&bad).is_err(), "{bad}");
        }
    }
}
