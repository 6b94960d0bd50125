//! Scenes on the CPU: what a glTF file (or the built-in default scene) describes, in the units and
//! conventions of `docs/scenes.md`.

mod accessor;
mod animation;
mod camera_path;
mod crowd;
mod default_scene;
mod deform;
mod environment;
mod files;
mod gltf_animation;
mod gltf_camera;
mod gltf_check;
mod gltf_deform;
mod gltf_export;
mod gltf_import;
mod gltf_importer;
mod gltf_material;
mod gltf_mesh;
mod level;
mod meshopt;
mod reflections;
mod sky;
mod terrain;
mod texture;

pub use animation::{Animation, Track};
pub use camera_path::{CameraKey, CameraPath};
pub use crowd::{MAX_CROWD, crowd};
pub use default_scene::{cuboid, default_scene, quad, uv_sphere};
pub use deform::{Deform, Joint, MAX_INFLUENCES, Morph, MorphTarget, Posed};
pub use environment::{EnvMap, Environment};
pub use files::{MemoryFiles, SceneFiles, SceneFolder};
pub use gltf_export::save_gltf;
pub use gltf_import::{
    DEFAULT_MAX_TEXTURE_SIZE, LoadOptions, SUPPORTED_EXTENSIONS, load_gltf, load_gltf_from,
    load_gltf_opts, load_gltf_with,
};
pub use level::{DEFAULT_SUN, default_level, default_level_with_sun};
pub use reflections::{BUILTIN_SCENES, builtin_scene, reflection_scene};
pub use terrain::{MAX_TERRAIN_TRIANGLES, terrain};
pub use texture::{Texture, TextureRef, Wrap, mip_chain_texels};

use anyhow::Result;
use glam::{DMat4, DVec3, Vec2, Vec3, Vec4};
use std::path::Path;
use std::sync::Arc;

/// One triangle mesh (one glTF primitive) in its object's local space.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals; flat normals are generated where the file has none.
    pub normals: Vec<Vec3>,
    /// TEXCOORD_0, or zeros.
    pub uvs: Vec<Vec2>,
    /// TEXCOORD_1, or empty where no texture of the mesh's material reads it.
    pub uvs1: Vec<Vec2>,
    /// COLOR_0 (RGBA, alpha 1 where the file stores RGB), multiplied into the base colour; empty
    /// without one.
    pub colors: Vec<Vec4>,
    /// xyz tangent, w handedness; only filled when the material has a normal map.
    pub tangents: Vec<Vec4>,
    pub indices: Vec<u32>,
    pub material: u32,
    /// Skinned meshes: per vertex, JOINTS_0 then JOINTS_1 (indices into the object's skin) and
    /// their weights (normalised, 0 for absent influences); empty otherwise.
    pub joints: Vec<[u16; MAX_INFLUENCES]>,
    pub weights: Vec<[f32; MAX_INFLUENCES]>,
    /// Morph targets (glTF 2.0 §3.7.2.2).
    pub targets: Vec<MorphTarget>,
}

/// A placed mesh. Transforms are kept in f64 so that a scene far from the origin keeps its
/// precision until it is rebased around its own centre (see [`Scene::origin`]).
#[derive(Clone, Debug)]
pub struct Object {
    pub name: String,
    pub mesh: usize,
    /// World transform at time 0 (the rest pose of an animated object).
    pub transform: DMat4,
    /// Rigid motion over time, if the object moves.
    pub animation: Option<Animation>,
    /// Skin and morph targets, if its mesh deforms (then `transform` is the identity for a
    /// skinned mesh, whose joints place it).
    pub deform: Option<Arc<Deform>>,
}

impl Object {
    /// A static object.
    pub fn new(name: impl Into<String>, mesh: usize, transform: DMat4) -> Object {
        Object { name: name.into(), mesh, transform, animation: None, deform: None }
    }

    /// World transform at `time` seconds.
    pub fn transform_at(&self, time: f64) -> DMat4 {
        self.animation.as_ref().map_or(self.transform, |a| a.world_at(time))
    }

    /// Whether it moves or deforms over time.
    pub fn moves(&self) -> bool {
        self.animation.is_some() || self.deform.as_ref().is_some_and(|d| d.moves())
    }

    /// Whether its mesh must be posed ([`Object::mesh_at`]) rather than read as stored.
    pub fn deforms(&self) -> bool {
        self.deform.is_some()
    }

