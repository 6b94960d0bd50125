//! Write a [`Scene`] as glTF 2.0: `NAME.gltf` with `NAME.bin`, textures as PNG and an environment
//! map as EXR beside it, following the same conventions the importer reads (lights as
//! KHR_lights_punctual with color x intensity = irradiance or W/sr; emission beyond 1 through
//! KHR_materials_emissive_strength; KHR_materials_specular; `scenes[0].extras`). The `gltf`
//! crate only reads, so the JSON is written here with serde_json. Animated nodes keep their
//! channels and their animated ancestors (as nested nodes); a skinned or morphed object is
//! written as a static mesh in its rest pose (its skin, targets and weights channels are not).

use super::{AlphaMode, Environment, Light, Scene, Track, Wrap};
use crate::image_io::Image;
use anyhow::{Context, Result};
use glam::{DMat4, DQuat, DVec3, Vec3};
use serde_json::{Value, json};
use std::path::Path;

#[derive(Default)]
struct Writer {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Writer {
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    /// Float accessor of `n`-component elements; min/max as glTF requires for positions and
    /// animation inputs.
    fn floats(
        &mut self,
        data: &[f32],
        n: usize,
        kind: &str,
        target: Option<u32>,
        bounds: bool,
    ) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        let mut a = json!({"bufferView": view, "componentType": 5126, "count": data.len() / n, "type": kind});
        if bounds && !data.is_empty() {
            let mut lo = vec![f32::MAX; n];
            let mut hi = vec![f32::MIN; n];
            for c in data.chunks_exact(n) {
                for k in 0..n {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
            }
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn indices(&mut self, idx: &[u32]) -> usize {
        let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(34963));
        self.accessors.push(json!({"bufferView": view, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}));
        self.accessors.len() - 1
    }

    /// A track's input (times) and output (values, or CUBICSPLINE's triples) accessors.
    fn track3(&mut self, t: &Track<DVec3>) -> (usize, usize) {
        let values: Vec<f32> = keyed(t).iter().flat_map(|v| v.as_vec3().to_array()).collect();
        (self.times(t), self.floats(&values, 3, "VEC3", None, false))
    }

    fn track_quat(&mut self, t: &Track<DQuat>) -> (usize, usize) {
        let values: Vec<f32> = keyed(t).iter().flat_map(|q| q.as_quat().to_array()).collect();
        (self.times(t), self.floats(&values, 4, "VEC4", None, false))
    }

    fn times<T>(&mut self, t: &Track<T>) -> usize {
        let times: Vec<f32> = t.times.iter().map(|x| *x as f32).collect();
        self.floats(&times, 1, "SCALAR", None, true)
    }
}

/// A sampler's output: the values, or for CUBICSPLINE (in-tangent, value, out-tangent) per key.
fn keyed<T: Copy>(t: &Track<T>) -> Vec<T> {
    if t.tangents.len() != t.values.len() {
        return t.values.clone();
    }
    t.values.iter().zip(&t.tangents).flat_map(|(v, [a, b])| [*a, *v, *b]).collect()
}

fn interpolation<T>(t: &Track<T>) -> &'static str {
    match (t.step, t.tangents.len() == t.values.len() && !t.values.is_empty()) {
        (true, _) => "STEP",
        (false, true) => "CUBICSPLINE",
        (false, false) => "LINEAR",
    }
}

/// A material's textureInfo: the texture, its TEXCOORD set, and its KHR_texture_transform
/// (the affine map taken apart into offset, rotation and scale as the extension composes them,
/// TextureRef::khr_transform).
fn texture_info(r: super::TextureRef) -> Value {
    let mut v = json!({"index": r.index});
    if r.set != 0 {
        v["texCoord"] = json!(r.set);
    }
    if r.transform != glam::Affine2::IDENTITY {
        let (c0, c1) = (r.transform.matrix2.x_axis, r.transform.matrix2.y_axis);
        // Columns sx (cos, -sin) and sy (sin, cos); a mirror (negative determinant) in sy.
        let (sx, sy) = (c0.length(), c1.length() * r.transform.matrix2.determinant().signum());
        let rotation = (-c0.y).atan2(c0.x);
        v["extensions"] = json!({"KHR_texture_transform": {
            "offset": r.transform.translation.to_array(),
            "rotation": rotation,
            "scale": [sx, sy],
        }});
    }
    v
}

fn wrap(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => 10497,
        Wrap::Clamp => 33071,
        Wrap::Mirror => 33648,
    }
}

