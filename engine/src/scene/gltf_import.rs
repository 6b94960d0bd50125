//! glTF 2.0 (.gltf, .glb) import through the `gltf` crate, following the scene conventions.
//!
//! Files are untrusted: everything the `gltf` crate's validation leaves out is checked before it
//! is used (`gltf_check`, `accessor`), side files are read through [`SceneFiles`] (inside the
//! scene's folder, regular files only), and every size is held to a [`Limits`] budget. A problem
//! is an error that names the JSON path, or a warning and a neutral fallback where a viewer can
//! live with it (a missing texture, an unsupported optional extension, an orthographic camera).

use super::files::{SceneFiles, SceneFolder, read_uri, short};
use super::gltf_animation::animations;
use super::gltf_camera::{camera_pose, local_rotation};
use super::gltf_importer::Importer;
use super::gltf_mesh::primitive;
use super::{
    Animation, Camera, DEFAULT_MAX_DEPTH, Deform, EnvMap, Environment, Light, Material, Mesh,
    Object, Scene,
};
use crate::limits::{Budget, Limits, over_budget, read_regular_file};
use anyhow::{Context, Result, anyhow, bail};
use glam::{DMat4, DQuat, DVec3, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// Extensions whose meaning Hush implements. Anything else is ignored with a warning when
/// optional and refused when required.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_specular",
    "KHR_texture_transform",
    "KHR_mesh_quantization",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    super::meshopt::EXTENSION,
];

/// Largest texture side kept on load (larger ones are halved until they fit).
pub const DEFAULT_MAX_TEXTURE_SIZE: u32 = 2048;

/// How a scene is loaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Largest texture side kept; larger textures are halved until they fit.
    pub max_texture_size: u32,
    pub limits: Limits,
    /// Which of the file's animations plays (its index); None plays every one at once (a node
    /// that several drive loops over the longest of them).
    pub animation: Option<usize>,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            max_texture_size: DEFAULT_MAX_TEXTURE_SIZE,
            limits: Limits::default(),
            animation: None,
        }
    }
}

pub fn load_gltf(path: &Path) -> Result<Scene> {
    load_gltf_opts(path, &LoadOptions::default())
}

pub fn load_gltf_with(path: &Path, max_texture_size: u32) -> Result<Scene> {
    load_gltf_opts(path, &LoadOptions { max_texture_size, ..LoadOptions::default() })
}

/// Load a `.gltf`/`.glb` file. Its side files are read from the folder it really lies in
/// (symlinks resolved), and nothing outside that folder.
pub fn load_gltf_opts(path: &Path, opts: &LoadOptions) -> Result<Scene> {
    let ctx = || format!("loading glTF scene {}", path.display());
    let real = std::fs::canonicalize(path).map_err(|e| anyhow!("{e}")).with_context(ctx)?;
    let bytes = read_regular_file(&real, opts.limits.file_bytes).with_context(ctx)?;
    let folder = SceneFolder::new(real.parent().unwrap_or(Path::new("/"))).with_context(ctx)?;
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    load_gltf_from(&bytes, &name, &folder, opts).with_context(ctx)
}

/// Load a scene from the bytes of its `.gltf`/`.glb` file, reading the files it names from
/// `files`. A panic inside a dependency comes back as an error: a last line of defence, as
/// every input known to cause one is refused before it reaches the dependency.
pub fn load_gltf_from(
    bytes: &[u8],
    name: &str,
    files: &dyn SceneFiles,
    opts: &LoadOptions,
) -> Result<Scene> {
    let run = std::panic::AssertUnwindSafe(|| {
        let (document, blob) = parse(bytes, &opts.limits)?;
        Importer {
            files,
            warnings: vec![],
            max_texture_size: opts.max_texture_size,
            budget: Budget::new(opts.limits),
            triangles: 0,
            animation: opts.animation,
        }
        .import(&document, blob, name.to_string())
    });
    std::panic::catch_unwind(run).unwrap_or_else(|p| {
        Err(crate::Error::ImportPanic(crate::error::panic_message(p.as_ref())).into())
    })
}