    /// Its mesh at `time` seconds (None: the rest pose): `mesh` itself, or posed by its skin
    /// and morph targets.
    pub fn mesh_at<'a>(&self, mesh: &'a Mesh, time: Option<f64>) -> std::borrow::Cow<'a, Mesh> {
        match &self.deform {
            Some(d) => std::borrow::Cow::Owned(d.pose(mesh, time)),
            None => std::borrow::Cow::Borrowed(mesh),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    Opaque,
    /// Cut out where base colour alpha < cutoff.
    Mask(f32),
    /// Seen with probability alpha (stochastic transparency): each ray, and each real-time
    /// frame's raster, passes through with probability 1 - alpha, so that every mean converges
    /// to alpha x this surface + (1 - alpha) x what lies behind it, as glTF's "over" blend.
    Blend,
}

/// glTF metallic-roughness material (+ KHR_materials_specular, KHR_materials_emissive_strength).
#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    pub base_color: Vec4,
    pub base_color_texture: Option<TextureRef>,
    pub metallic: f32,
    pub roughness: f32,
    /// Roughness in G, metallic in B (glTF).
    pub metallic_roughness_texture: Option<TextureRef>,
    pub normal_texture: Option<TextureRef>,
    pub normal_scale: f32,
    /// emissiveFactor x emissiveStrength: radiance in W/m^2/sr, front face only.
    pub emission: Vec3,
    pub emissive_texture: Option<TextureRef>,
    /// KHR_materials_specular: 0 makes a dielectric purely Lambertian.
    pub specular_factor: f32,
    pub specular_color: Vec3,
    /// KHR_materials_ior: a dielectric's F0 is ((ior - 1) / (ior + 1))^2 (0.04 at the default
    /// 1.5), times the specular colour.
    pub ior: f32,
    /// KHR_materials_transmission: the share of the dielectric base that lets light through
    /// (tinted by the base colour) instead of scattering it diffusely. 0 is opaque. A
    /// transmissive material is two-sided whatever `double_sided` says: an interface has two.
    pub transmission: f32,
    /// KHR_materials_volume: 0 is thin-walled (light passes straight through, unrefracted);
    /// more means the mesh closes a volume that refracts by `ior` on the way in and out.
    pub thickness: f32,
    /// KHR_materials_volume: inside the volume, light keeps `attenuation_color` of itself per
    /// `attenuation_distance` metres travelled (Beer-Lambert); infinite distance absorbs nothing.
    pub attenuation_color: Vec3,
    pub attenuation_distance: f32,
    pub alpha_mode: AlphaMode,
    pub double_sided: bool,
}

impl Default for Material {
    fn default() -> Self {
        // glTF's default material.
        Self {
            name: "default".into(),
            base_color: Vec4::ONE,
            base_color_texture: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            emission: Vec3::ZERO,
            emissive_texture: None,
            specular_factor: 1.0,
            specular_color: Vec3::ONE,
            ior: 1.5,
            transmission: 0.0,
            thickness: 0.0,
            attenuation_color: Vec3::ONE,
            attenuation_distance: f32::INFINITY,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
        }
    }
}

impl Material {
    /// Its textures in the shaders' slot order: base colour, metallic-roughness, normal, emissive.
    pub fn texture_refs(&self) -> [Option<TextureRef>; 4] {
        [
            self.base_color_texture,
            self.metallic_roughness_texture,
            self.normal_texture,
            self.emissive_texture,
        ]
    }

    /// Absorption coefficient per metre inside a volume (KHR_materials_volume):
    /// -ln(attenuation colour) / attenuation distance, 0 where nothing is absorbed.
    pub fn absorption(&self) -> Vec3 {
        if self.thickness <= 0.0 || !self.attenuation_distance.is_finite() {
            return Vec3::ZERO;
        }
        let c = self.attenuation_color.clamp(Vec3::splat(1e-6), Vec3::ONE);
        Vec3::new(-c.x.ln(), -c.y.ln(), -c.z.ln()) / self.attenuation_distance
    }

    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }
}