fn mat(m: DMat4) -> Vec<f64> {
    m.to_cols_array().to_vec()
}

/// Rotation taking the node's -Z (where glTF lights and cameras point) to `dir`.
fn aim(dir: Vec3) -> [f64; 4] {
    DQuat::from_rotation_arc(DVec3::NEG_Z, dir.as_dvec3().normalize_or(DVec3::NEG_Z)).to_array()
}

/// Write `scene` to `path` (a `.gltf`); side files share its stem.
pub fn save_gltf(scene: &Scene, path: &Path) -> Result<()> {
    let ctx = || format!("writing glTF {}", path.display());
    let dir = path.parent().unwrap_or(Path::new("."));
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let mut w = Writer::default();

    let mut images = vec![];
    let mut samplers = vec![];
    let mut textures = vec![];
    for (i, t) in scene.textures.iter().enumerate() {
        let file = format!("{stem}_tex{i}.png");
        let img = image::RgbaImage::from_raw(t.width, t.height, t.rgba8.clone())
            .context("texture size")?;
        img.save(dir.join(&file)).with_context(|| format!("writing {file}"))?;
        images.push(json!({"uri": file, "name": t.name}));
        let mut sampler = json!({"wrapS": wrap(t.wrap_s), "wrapT": wrap(t.wrap_t)});
        if t.nearest {
            sampler["magFilter"] = json!(9728);
        }
        samplers.push(sampler);
        textures.push(json!({"source": i, "sampler": i}));
    }
    let tex = |r: Option<super::TextureRef>| r.map(texture_info);

    let mut uses_strength = false;
    let materials: Vec<Value> = scene
        .materials
        .iter()
        .map(|m| {
            let mut pbr = json!({"baseColorFactor": m.base_color.to_array(), "metallicFactor": m.metallic, "roughnessFactor": m.roughness});
            if let Some(t) = tex(m.base_color_texture) {
                pbr["baseColorTexture"] = t;
            }
            if let Some(t) = tex(m.metallic_roughness_texture) {
                pbr["metallicRoughnessTexture"] = t;
            }
            let mut v = json!({"name": m.name, "pbrMetallicRoughness": pbr, "doubleSided": m.double_sided});
            let mut ext = serde_json::Map::new();
            let e = m.emission.max_element();
            if e > 0.0 {
                let s = e.max(1.0);
                v["emissiveFactor"] = json!((m.emission / s).to_array());
                if s > 1.0 {
                    ext.insert("KHR_materials_emissive_strength".into(), json!({"emissiveStrength": s}));
                    uses_strength = true;
                }
            }
            if let Some(t) = tex(m.emissive_texture) {
                v["emissiveTexture"] = t;
            }
            if let Some(t) = tex(m.normal_texture) {
                let mut t = t;
                t["scale"] = json!(m.normal_scale);
                v["normalTexture"] = t;
            }
            if m.alpha_mode == AlphaMode::Blend {
                v["alphaMode"] = json!("BLEND");
            }
            if let AlphaMode::Mask(c) = m.alpha_mode {
                v["alphaMode"] = json!("MASK");
                v["alphaCutoff"] = json!(c);
            }
            ext.insert("KHR_materials_specular".into(), json!({"specularFactor": m.specular_factor, "specularColorFactor": m.specular_color.to_array()}));
            if m.ior != 1.5 {
                ext.insert("KHR_materials_ior".into(), json!({"ior": m.ior}));
            }
            if m.transmission > 0.0 {
                ext.insert("KHR_materials_transmission".into(), json!({"transmissionFactor": m.transmission}));
            }
            if m.thickness > 0.0 {
                let mut vol = json!({"thicknessFactor": m.thickness});
                if m.attenuation_distance.is_finite() {
                    vol["attenuationDistance"] = json!(m.attenuation_distance);
                    vol["attenuationColor"] = json!(m.attenuation_color.to_array());
                }
                ext.insert("KHR_materials_volume".into(), vol);
            }
            v["extensions"] = Value::Object(ext);
            v
        })
        .collect();

    // Deforming objects' meshes posed at rest, after the scene's own.
    let mut posed = vec![];
    let mut mesh_of = vec![];
    for o in &scene.objects {
        if o.deforms() {
            mesh_of.push(scene.meshes.len() + posed.len());
            posed.push(o.mesh_at(&scene.meshes[o.mesh], None).into_owned());
        } else {
            mesh_of.push(o.mesh);
        }
    }
    let mut meshes = vec![];
    for m in scene.meshes.iter().chain(&posed) {
        let pos: Vec<f32> = m.positions.iter().flat_map(|p| p.to_array()).collect();
        let mut attrs = json!({"POSITION": w.floats(&pos, 3, "VEC3", Some(34962), true)});
        // Per-vertex attributes the mesh has: (name, vertices, components, accessor type, data).
        let flat2 = |v: &[glam::Vec2]| v.iter().flat_map(|p| p.to_array()).collect::<Vec<f32>>();
        let attributes = [
            (
                "NORMAL",
                m.normals.len(),
                3,
                "VEC3",
                m.normals.iter().flat_map(|p| p.to_array()).collect(),
            ),
            ("TEXCOORD_0", m.uvs.len(), 2, "VEC2", flat2(&m.uvs)),
            ("TEXCOORD_1", m.uvs1.len(), 2, "VEC2", flat2(&m.uvs1)),
            (
                "COLOR_0",
                m.colors.len(),
                4,
                "VEC4",
                m.colors.iter().flat_map(|p| p.to_array()).collect(),
            ),
        ];
        for (name, n, k, ty, data) in attributes {
            if n == m.positions.len() {
                attrs[name] = json!(w.floats(&data, k, ty, Some(34962), false));
            }
        }
        let indices = w.indices(&m.indices);
        meshes.push(json!({"primitives": [{"attributes": attrs, "indices": indices, "material": m.material, "mode": 4}]}));
    }

    let mut nodes = vec![];
    let mut roots = vec![];
    let mut animations = vec![];
    for (o, &mesh) in scene.objects.iter().zip(&mesh_of) {
        let node = json!({"name": o.name, "mesh": mesh});
        let root = match &o.animation {
            None => {
                let mut node = node;
                node["matrix"] = json!(mat(o.transform));
                nodes.push(node);
                nodes.len() - 1
            }
            Some(a) => {
                let (root, channels, samplers) = animated_nodes(&mut w, &mut nodes, a, node);
                animations
                    .push(json!({"name": o.name, "samplers": samplers, "channels": channels}));
                root
            }
        };
        roots.push(root);
    }

    let mut lights = vec![];
    for l in &scene.lights {
        let (kind, c, node) = match *l {
            Light::Directional { direction, irradiance } => {
                ("directional", irradiance, json!({"rotation": aim(direction)}))
            }
            Light::Point { position, intensity } => {
                ("point", intensity, json!({"translation": position.to_array()}))
            }
            Light::Spot { position, direction, intensity, .. } => (
                "spot",
                intensity,
                json!({"translation": position.to_array(), "rotation": aim(direction)}),
            ),
        };
        let i = c.max_element().max(0.0);
        let color = if i > 0.0 { c / i } else { Vec3::ONE };
        let mut light = json!({"type": kind, "color": color.to_array(), "intensity": i});
        if let Light::Spot { inner_cone, outer_cone, .. } = *l {
            light["spot"] = json!({"innerConeAngle": inner_cone, "outerConeAngle": outer_cone});
        }
        let mut node = node;
        node["extensions"] = json!({"KHR_lights_punctual": {"light": lights.len()}});
        lights.push(light);
        roots.push(nodes.len());
        nodes.push(node);
    }

    let mut cameras = vec![];
    if let Some(c) = &scene.camera {
        let mut cam =
            json!({"type": "perspective", "perspective": {"yfov": c.yfov, "znear": 0.01}});
        if let Some(l) = c.lens {
            cam["extras"] =
                json!({"aperture_radius": l.aperture_radius, "focus_distance": l.focus_distance});
        }
        cameras.push(cam);
        roots.push(nodes.len());
        nodes.push(json!({"name": "camera", "camera": 0, "matrix": mat(c.world)}));
    }

    let mut extras = json!({"max_depth": scene.max_depth, "procedural_sky": scene.procedural_sky});
    if let Some((rw, rh)) = scene.resolution {
        extras["resolution"] = json!([rw, rh]);
    }
    match &scene.environment {
        Environment::None => {}
        Environment::Constant(c) => extras["environment"] = json!({"radiance": c.to_array()}),
        Environment::Map(m) => {
            let file = format!("{stem}_environment.exr");
            Image { width: m.width, height: m.height, data: m.rgb.clone() }
                .save(&dir.join(&file))?;
            extras["environment"] =
                json!({"map": file, "intensity": 1.0, "rotation_y_degrees": m.rotation_y_degrees});
        }
    }

    let bin_name = format!("{stem}.bin");
    let mut used = vec!["KHR_materials_specular"];
    let transformed = |m: &super::Material| {
        m.texture_refs().into_iter().flatten().any(|t| t.transform != glam::Affine2::IDENTITY)
    };
    if scene.materials.iter().any(transformed) {
        used.push("KHR_texture_transform");
    }
    if uses_strength {
        used.push("KHR_materials_emissive_strength");
    }
    if !lights.is_empty() {
        used.push("KHR_lights_punctual");
    }
    if scene.materials.iter().any(|m| m.transmission > 0.0) {
        used.push("KHR_materials_transmission");
    }
    if scene.materials.iter().any(|m| m.thickness > 0.0) {
        used.push("KHR_materials_volume");
    }
    if scene.materials.iter().any(|m| m.ior != 1.5) {
        used.push("KHR_materials_ior");
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "Hush"},
        "extensionsUsed": used,
        "scene": 0,
        "scenes": [{"name": scene.name, "nodes": roots, "extras": extras}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": w.accessors,
        "bufferViews": w.views,
        "buffers": [{"uri": bin_name, "byteLength": w.bin.len()}],
    });
    for (k, v) in [
        ("images", images),
        ("samplers", samplers),
        ("textures", textures),
        ("animations", animations),
        ("cameras", cameras),
    ] {
        if !v.is_empty() {
            doc[k] = Value::Array(v);
        }
    }
    if !lights.is_empty() {
        doc["extensions"] = json!({"KHR_lights_punctual": {"lights": lights}});
    }
    std::fs::write(dir.join(&bin_name), &w.bin).with_context(ctx)?;
    std::fs::write(path, serde_json::to_string_pretty(&doc)?).with_context(ctx)?;
    Ok(())
}

