//! glTF 2.0 (.gltf, .glb) import through the `gltf` crate, following the scene conventions.

use super::paths::{read_uri, resolve};
use super::{
    Animation, Track, AlphaMode, Camera, EnvMap, Environment, Light, Material, Mesh, Object, Scene, Texture,
    TextureRef, Wrap, DEFAULT_MAX_DEPTH,
};
use anyhow::{Context, Result, anyhow, bail};
use glam::{DMat4, Vec2, Vec3, Vec4};
use std::collections::HashMap;
use std::path::Path;

/// Extensions whose meaning Hush implements. Anything else is ignored with a warning when
/// optional and refused when required.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_specular",
];

/// Largest texture side kept on load (larger ones are halved until they fit).
pub const DEFAULT_MAX_TEXTURE_SIZE: u32 = 2048;

pub fn load_gltf(path: &Path) -> Result<Scene> {
    load_gltf_with(path, DEFAULT_MAX_TEXTURE_SIZE)
}

pub fn load_gltf_with(path: &Path, max_texture_size: u32) -> Result<Scene> {
    let ctx = || format!("loading glTF scene {}", path.display());
    let bytes = std::fs::read(path).with_context(ctx)?;
    let (document, blob) = parse(&bytes).with_context(ctx)?;
    let base = path.parent().unwrap_or(Path::new("."));
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    Importer { base, warnings: vec![], max_texture_size }.import(&document, blob.as_deref(), name).with_context(ctx)
}

/// JSON (from a .gltf or a .glb's JSON chunk) -> validated document, refusing unsupported
/// required extensions by name (the `gltf` crate's own error only says "Unsupported").
fn parse(bytes: &[u8]) -> Result<(gltf::Document, Option<Vec<u8>>)> {
    let (json, blob) = if bytes.starts_with(b"glTF") {
        let glb = gltf::Glb::from_slice(bytes).map_err(|e| anyhow!("reading GLB container: {e}"))?;
        (glb.json.to_vec(), glb.bin.map(|b| b.to_vec()))
    } else {
        (bytes.to_vec(), None)
    };
    let mut v: serde_json::Value = serde_json::from_slice(&json).map_err(|e| anyhow!("parsing glTF JSON: {e}"))?;
    let mut unsupported = vec![];
    if let Some(req) = v.get("extensionsRequired").and_then(|r| r.as_array()) {
        for e in req.iter().filter_map(|e| e.as_str()) {
            if !SUPPORTED_EXTENSIONS.contains(&e) {
                unsupported.push(e.to_string());
            }
        }
    }
    if !unsupported.is_empty() {
        bail!(
            "the file requires glTF extensions Hush does not support: {} (supported: {})",
            unsupported.join(", "),
            SUPPORTED_EXTENSIONS.join(", ")
        );
    }
    // `scene.nodes` is optional in glTF 2.0, but the `gltf` crate's schema requires it.
    if let Some(scenes) = v.get_mut("scenes").and_then(|s| s.as_array_mut()) {
        for s in scenes.iter_mut().filter_map(|s| s.as_object_mut()) {
            s.entry("nodes").or_insert_with(|| serde_json::json!([]));
        }
    }
    let root: gltf::json::Root = serde_json::from_value(v).map_err(|e| anyhow!("reading glTF JSON: {e}"))?;
    let document = gltf::Document::from_json(root).map_err(|e| anyhow!("invalid glTF: {e}"))?;
    Ok((document, blob))
}

struct Importer<'a> {
    base: &'a Path,
    warnings: Vec<String>,
    max_texture_size: u32,
}