/// KHR_lights_punctual, in the radiometric reading of the conventions.
#[derive(Clone, Copy, Debug)]
pub enum Light {
    /// `direction` is where the light travels (the node's -Z); `irradiance` in W/m^2.
    Directional {
        direction: Vec3,
        irradiance: Vec3,
    },
    /// Radiant intensity in W/sr.
    Point {
        position: DVec3,
        intensity: Vec3,
    },
    Spot {
        position: DVec3,
        direction: Vec3,
        intensity: Vec3,
        inner_cone: f32,
        outer_cone: f32,
    },
}

/// A pinhole camera: looks down its local -Z, +Y up, +X right.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub world: DMat4,
    /// Full vertical field of view, radians.
    pub yfov: f32,
    /// A thin lens (depth of field); None: a pinhole.
    pub lens: Option<ThinLens>,
}

/// A thin lens (the oracle's convention, Mitsuba's `thinlens`): rays start uniformly over the
/// disk of `aperture_radius` in the camera's local XY plane and meet on the plane at
/// `focus_distance` along its -Z. Both in meters, > 0. The reference tracer follows it; the
/// real-time frame's raster G-buffer stays a pinhole (its primary rays would have to be traced).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    pub aperture_radius: f32,
    pub focus_distance: f32,
}

impl ThinLens {
    /// A lens from its two numbers, or an error naming the one out of range.
    pub fn new(aperture_radius: f64, focus_distance: f64) -> anyhow::Result<ThinLens> {
        let ok = |v: f64| v.is_finite() && v > 0.0 && v < 1e9;
        if !ok(aperture_radius) {
            anyhow::bail!(
                "the aperture radius must be a finite number of meters > 0, got {aperture_radius}"
            );
        }
        if !ok(focus_distance) {
            anyhow::bail!(
                "the focus distance must be a finite number of meters > 0, got {focus_distance}"
            );
        }
        Ok(ThinLens {
            aperture_radius: aperture_radius as f32,
            focus_distance: focus_distance as f32,
        })
    }
}

impl Camera {
    pub fn look_at(eye: DVec3, target: DVec3, yfov_degrees: f32) -> Camera {
        // The camera's +Z points away from what it looks at (glTF cameras look down -Z).
        let z = (eye - target).normalize_or(DVec3::Z);
        let x = DVec3::Y.cross(z).normalize_or(DVec3::X);
        let y = z.cross(x);
        let world = DMat4::from_cols(x.extend(0.0), y.extend(0.0), z.extend(0.0), eye.extend(1.0));
        Camera { world, yfov: yfov_degrees.to_radians(), lens: None }
    }
    pub fn eye(&self) -> DVec3 {
        self.world.w_axis.truncate()
    }
}

/// Everything the renderer needs from a file.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub name: String,
    pub meshes: Vec<Mesh>,
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub lights: Vec<Light>,
    pub camera: Option<Camera>,
    pub environment: Environment,
    /// `scenes[0].extras.resolution`.
    pub resolution: Option<(u32, u32)>,
    /// Path length as Mitsuba counts it (2 = direct light only); -1 = unbounded.
    pub max_depth: i32,
    /// Non-fatal problems met while loading (missing textures, unsupported optional extensions).
    pub warnings: Vec<String>,
    /// The environment is the procedural sky of the first directional light (the sun + sky
    /// preset or the default level): moving the sun regenerates it.
    pub procedural_sky: bool,
    /// The names of the file's animations ("animation N" where unnamed), whichever play
    /// (`LoadOptions::animation`).
    pub animations: Vec<String>,
}

/// Mitsuba's default path length, also the conventions' default.
pub const DEFAULT_MAX_DEPTH: i32 = 6;

impl Scene {
    /// Load a `.gltf`/`.glb` file or a built-in scene by name ([`BUILTIN_SCENES`], `terrain:N` or
    /// `crowd:N`).
    pub fn load(path_or_default: &str) -> Result<Scene> {
        Scene::load_with(path_or_default, &LoadOptions::default())
    }

    pub fn load_with(path_or_default: &str, opts: &LoadOptions) -> Result<Scene> {
        match builtin_scene(path_or_default) {
            Some(s) => Ok(s),
            None => load_gltf_opts(Path::new(path_or_default), opts),
        }
    }

    /// Load a file or a built-in scene as the viewer and the tools show it: under `opts`'
    /// budgets, with the sun and sky preset added where the scene has no light (the
    /// conventions' rule). Warnings stay in [`Scene::warnings`] for the caller to show.
    pub fn open(path_or_default: &str, opts: &LoadOptions) -> Result<Scene> {
        let mut scene = Scene::load_with(path_or_default, opts)?;
        scene.add_sun_and_sky_if_unlit();
        Ok(scene)
    }