/// JSON (from a .gltf or a .glb's JSON chunk) -> validated document, refusing unsupported
/// required extensions by name (the `gltf` crate's own error only says "Unsupported").
fn parse(bytes: &[u8], limits: &Limits) -> Result<(gltf::Document, Option<Vec<u8>>)> {
    let (json, blob) = if bytes.starts_with(b"glTF") {
        // The gltf crate subtracts the header's 12 bytes from this length unchecked.
        let length = bytes.get(8..12).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        if length.is_some_and(|l| l < 12) {
            bail!(
                "reading GLB container: its length {} is shorter than its 12-byte header",
                length.unwrap_or(0)
            );
        }
        let glb =
            gltf::Glb::from_slice(bytes).map_err(|e| anyhow!("reading GLB container: {e}"))?;
        (glb.json, glb.bin.map(|b| b.to_vec()))
    } else {
        (std::borrow::Cow::Borrowed(bytes), None)
    };
    if json.len() as u64 > limits.json_bytes {
        return Err(over_budget(
            "json-bytes",
            "the file's JSON",
            json.len() as u64,
            limits.json_bytes,
        ));
    }
    let mut v: serde_json::Value =
        serde_json::from_slice(&json).map_err(|e| anyhow!("parsing glTF JSON: {e}"))?;
    drop(json);
    let mut unsupported = vec![];
    if let Some(req) = v.get("extensionsRequired").and_then(|r| r.as_array()) {
        for e in req.iter().filter_map(|e| e.as_str()) {
            if !SUPPORTED_EXTENSIONS.contains(&e) {
                unsupported.push(short(e));
            }
        }
    }
    if !unsupported.is_empty() {
        let supported = SUPPORTED_EXTENSIONS.iter().map(|e| e.to_string()).collect();
        return Err(crate::Error::UnsupportedExtension { unsupported, supported }.into());
    }
    // Every required extension is one Hush implements (checked above); the `gltf` crate would
    // refuse those it has no feature for (KHR_mesh_quantization, EXT_meshopt_compression), so
    // the list is not passed on.
    if let Some(o) = v.as_object_mut() {
        o.remove("extensionsRequired");
    }
    // `scene.nodes` is optional in glTF 2.0, but the `gltf` crate's schema requires it.
    if let Some(scenes) = v.get_mut("scenes").and_then(|s| s.as_array_mut()) {
        for s in scenes.iter_mut().filter_map(|s| s.as_object_mut()) {
            s.entry("nodes").or_insert_with(|| serde_json::json!([]));
        }
    }
    let root: gltf::json::Root =
        serde_json::from_value(v).map_err(|e| anyhow!("reading glTF JSON: {e}"))?;
    super::gltf_check::check(&root, limits)?;
    let document = gltf::Document::from_json(root).map_err(|e| anyhow!("invalid glTF: {e}"))?;
    Ok((document, blob))
}

/// An orthographic camera, rendered through a perspective one once the scene's bounds are known.
struct Orthographic {
    index: usize,
    pose: DMat4,
    ymag: f64,
}