impl Importer<'_> {
    fn warn(&mut self, msg: String) {
        log::warn!("{msg}");
        self.warnings.push(msg);
    }

    fn import(mut self, doc: &gltf::Document, blob: Option<&[u8]>, name: String) -> Result<Scene> {
        for ext in doc.extensions_used() {
            if !SUPPORTED_EXTENSIONS.contains(&ext) {
                self.warn(format!("optional glTF extension {ext} is not supported; ignored"));
            }
        }
        let buffers = self.load_buffers(doc, blob)?;
        let (textures, tex_map) = self.load_textures(doc, &buffers);
        let materials: Vec<Material> =
            doc.materials().map(|m| self.material(&m, &tex_map)).collect();
        let mut scene = Scene {
            name,
            textures,
            materials,
            max_depth: DEFAULT_MAX_DEPTH,
            ..Default::default()
        };
        let default_material = scene.materials.len() as u32;
        scene.materials.push(Material::default());

        let gscene = doc
            .default_scene()
            .or_else(|| doc.scenes().next())
            .ok_or_else(|| anyhow!("the file has no scene"))?;
        self.scene_extras(&gscene, &mut scene)?;
        let mut mesh_cache: HashMap<usize, Vec<usize>> = HashMap::new();
        let mut animated = self.animations(doc, &buffers);
        // (node, parent world transform, whether an ancestor is animated)
        let mut stack: Vec<(gltf::Node, DMat4, bool)> =
            gscene.nodes().map(|n| (n, DMat4::IDENTITY, false)).collect();
        while let Some((node, parent, moving_parent)) = stack.pop() {
            let mut animation = animated.remove(&node.index());
            if let Some(a) = animation.as_mut() {
                if moving_parent {
                    self.warn(format!("node {:?} is animated under an animated parent; only the parent's rest pose is used", node.name()));
                }
                a.parent = parent;
            }
            let local = node.transform().matrix().map(|c| c.map(|x| x as f64));
            let world = parent * DMat4::from_cols_array_2d(&local);
            if !world.is_finite() {
                self.warn(format!("node {:?} has a non-finite transform; skipped", node.name()));
                continue;
            }
            if let Some(mesh) = node.mesh() {
                let ids = match mesh_cache.get(&mesh.index()) {
                    Some(ids) => ids.clone(),
                    None => {
                        let ids = self.mesh(&mesh, &buffers, &scene.materials, default_material, &mut scene.meshes)
                            .with_context(|| format!("mesh {:?} ({})", mesh.name(), mesh.index()))?;
                        mesh_cache.insert(mesh.index(), ids.clone());
                        ids
                    }
                };
                for id in ids {
                    scene.objects.push(Object {
                        name: node.name().unwrap_or("").to_string(),
                        mesh: id,
                        transform: world,
                        animation: animation.clone(),
                    });
                }
            }
            if let Some(light) = node.light() {
                scene.lights.push(self.light(&light, &world));
            }
            if let Some(cam) = node.camera() {
                if scene.camera.is_none() {
                    match cam.projection() {
                        gltf::camera::Projection::Perspective(p) => {
                            scene.camera = Some(Camera { world, yfov: p.yfov() });
                        }
                        gltf::camera::Projection::Orthographic(_) => self.warn(
                            "orthographic cameras are not supported; using a default view".into(),
                        ),
                    }
                }
            }
            let moving = moving_parent || animation.is_some();
            if animation.is_some() && node.children().next().is_some() {
                self.warn(format!("children of animated node {:?} are placed at its rest pose", node.name()));
            }
            for child in node.children() {
                stack.push((child, world, moving));
            }
        }
        scene.warnings = self.warnings;
        Ok(scene)
    }

    /// Node index -> its animation (translation/rotation/scale channels of every glTF animation).
    fn animations(&mut self, doc: &gltf::Document, buffers: &[Vec<u8>]) -> HashMap<usize, Animation> {
        use gltf::animation::{Interpolation, Property, util::ReadOutputs};
        let mut map: HashMap<usize, Animation> = HashMap::new();
        for anim in doc.animations() {
            for ch in anim.channels() {
                let node = ch.target().node();
                let reader = ch.reader(|b| buffers.get(b.index()).map(|v| v.as_slice()));
                let Some(times) = reader.read_inputs() else { continue };
                let times: Vec<f64> = times.map(|t| t as f64).collect();
                let interp = ch.sampler().interpolation();
                // CUBICSPLINE stores (in-tangent, value, out-tangent) per key: keep the values.
                let pick = |i: usize| match interp {
                    Interpolation::CubicSpline => i % 3 == 1,
                    _ => true,
                };
                if interp == Interpolation::CubicSpline {
                    self.warn(format!("animation on node {:?}: CUBICSPLINE is sampled linearly between keys", node.name()));
                }
                let sorted = times.windows(2).all(|w| w[0] <= w[1]) && times.iter().all(|t| t.is_finite());
                if !sorted {
                    self.warn(format!("animation on node {:?} has unsorted or non-finite key times; ignored", node.name()));
                    continue;
                }
                let (t, r, s) = node.transform().decomposed();
                let a = map.entry(node.index()).or_insert_with(|| Animation {
                    parent: DMat4::IDENTITY,
                    translation: glam::DVec3::from_array(t.map(|x| x as f64)),
                    rotation: glam::DQuat::from_array(r.map(|x| x as f64)),
                    scale: glam::DVec3::from_array(s.map(|x| x as f64)),
                    translation_track: None,
                    rotation_track: None,
                    scale_track: None,
                });
                let step = interp == Interpolation::Step;
                let v3 = |it: &mut dyn Iterator<Item = [f32; 3]>| -> Vec<glam::DVec3> {
                    it.enumerate().filter(|(i, _)| pick(*i)).map(|(_, v)| glam::DVec3::from_array(v.map(|x| x as f64))).collect()
                };
                match (ch.target().property(), reader.read_outputs()) {
                    (Property::Translation, Some(ReadOutputs::Translations(mut it))) => {
                        a.translation_track = Some(Track { times: times.clone(), values: v3(&mut it), step });
                    }
                    (Property::Scale, Some(ReadOutputs::Scales(mut it))) => {
                        a.scale_track = Some(Track { times: times.clone(), values: v3(&mut it), step });
                    }
                    (Property::Rotation, Some(ReadOutputs::Rotations(it))) => {
                        let values = it.into_f32().enumerate().filter(|(i, _)| pick(*i))
                            .map(|(_, q)| glam::DQuat::from_array(q.map(|x| x as f64)).normalize()).collect();
                        a.rotation_track = Some(Track { times: times.clone(), values, step });
                    }
                    (Property::MorphTargetWeights, _) => self.warn("morph target animation is not supported; ignored".into()),
                    _ => self.warn(format!("animation channel on node {:?} could not be read; ignored", node.name())),
                }
            }
        }
        map.retain(|_, a| a.duration() > 0.0 || a.translation_track.is_some() || a.rotation_track.is_some() || a.scale_track.is_some());
        map
    }

    fn load_buffers(&mut self, doc: &gltf::Document, blob: Option<&[u8]>) -> Result<Vec<Vec<u8>>> {
        doc.buffers()
            .map(|b| {
                let data = match b.source() {
                    gltf::buffer::Source::Bin => blob
                        .map(|b| b.to_vec())
                        .ok_or_else(|| anyhow!("buffer {} refers to a missing GLB chunk", b.index()))?,
                    gltf::buffer::Source::Uri(uri) => read_uri(self.base, uri)
                        .with_context(|| format!("buffer {} ({uri})", b.index()))?,
                };
                if data.len() < b.length() {
                    bail!("buffer {} holds {} bytes, the file says {}", b.index(), data.len(), b.length());
                }
                Ok(data)
            })
            .collect()
    }

    /// Decode every texture a material uses. A texture that cannot be read is a warning and a
    /// neutral fallback (the material renders with its factors alone).
    fn load_textures(
        &mut self,
        doc: &gltf::Document,
        buffers: &[Vec<u8>],
    ) -> (Vec<Texture>, HashMap<(usize, bool), u32>) {
        // Which textures are colour (sRGB) and which are data.
        let mut uses: Vec<(usize, bool)> = vec![];
        for m in doc.materials() {
            let pbr = m.pbr_metallic_roughness();
            let mut add = |t: Option<gltf::Texture>, srgb: bool| {
                if let Some(t) = t {
                    if !uses.contains(&(t.index(), srgb)) {
                        uses.push((t.index(), srgb));
                    }
                }
            };
            add(pbr.base_color_texture().map(|i| i.texture()), true);
            add(pbr.metallic_roughness_texture().map(|i| i.texture()), false);
            add(m.normal_texture().map(|i| i.texture()), false);
            add(m.emissive_texture().map(|i| i.texture()), true);
        }
        let mut textures = vec![];
        let mut map = HashMap::new();
        let all: Vec<gltf::Texture> = doc.textures().collect();
        for (ti, srgb) in uses {
            let t = &all[ti];
            let img = t.source();
            let (label, bytes) = match img.source() {
                gltf::image::Source::Uri { uri, .. } => {
                    (uri.to_string(), read_uri(self.base, uri).map_err(|e| e.to_string()))
                }
                gltf::image::Source::View { view, .. } => {
                    let b = &buffers[view.buffer().index()];
                    let r = b.get(view.offset()..view.offset() + view.length());
                    (format!("image {}", img.index()), r.map(|s| s.to_vec()).ok_or("view out of range".into()))
                }
            };
            let decoded = bytes.and_then(|b| {
                Texture::decode(&label, &b, srgb, self.max_texture_size).map_err(|e| format!("{e:#}"))
            });
            match decoded {
                Ok(mut tex) => {
                    let wrap = |w: gltf::texture::WrappingMode| match w {
                        gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
                        gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
                        gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
                    };
                    tex.wrap_s = wrap(t.sampler().wrap_s());
                    tex.wrap_t = wrap(t.sampler().wrap_t());
                    map.insert((ti, srgb), textures.len() as u32);
                    textures.push(tex);
                }
                Err(e) => self.warn(format!("texture {label}: {e}; rendering without it")),
            }
        }
        (textures, map)
    }

    fn tex(
        &mut self,
        map: &HashMap<(usize, bool), u32>,
        t: Option<(gltf::Texture, u32)>,
        srgb: bool,
    ) -> Option<TextureRef> {
        let (t, set) = t?;
        if set != 0 {
            self.warn(format!("texture {} uses TEXCOORD_{set}; only TEXCOORD_0 is supported", t.index()));
        }
        map.get(&(t.index(), srgb)).map(|&index| TextureRef { index })
    }

    fn material(&mut self, m: &gltf::Material, tex: &HashMap<(usize, bool), u32>) -> Material {
        let pbr = m.pbr_metallic_roughness();
        let (specular_factor, specular_color) = match m.specular() {
            Some(s) => {
                if s.specular_texture().is_some() || s.specular_color_texture().is_some() {
                    self.warn(format!("material {:?}: specular textures are not supported", m.name()));
                }
                (s.specular_factor(), Vec3::from(s.specular_color_factor()))
            }
            None => (1.0, Vec3::ONE),
        };
        let alpha_mode = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5)),
            gltf::material::AlphaMode::Blend => {
                // A path tracer has no draw order; blending is rendered as a 50% cut-out.
                self.warn(format!("material {:?}: alpha BLEND is rendered as MASK 0.5", m.name()));
                AlphaMode::Mask(0.5)
            }
        };
        let strength = m.emissive_strength().unwrap_or(1.0);
        let clamp01 = |x: f32| if x.is_finite() { x.clamp(0.0, 1.0) } else { 0.0 };
        let fin = |v: Vec3| if v.is_finite() { v.max(Vec3::ZERO) } else { Vec3::ZERO };
        Material {
            name: m.name().unwrap_or("").to_string(),
            base_color: Vec4::from(pbr.base_color_factor()).clamp(Vec4::ZERO, Vec4::ONE),
            base_color_texture: self.tex(tex, pbr.base_color_texture().map(|i| (i.texture(), i.tex_coord())), true),
            metallic: clamp01(pbr.metallic_factor()),
            roughness: clamp01(pbr.roughness_factor()),
            metallic_roughness_texture: self.tex(
                tex,
                pbr.metallic_roughness_texture().map(|i| (i.texture(), i.tex_coord())),
                false,
            ),
            normal_texture: self.tex(tex, m.normal_texture().map(|i| (i.texture(), i.tex_coord())), false),
            normal_scale: m.normal_texture().map(|n| n.scale()).unwrap_or(1.0),
            emission: fin(Vec3::from(m.emissive_factor()) * strength),
            emissive_texture: self.tex(tex, m.emissive_texture().map(|i| (i.texture(), i.tex_coord())), true),
            specular_factor: clamp01(specular_factor),
            specular_color: fin(specular_color),
            alpha_mode,
            double_sided: m.double_sided(),
        }
    }

    fn mesh(
        &mut self,
        mesh: &gltf::Mesh,
        buffers: &[Vec<u8>],
        materials: &[Material],
        default_material: u32,
        out: &mut Vec<Mesh>,
    ) -> Result<Vec<usize>> {
        let mut ids = vec![];
        for prim in mesh.primitives() {
            use gltf::mesh::Mode;
            let mode = prim.mode();
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                self.warn(format!("mesh {:?}: {mode:?} primitives are not rendered", mesh.name()));
                continue;
            }
            let reader = prim.reader(|b| buffers.get(b.index()).map(|v| v.as_slice()));
            let positions: Vec<Vec3> = match reader.read_positions() {
                Some(p) => p.map(Vec3::from).collect(),
                None => {
                    self.warn(format!("mesh {:?}: a primitive has no POSITION; skipped", mesh.name()));
                    continue;
                }
            };
            let n = positions.len();
            let raw: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..n as u32).collect(),
            };
            if let Some(bad) = raw.iter().find(|&&i| i as usize >= n) {
                bail!("index {bad} is out of range for {n} vertices");
            }
            let indices = triangulate(mode, &raw);
            let normals: Option<Vec<Vec3>> = reader.read_normals().map(|r| r.map(Vec3::from).collect());
            let uvs: Vec<Vec2> = match reader.read_tex_coords(0) {
                Some(t) => t.into_f32().map(Vec2::from).collect(),
                None => vec![Vec2::ZERO; n],
            };
            let material = prim.material().index().map(|i| i as u32).unwrap_or(default_material);
            let tangents: Option<Vec<Vec4>> = reader.read_tangents().map(|t| t.map(Vec4::from).collect());
            let mut m = Mesh { positions, normals: normals.unwrap_or_default(), uvs, tangents: vec![], indices, material };
            if m.normals.len() != n {
                // glTF: without NORMAL, clients compute flat normals.
                flatten_with_face_normals(&mut m);
            }
            let wants_tangents = materials.get(material as usize).is_some_and(|m| m.normal_texture.is_some());
            if wants_tangents {
                match tangents {
                    Some(t) if t.len() == m.positions.len() => m.tangents = t,
                    _ => generate_tangents(&mut m),
                }
            }
            ids.push(out.len());
            out.push(m);
        }
        Ok(ids)
    }

    fn light(&mut self, l: &gltf::khr_lights_punctual::Light, world: &DMat4) -> Light {
        use gltf::khr_lights_punctual::Kind;
        let c = Vec3::from(l.color()) * l.intensity();
        let c = if c.is_finite() { c.max(Vec3::ZERO) } else { Vec3::ZERO };
        if l.range().is_some() {
            self.warn("light range is ignored (lights follow the inverse-square law)".into());
        }
        let position = world.w_axis.truncate();
        let direction = (-world.z_axis.truncate()).normalize_or(glam::DVec3::NEG_Z).as_vec3();
        match l.kind() {
            Kind::Directional => Light::Directional { direction, irradiance: c },
            Kind::Point => Light::Point { position, intensity: c },
            Kind::Spot { inner_cone_angle, outer_cone_angle } => Light::Spot {
                position,
                direction,
                intensity: c,
                inner_cone: inner_cone_angle,
                outer_cone: outer_cone_angle,
            },
        }
    }

    fn scene_extras(&mut self, s: &gltf::Scene, scene: &mut Scene) -> Result<()> {
        let Some(raw) = s.extras() else { return Ok(()) };
        let v: serde_json::Value = serde_json::from_str(raw.get()).context("parsing scene extras")?;
        if let Some(r) = v.get("resolution") {
            let wh = r
                .as_array()
                .filter(|a| a.len() == 2)
                .and_then(|a| Some((a[0].as_u64()?, a[1].as_u64()?)))
                .filter(|&(w, h)| w > 0 && h > 0 && w <= 16384 && h <= 16384)
                .ok_or_else(|| anyhow!("extras.resolution must be [width, height] in 1..=16384, got {r}"))?;
            scene.resolution = Some((wh.0 as u32, wh.1 as u32));
        }
        if let Some(d) = v.get("max_depth") {
            scene.max_depth = d
                .as_i64()
                .filter(|&d| d >= -1 && d <= 1 << 16)
                .ok_or_else(|| anyhow!("extras.max_depth must be an integer >= -1, got {d}"))? as i32;
        }
        // Written by Hush's exporter: the environment is the sun's procedural sky.
        scene.procedural_sky = v.get("procedural_sky").and_then(|b| b.as_bool()).unwrap_or(false);
        if let Some(env) = v.get("environment") {
            if let Some(rad) = env.get("radiance") {
                let c = rad
                    .as_array()
                    .filter(|a| a.len() == 3)
                    .and_then(|a| Some(Vec3::new(a[0].as_f64()? as f32, a[1].as_f64()? as f32, a[2].as_f64()? as f32)))
                    .filter(|c| c.is_finite() && c.min_element() >= 0.0)
                    .ok_or_else(|| anyhow!("extras.environment.radiance must be [r, g, b] >= 0, got {rad}"))?;
                scene.environment = Environment::Constant(c);
            } else if let Some(map) = env.get("map").and_then(|m| m.as_str()) {
                let intensity = env.get("intensity").and_then(|x| x.as_f64()).unwrap_or(1.0) as f32;
                let rot = env.get("rotation_y_degrees").and_then(|x| x.as_f64()).unwrap_or(0.0) as f32;
                let path = resolve(self.base, map)?;
                scene.environment = Environment::Map(EnvMap::load_exr(&path, intensity, rot)?);
            } else {
                bail!("extras.environment needs `radiance` or `map`, got {env}");
            }
        }
        Ok(())
    }
}