    pub fn is_animated(&self) -> bool {
        self.objects.iter().any(|o| o.moves())
    }

    /// Seconds after which the animation of every object repeats (the longest loop; 0 when
    /// nothing moves).
    pub fn animation_length(&self) -> f64 {
        let mut d = 0.0f64;
        for o in &self.objects {
            d = d.max(o.animation.as_ref().map_or(0.0, |a| a.duration()));
            if let Some(f) = &o.deform {
                for j in &f.skin {
                    d = d.max(j.animation.as_ref().map_or(0.0, |a| a.duration()));
                }
                if let Some(m) = &f.morph {
                    let end = m.tracks.iter().map(|t| t.times.last().copied().unwrap_or(0.0));
                    d = d.max(end.fold(m.period, f64::max));
                }
            }
        }
        d
    }

    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| self.meshes[o.mesh].indices.len() / 3).sum()
    }

    /// World-space bounds of all geometry (f64), or None for an empty scene. Vertices at
    /// non-finite positions are left out (their triangles are dropped before rendering): one
    /// +Inf vertex would otherwise make the bounds, and the rebasing origin, infinite.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for o in &self.objects {
            for p in &o.mesh_at(&self.meshes[o.mesh], None).positions {
                let w = o.transform.transform_point3(p.as_dvec3());
                if w.is_finite() {
                    lo = lo.min(w);
                    hi = hi.max(w);
                }
            }
        }
        (lo.x <= hi.x).then_some((lo, hi))
    }

    /// The point the GPU scene is rebased around: the centre of the geometry. Rendering relative
    /// to it keeps f32 precision for scenes far from the world origin.
    pub fn origin(&self) -> DVec3 {
        self.bounds().map(|(lo, hi)| (lo + hi) * 0.5).unwrap_or(DVec3::ZERO)
    }

    /// The camera to render from: the file's, or one framing the geometry.
    pub fn camera_or_default(&self) -> Camera {
        if let Some(c) = self.camera {
            return c;
        }
        let (lo, hi) = self.bounds().unwrap_or((DVec3::splat(-1.0), DVec3::splat(1.0)));
        let c = (lo + hi) * 0.5;
        let r = ((hi - lo).length() * 0.5).max(1e-6);
        let fov = 45.0f32;
        let dist = r / (fov.to_radians() as f64 * 0.5).tan();
        Camera::look_at(c + DVec3::new(0.0, r * 0.25, dist), c, fov)
    }

    /// Whether the scene has any light source at all (punctual, emissive or environment).
    pub fn has_any_light(&self) -> bool {
        !self.lights.is_empty()
            || !matches!(self.environment, Environment::None)
            || self.objects.iter().any(|o| {
                let m = self.meshes[o.mesh].material as usize;
                self.materials.get(m).is_some_and(|m| m.is_emissive())
            })
    }

    /// The conventions' rule: a scene with no lights and no emitters gets a sun and a sky.
    pub fn add_sun_and_sky_if_unlit(&mut self) {
        if self.has_any_light() {
            return;
        }
        log::info!("scene {:?} has no light: adding the sun + sky preset", self.name);
        let (sun, sky) = sky::sun_and_sky(Vec3::new(-0.4, -0.8, -0.45).normalize());
        self.lights.push(sun);
        self.environment = Environment::Map(sky);
        self.procedural_sky = true;
    }

    /// Point the first directional light along `dir` (regenerating a procedural sky with it).
    /// Returns false when the scene has no directional light.
    pub fn set_sun_direction(&mut self, dir: Vec3) -> bool {
        let Some(Light::Directional { direction, .. }) =
            self.lights.iter_mut().find(|l| matches!(l, Light::Directional { .. }))
        else {
            return false;
        };
        *direction = dir.normalize_or(Vec3::NEG_Y);
        if self.procedural_sky {
            let (_, sky) = sky::sun_and_sky(*direction);
            self.environment = Environment::Map(sky);
        }
        true
    }

    pub fn sun_direction(&self) -> Option<Vec3> {
        self.lights.iter().find_map(|l| match l {
            Light::Directional { direction, .. } => Some(*direction),
            _ => None,
        })
    }
}