impl Importer<'_> {
    fn import(
        mut self,
        doc: &gltf::Document,
        blob: Option<Vec<u8>>,
        name: String,
    ) -> Result<Scene> {
        for ext in doc.extensions_used() {
            if !SUPPORTED_EXTENSIONS.contains(&ext) {
                self.warn(format!(
                    "optional glTF extension {} is not supported; ignored",
                    short(ext)
                ));
            }
        }
        let mut buffers = self.load_buffers(doc, blob)?;
        super::meshopt::decompress(doc.as_json(), &mut buffers, &mut self.budget)?;
        let (textures, tex_map) = self.load_textures(doc, &buffers)?;
        let materials: Vec<Material> =
            doc.materials().map(|m| self.material(&m, &tex_map)).collect();
        let mut scene =
            Scene { name, textures, materials, max_depth: DEFAULT_MAX_DEPTH, ..Default::default() };
        let default_material = scene.materials.len() as u32;
        scene.materials.push(Material::default());

        let gscene = doc
            .default_scene()
            .or_else(|| doc.scenes().next())
            .ok_or_else(|| anyhow!("the file has no scene"))?;
        self.scene_extras(&gscene, &mut scene)?;
        let data = super::accessor::Data { root: doc.as_json(), buffers: &buffers };
        let mut mesh_cache: HashMap<usize, Vec<usize>> = HashMap::new();
        scene.animations = doc
            .animations()
            .map(|a| a.name().map_or_else(|| format!("animation {}", a.index()), str::to_string))
            .collect();
        let only = self.animation;
        let mut animated = animations(&mut self, doc, &data, only)?;
        let mut ortho: Option<Orthographic> = None;
        // Each node's rest world transform and, where it or an ancestor is animated, its
        // animation: what places the joints of skins, filled in as the walk meets them.
        let mut placed: HashMap<usize, (DMat4, Option<Animation>)> = HashMap::new();
        // Skinned objects wait for the walk to place every joint: (object, skin).
        let mut skinned: Vec<(usize, usize)> = vec![];
        // (node, parent world transform, parent world rotation, the parent's animation).
        // The node hierarchy is a forest (gltf_check), so this walk visits each node once.
        let mut stack: Vec<(gltf::Node, DMat4, DQuat, Option<Animation>)> =
            gscene.nodes().map(|n| (n, DMat4::IDENTITY, DQuat::IDENTITY, None)).collect();
        while let Some((node, parent, parent_rotation, parent_motion)) = stack.pop() {
            let local =
                DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(|x| x as f64)));
            let world = parent * local;
            let rotation = parent_rotation * local_rotation(&node);
            if !world.is_finite() {
                self.warn(format!(
                    "nodes[{}] has a non-finite transform; skipped with its children",
                    node.index()
                ));
                continue;
            }
            // Its own channels under its parent's motion, or carried by that motion.
            let animation = match (animated.nodes.remove(&node.index()), parent_motion) {
                (Some(mut a), Some(up)) => {
                    a.parent_motion = Some(std::sync::Arc::new(up));
                    Some(a)
                }
                (Some(mut a), None) => {
                    a.parent = parent;
                    Some(a)
                }
                (None, Some(up)) => Some(Animation::carried(up, local)),
                (None, None) => None,
            };
            placed.insert(node.index(), (world, animation.clone()));
            if let Some(mesh) = node.mesh() {
                let ids = match mesh_cache.get(&mesh.index()) {
                    Some(ids) => ids.clone(),
                    None => {
                        let ids = self.mesh(&mesh, &data, default_material, &mut scene.meshes)?;
                        mesh_cache.insert(mesh.index(), ids.clone());
                        ids
                    }
                };
                let placed: u64 =
                    ids.iter().map(|&id| scene.meshes[id].indices.len() as u64 / 3).sum();
                self.place_triangles(
                    placed,
                    format_args!("nodes[{}] (meshes[{}])", node.index(), mesh.index()),
                )?;
                let morph = self.morph(&node, &mesh, &mut animated.weights);
                let skin = node
                    .skin()
                    .filter(|_| ids.iter().any(|&id| !scene.meshes[id].joints.is_empty()));
                for id in ids {
                    let deform = (morph.is_some() || skin.is_some()).then(|| {
                        std::sync::Arc::new(Deform { skin: vec![], morph: morph.clone() })
                    });
                    if let Some(s) = &skin {
                        skinned.push((scene.objects.len(), s.index()));
                    }
                    // A skinned mesh is placed by its joints alone (glTF 2.0 §3.7.3.3).
                    let skinned = skin.is_some() && !scene.meshes[id].joints.is_empty();
                    scene.objects.push(Object {
                        name: node.name().unwrap_or("").to_string(),
                        mesh: id,
                        transform: if skinned { DMat4::IDENTITY } else { world },
                        animation: if skinned { None } else { animation.clone() },
                        deform,
                    });
                }
            }
            if let Some(light) = node.light() {
                scene.lights.push(self.light(&light, &world));
            }
            if let Some(cam) = node.camera()
                && scene.camera.is_none()
                && ortho.is_none()
            {
                match camera_pose(world, rotation) {
                        None => self.warn(format!("nodes[{}] places cameras[{}] with a degenerate transform; using a default view", node.index(), cam.index())),
                        Some(pose) => match cam.projection() {
                            gltf::camera::Projection::Perspective(p) => scene.camera = Some(Camera { world: pose, yfov: p.yfov(), lens: camera_lens(&cam)? }),
                            gltf::camera::Projection::Orthographic(o) => {
                                ortho = Some(Orthographic { index: cam.index(), pose, ymag: o.ymag().abs() as f64 })
                            }
                        },
                    }
            }
            if animation.is_some() && (node.light().is_some() || node.camera().is_some()) {
                self.warn(format!(
                    "nodes[{}] moves a light or a camera, which stay at their rest pose",
                    node.index()
                ));
            }
            for child in node.children() {
                stack.push((child, world, rotation, animation.clone()));
            }
        }
        self.bind_skins(doc, &data, &placed, &skinned, &mut scene)?;
        if let Some(o) = ortho {
            scene.camera = Some(self.perspective_for(&o, &scene));
        }
        if scene.triangle_count() > 0 && scene.bounds().is_none() {
            bail!("no vertex of the scene's triangles has a finite position");
        }
        scene.warnings = self.warnings;
        Ok(scene)
    }

    /// Refuse `n` more triangles than placed so far where they would exceed the triangles budget.
    pub(super) fn triangles_fit(&self, n: u64, what: std::fmt::Arguments) -> Result<()> {
        let total = self.triangles.saturating_add(n);
        let limit = self.budget.limits.triangles;
        if total > limit {
            return Err(over_budget(
                "triangles",
                format_args!("the scene, up to {what},"),
                total,
                limit,
            ));
        }
        Ok(())
    }

    /// Count `n` more triangles against the triangles budget.
    fn place_triangles(&mut self, n: u64, what: std::fmt::Arguments) -> Result<()> {
        self.triangles_fit(n, what)?;
        self.triangles += n;
        Ok(())
    }

    /// Hush renders perspective cameras only: an orthographic camera becomes a perspective one
    /// at its pose whose view, at the distance of the scene's centre, is as tall as the
    /// orthographic one's (2 ymag).
    fn perspective_for(&mut self, o: &Orthographic, scene: &Scene) -> Camera {
        let eye = o.pose.w_axis.truncate();
        let fwd = -o.pose.z_axis.truncate();
        let (lo, hi) = scene.bounds().unwrap_or((eye - DVec3::ONE, eye + DVec3::ONE));
        let extent = (hi - lo).length().max(1e-9);
        let d = ((lo + hi) * 0.5 - eye).dot(fwd);
        let d = if d > 1e-6 * extent { d } else { 0.5 * extent };
        let yfov = (2.0 * (o.ymag / d).atan()).clamp(1f64.to_radians(), 150f64.to_radians()) as f32;
        self.warn(format!(
            "cameras[{}] is orthographic; Hush renders it as a perspective camera at its place with a vertical field of view of {:.1} degrees (its height 2 x ymag = {:.3} at the scene's centre, {:.3} away)",
            o.index,
            yfov.to_degrees(),
            2.0 * o.ymag,
            d
        ));
        Camera { world: o.pose, yfov, lens: None }
    }

    fn load_buffers(
        &mut self,
        doc: &gltf::Document,
        mut blob: Option<Vec<u8>>,
    ) -> Result<Vec<Vec<u8>>> {
        let limit = self.budget.limits.file_bytes;
        let mut out = vec![];
        for b in doc.buffers() {
            if super::meshopt::is_fallback(&b) {
                // Space for compressed views to decode into (super::meshopt), charged first.
                self.budget.decode(b.length() as u64, format_args!("buffers[{}]", b.index()))?;
                out.push(vec![0u8; b.length()]);
                continue;
            }
            let data = match b.source() {
                gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                    anyhow!(
                        "buffers[{}] has no uri and there is no (unclaimed) GLB binary chunk",
                        b.index()
                    )
                })?,
                gltf::buffer::Source::Uri(uri) => read_uri(self.files, uri, limit)
                    .with_context(|| format!("buffers[{}] ({})", b.index(), short(uri)))?,
            };
            if (data.len() as u64) < b.length() as u64 {
                bail!(
                    "buffers[{}] holds {} bytes, the file says {}",
                    b.index(),
                    data.len(),
                    b.length()
                );
            }
            self.budget.decode(data.len() as u64, format_args!("buffers[{}]", b.index()))?;
            out.push(data);
        }
        Ok(out)
    }

    fn mesh(
        &mut self,
        mesh: &gltf::Mesh,
        data: &super::accessor::Data,
        default_material: u32,
        out: &mut Vec<Mesh>,
    ) -> Result<Vec<usize>> {
        let mut ids = vec![];
        for prim in mesh.primitives() {
            let here = format!("meshes[{}].primitives[{}]", mesh.index(), prim.index());
            let Some(m) = primitive(self, &prim, data, default_material, &here)? else { continue };
            ids.push(out.len());
            out.push(m);
        }
        Ok(ids)
    }

    fn light(&mut self, l: &gltf::khr_lights_punctual::Light, world: &DMat4) -> Light {
        use gltf::khr_lights_punctual::Kind;
        let c = Vec3::from(l.color()) * l.intensity();
        let c = if c.is_finite() && c.min_element() >= 0.0 {
            c
        } else {
            self.warn(format!("light {}: colour x intensity {c} is not finite and non-negative; the light is black", l.index()));
            Vec3::ZERO
        };
        if l.range().is_some() {
            self.warn("light range is ignored (lights follow the inverse-square law)".into());
        }
        let position = world.w_axis.truncate();
        let direction = (-world.z_axis.truncate()).normalize_or(DVec3::NEG_Z).as_vec3();
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
        let v: serde_json::Value =
            serde_json::from_str(raw.get()).context("parsing scene extras")?;
        let here = format!("scenes[{}].extras", s.index());
        if let Some(r) = v.get("resolution") {
            let wh = r
                .as_array()
                .filter(|a| a.len() == 2)
                .and_then(|a| Some((a[0].as_u64()?, a[1].as_u64()?)))
                .filter(|&(w, h)| w > 0 && h > 0 && w <= 16384 && h <= 16384)
                .ok_or_else(|| {
                    anyhow!(
                        "{here}.resolution must be [width, height] in 1..=16384, got {}",
                        shown(r)
                    )
                })?;
            scene.resolution = Some((wh.0 as u32, wh.1 as u32));
        }
        if let Some(d) = v.get("max_depth") {
            scene.max_depth =
                d.as_i64().filter(|&d| (-1..=1 << 16).contains(&d)).ok_or_else(|| {
                    anyhow!("{here}.max_depth must be an integer in -1..=65536, got {}", shown(d))
                })? as i32;
        }
        // Written by Hush's exporter: the environment is the sun's procedural sky.
        if let Some(p) = v.get("procedural_sky") {
            scene.procedural_sky = p.as_bool().ok_or_else(|| {
                anyhow!("{here}.procedural_sky must be true or false, got {}", shown(p))
            })?;
        }
        let Some(env) = v.get("environment") else { return Ok(()) };
        if let Some(obj) = env.as_object() {
            let known: &[&str] = if obj.contains_key("radiance") {
                &["radiance"]
            } else {
                &["map", "intensity", "rotation_y_degrees"]
            };
            for k in obj.keys().filter(|k| !known.contains(&k.as_str())) {
                self.warn(format!(
                    "{here}.environment.{}: not used with {}; ignored",
                    short(k),
                    known[0]
                ));
            }
        }
        let number =
            |key: &str, default: f64, ok: &dyn Fn(f64) -> bool, what: &str| -> Result<f64> {
                match env.get(key) {
                    None => Ok(default),
                    Some(x) => x.as_f64().filter(|x| x.is_finite() && ok(*x)).ok_or_else(|| {
                        anyhow!("{here}.environment.{key} must be {what}, got {}", shown(x))
                    }),
                }
            };
        if let Some(rad) = env.get("radiance") {
            let c = rad
                .as_array()
                .filter(|a| a.len() == 3)
                .and_then(|a| {
                    Some(Vec3::new(
                        a[0].as_f64()? as f32,
                        a[1].as_f64()? as f32,
                        a[2].as_f64()? as f32,
                    ))
                })
                .filter(|c| c.is_finite() && c.min_element() >= 0.0)
                .ok_or_else(|| {
                    anyhow!(
                        "{here}.environment.radiance must be [r, g, b] >= 0, got {}",
                        shown(rad)
                    )
                })?;
            scene.environment = Environment::Constant(c);
        } else if let Some(map) = env.get("map") {
            let map = map.as_str().ok_or_else(|| {
                anyhow!("{here}.environment.map must be a file name, got {}", shown(map))
            })?;
            let intensity = number("intensity", 1.0, &|x| x >= 0.0, "a number >= 0")? as f32;
            let rot = number("rotation_y_degrees", 0.0, &|_| true, "a number (degrees)")? as f32;
            let bytes = read_uri(self.files, map, self.budget.limits.file_bytes)
                .with_context(|| format!("{here}.environment.map"))?;
            scene.environment = Environment::Map(EnvMap::from_exr(
                &short(map),
                &bytes,
                intensity,
                rot,
                &mut self.budget,
            )?);
        } else {
            bail!("{here}.environment needs `radiance` or `map`, got {}", shown(env));
        }
        Ok(())
    }
}

/// A JSON value for an error message, shortened.
fn shown(v: &serde_json::Value) -> String {
    let s = v.to_string();
    if s.len() > 80 { short(&s) } else { s }
}

/// A camera's thin lens from its `extras` (`aperture_radius` and `focus_distance`, meters):
/// both or neither.
fn camera_lens(cam: &gltf::Camera) -> Result<Option<crate::scene::ThinLens>> {
    let Some(raw) = cam.extras() else { return Ok(None) };
    let here = format!("cameras[{}].extras", cam.index());
    let v: serde_json::Value =
        serde_json::from_str(raw.get()).with_context(|| format!("parsing {here}"))?;
    let num = |k: &str| {
        v.get(k)
            .map(|x| {
                x.as_f64().ok_or_else(|| {
                    anyhow!("{here}.{k} must be a number of meters, got {}", shown(x))
                })
            })
            .transpose()
    };
    match (num("aperture_radius")?, num("focus_distance")?) {
        (None, None) => Ok(None),
        (Some(a), Some(f)) => {
            crate::scene::ThinLens::new(a, f).map(Some).with_context(|| here.clone())
        }
        _ => Err(anyhow!("{here} needs both aperture_radius and focus_distance for a thin lens")),
    }
}