fn triangulate(mode: gltf::mesh::Mode, idx: &[u32]) -> Vec<u32> {
    use gltf::mesh::Mode;
    match mode {
        Mode::Triangles => idx[..idx.len() / 3 * 3].to_vec(),
        Mode::TriangleStrip => (2..idx.len())
            .flat_map(|i| {
                if i % 2 == 0 { [idx[i - 2], idx[i - 1], idx[i]] } else { [idx[i - 1], idx[i - 2], idx[i]] }
            })
            .collect(),
        Mode::TriangleFan => (2..idx.len()).flat_map(|i| [idx[0], idx[i - 1], idx[i]]).collect(),
        _ => vec![],
    }
}

/// Give every triangle its own three vertices with the face normal.
fn flatten_with_face_normals(m: &mut Mesh) {
    let mut out = Mesh { material: m.material, ..Default::default() };
    for t in m.indices.chunks_exact(3) {
        let p = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        for k in 0..3 {
            out.indices.push(out.positions.len() as u32);
            out.positions.push(p[k]);
            out.normals.push(n);
            out.uvs.push(m.uvs.get(t[k] as usize).copied().unwrap_or_default());
        }
    }
    *m = out;
}

/// MikkTSpace tangents (the glTF reference) for a mesh with a normal map but no TANGENT.
fn generate_tangents(m: &mut Mesh) {
    struct Geo<'a>(&'a mut Mesh);
    impl mikktspace::Geometry for Geo<'_> {
        fn num_faces(&self) -> usize {
            self.0.indices.len() / 3
        }
        fn num_vertices_of_face(&self, _: usize) -> usize {
            3
        }
        fn position(&self, f: usize, v: usize) -> [f32; 3] {
            self.0.positions[self.0.indices[f * 3 + v] as usize].into()
        }
        fn normal(&self, f: usize, v: usize) -> [f32; 3] {
            self.0.normals[self.0.indices[f * 3 + v] as usize].into()
        }
        fn tex_coord(&self, f: usize, v: usize) -> [f32; 2] {
            self.0.uvs[self.0.indices[f * 3 + v] as usize].into()
        }
        fn set_tangent_encoded(&mut self, t: [f32; 4], f: usize, v: usize) {
            let i = self.0.indices[f * 3 + v] as usize;
            self.0.tangents[i] = Vec4::from(t);
        }
    }
    m.tangents = vec![Vec4::new(1.0, 0.0, 0.0, 1.0); m.positions.len()];
    // MikkTSpace writes per face-vertex; shared vertices get the last write, which matches for
    // the usual case of vertices split along UV seams.
    let _ = mikktspace::generate_tangents(&mut Geo(m));
}
