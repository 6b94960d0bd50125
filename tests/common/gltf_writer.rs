//! Writes small glTF files (buffers embedded as data URIs) for synthetic test scenes.

use base64::Engine;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

#[derive(Default)]
pub struct GltfWriter {
    bin: Vec<u8>,
    pub accessors: Vec<Value>,
    pub views: Vec<Value>,
    pub meshes: Vec<Value>,
    pub materials: Vec<Value>,
    pub nodes: Vec<Value>,
    pub cameras: Vec<Value>,
    pub lights: Vec<Value>,
    pub extras: Value,
    pub extensions_required: Vec<String>,
}

pub struct Prim<'a> {
    pub positions: &'a [[f32; 3]],
    pub normals: Option<&'a [[f32; 3]]>,
    pub indices: Option<&'a [u32]>,
    pub material: usize,
}

impl GltfWriter {
    fn push_data(&mut self, bytes: &[u8], target: u32) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let off = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.views.push(
            json!({"buffer": 0, "byteOffset": off, "byteLength": bytes.len(), "target": target}),
        );
        self.views.len() - 1
    }

    fn vec3_accessor(&mut self, v: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.push_data(&bytes, 34962);
        let finite: Vec<&[f32; 3]> = v.iter().filter(|p| p.iter().all(|x| x.is_finite())).collect();
        let mut lo = [f32::MAX; 3];
        let mut hi = [f32::MIN; 3];
        for p in &finite {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if finite.is_empty() {
            lo = [0.0; 3];
            hi = [0.0; 3];
        }
        self.accessors.push(json!({"bufferView": view, "componentType": 5126, "count": v.len(), "type": "VEC3", "min": lo, "max": hi}));
        self.accessors.len() - 1
    }

    /// A float accessor of `ty` ("VEC2", "VEC4", ...) over `v`; returns its index.
    pub fn floats(&mut self, v: &[f32], ty: &str) -> usize {
        let n = match ty {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "MAT4" => 16,
            _ => 4,
        };
        let bytes: Vec<u8> = v.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.push_data(&bytes, 34962);
        self.accessors.push(
            json!({"bufferView": view, "componentType": 5126, "count": v.len() / n, "type": ty}),
        );
        self.accessors.len() - 1
    }

    /// A normalized UNSIGNED_BYTE accessor of `ty` over `v` (each element padded to 4 bytes,
    /// as glTF aligns vertex attributes); returns its index.
    pub fn unorm8(&mut self, v: &[u8], ty: &str) -> usize {
        let n = if ty == "VEC3" { 3 } else { 4 };
        let bytes: Vec<u8> = v.chunks(n).flat_map(|c| [c, &[0u8; 4][..4 - n]].concat()).collect();
        let view = self.push_data(&bytes, 34962);
        self.views[view]["byteStride"] = json!(4);
        self.accessors.push(json!({"bufferView": view, "componentType": 5121, "normalized": true, "count": v.len() / n, "type": ty}));
        self.accessors.len() - 1
    }

    /// A mesh with one triangle primitive; returns the mesh index.
    pub fn mesh(&mut self, p: Prim) -> usize {
        let pos = self.vec3_accessor(p.positions);
        let mut attrs = json!({"POSITION": pos});
        if let Some(n) = p.normals {
            attrs["NORMAL"] = json!(self.vec3_accessor(n));
        }
        let mut prim = json!({"attributes": attrs, "material": p.material});
        if let Some(idx) = p.indices {
            let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
            let view = self.push_data(&bytes, 34963);
            self.accessors.push(json!({"bufferView": view, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}));
            prim["indices"] = json!(self.accessors.len() - 1);
        }
        self.meshes.push(json!({"primitives": [prim]}));
        self.meshes.len() - 1
    }

    /// A mesh built by the engine's scene helpers (scene::quad, scene::cuboid); its positions,
    /// normals and indices, with `material` of this file.
    pub fn engine_mesh(&mut self, m: &hush_engine::scene::Mesh, material: usize) -> usize {
        let arrays = |v: &[glam::Vec3]| v.iter().map(|p| p.to_array()).collect::<Vec<_>>();
        self.mesh(Prim {
            positions: &arrays(&m.positions),
            normals: Some(&arrays(&m.normals)),
            indices: Some(&m.indices),
            material,
        })
    }

    pub fn lambert(&mut self, c: [f32; 3]) -> usize {
        self.materials.push(json!({
            "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
            "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}
        }));
        self.materials.len() - 1
    }

    pub fn metal(&mut self, c: [f32; 3], roughness: f32) -> usize {
        self.materials.push(json!({
            "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": 1.0, "roughnessFactor": roughness}
        }));
        self.materials.len() - 1
    }

    pub fn emitter(&mut self, radiance: f32) -> usize {
        self.materials.push(json!({
            "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
            "emissiveFactor": [1.0, 1.0, 1.0],
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": radiance}}
        }));
        self.materials.len() - 1
    }

    pub fn node(&mut self, v: Value) -> usize {
        self.nodes.push(v);
        self.nodes.len() - 1
    }

    /// A camera node at `eye` looking at `target` (yfov radians).
    pub fn camera(&mut self, eye: [f32; 3], target: [f32; 3], yfov: f32) -> usize {
        let e = glam::Vec3::from(eye);
        let z = (e - glam::Vec3::from(target)).normalize();
        let x = glam::Vec3::Y.cross(z).normalize_or(glam::Vec3::X);
        let y = z.cross(x);
        let m = glam::Mat4::from_cols(x.extend(0.0), y.extend(0.0), z.extend(0.0), e.extend(1.0));
        self.cameras.push(json!({"type": "perspective", "perspective": {"yfov": yfov, "znear": 0.01, "aspectRatio": 1.0}}));
        self.node(json!({"camera": self.cameras.len() - 1, "matrix": m.to_cols_array()}))
    }

    pub fn to_json(&self) -> Value {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&self.bin)
        );
        let roots: Vec<usize> = (0..self.nodes.len())
            .filter(|i| {
                !self
                    .nodes
                    .iter()
                    .any(|n| n["children"].as_array().is_some_and(|c| c.contains(&json!(i))))
            })
            .collect();
        let mut j = json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": roots, "extras": self.extras}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{"byteLength": self.bin.len().max(1), "uri": uri}],
            "extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength", "KHR_lights_punctual"],
        });
        if self.bin.is_empty() {
            j["buffers"] = json!([]);
        }
        if !self.cameras.is_empty() {
            j["cameras"] = json!(self.cameras);
        }
        if !self.lights.is_empty() {
            j["extensions"] = json!({"KHR_lights_punctual": {"lights": self.lights}});
        }
        if !self.extensions_required.is_empty() {
            j["extensionsRequired"] = json!(self.extensions_required);
        }
        j
    }

    /// Write `name.gltf` into a fresh folder under the system temp dir; returns its path.
    pub fn write(&self, name: &str) -> PathBuf {
        write_json(name, &self.to_json())
    }
}

pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hush-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub fn write_json(name: &str, v: &Value) -> PathBuf {
    let p = temp_dir(name).join(format!("{name}.gltf"));
    std::fs::write(&p, serde_json::to_string_pretty(v).unwrap()).unwrap();
    p
}

/// Copy an oracle scene's .gltf (edited by `edit`) and its .bin into a temp folder.
pub fn edited_copy(src_gltf: &Path, name: &str, edit: impl FnOnce(&mut Value)) -> PathBuf {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(src_gltf).unwrap()).unwrap();
    edit(&mut v);
    let dir = temp_dir(name);
    for b in v["buffers"].as_array().unwrap() {
        let uri = b["uri"].as_str().unwrap();
        std::fs::copy(src_gltf.parent().unwrap().join(uri), dir.join(uri)).unwrap();
    }
    let p = dir.join(format!("{name}.gltf"));
    std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
    p
}

/// A white (0.7) Lambertian floor, 20 m square at y = 0, under a square emitter facing down
/// (centre, half size, radiance), seen straight down from `eye` (vertical field of view 1 rad,
/// square): a scene whose light is all direct, as the floor sees nothing but the emitter.
pub fn floor_under_light(
    name: &str,
    light: (glam::Vec3, f32, f32),
    eye: [f32; 3],
) -> hush_engine::scene::Scene {
    use glam::Vec3;
    use hush_engine::scene::quad;
    let mut g = GltfWriter::default();
    let white = g.lambert([0.7; 3]);
    let lamp = g.emitter(light.2);
    let floor = quad(Vec3::ZERO, Vec3::Z * 10.0, Vec3::X * 10.0, 0);
    let emitter = quad(light.0, Vec3::X * light.1, Vec3::Z * light.1, 0);
    for (mesh, material) in [(floor, white), (emitter, lamp)] {
        let m = g.engine_mesh(&mesh, material);
        g.node(json!({"mesh": m}));
    }
    g.camera(eye, [eye[0], 0.0, eye[2] + 0.001], 1.0);
    hush_engine::scene::load_gltf(&g.write(name)).unwrap()
}