/// Nodes for `a` and its animated ancestors, outermost first, `node` (the object's) innermost:
/// each ancestor a node with its channels, the static transforms between them as matrix
/// nodes. Returns the outermost node and the channels and samplers of them all.
fn animated_nodes(
    w: &mut Writer,
    nodes: &mut Vec<Value>,
    a: &super::Animation,
    mut first: Value,
) -> (usize, Vec<Value>, Vec<Value>) {
    let (mut channels, mut samplers) = (vec![], vec![]);
    let mut chain = vec![];
    let mut at = Some(a);
    while let Some(a) = at {
        chain.push(a);
        at = a.parent_motion.as_deref();
    }
    let mut child: Option<usize> = None;
    for (depth, a) in chain.into_iter().enumerate() {
        let mut node = if depth == 0 {
            std::mem::take(&mut first)
        } else {
            json!({"name": format!("animated parent {depth}")})
        };
        node["translation"] = json!(a.translation.to_array());
        node["rotation"] = json!(a.rotation.to_array());
        node["scale"] = json!(a.scale.to_array());
        if let Some(c) = child {
            node["children"] = json!([c]);
        }
        let target = nodes.len();
        let mut channel = |path: &str, (i, o): (usize, usize), interpolation: &str| {
            channels
                .push(json!({"sampler": samplers.len(), "target": {"node": target, "path": path}}));
            samplers.push(json!({"input": i, "output": o, "interpolation": interpolation}));
        };
        if let Some(t) = &a.translation_track {
            channel("translation", w.track3(t), interpolation(t));
        }
        if let Some(t) = &a.scale_track {
            channel("scale", w.track3(t), interpolation(t));
        }
        if let Some(t) = &a.rotation_track {
            channel("rotation", w.track_quat(t), interpolation(t));
        }
        nodes.push(node);
        child = Some(target);
        if a.parent != DMat4::IDENTITY {
            nodes.push(
                json!({"name": "static parent", "matrix": mat(a.parent), "children": [target]}),
            );
            child = Some(nodes.len() - 1);
        }
    }
    (child.unwrap_or(0), channels, samplers)
}
