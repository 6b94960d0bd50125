//! The CPU half of uploading a scene: flatten objects into world-space triangles rebased around
//! the scene's centre, build the BVH, pack materials, lights, emitters, the environment and
//! textures into the layouts the shaders read (`shaders/common/*.wgsl`).

mod animate;
mod assemble;
mod flatten;
mod instances;
pub mod posing;

pub use super::pack::GpuLight;
use super::pack::{EnvPack, pack_light, pack_textures};
use crate::accel::{self, Accel, BvhKind};
use crate::scene::{AlphaMode, Environment, Scene};
use anyhow::{Result, bail};
use bytemuck::{Pod, Zeroable};
use flatten::{Flat, flatten, pack_glass, pack_texture_uses, previous_vertices, rebased};
use glam::{DMat4, DVec3, Vec3, Vec4};
pub use instances::{Draw, INSTANCE_TEXELS, Instancing, NO_INSTANCE};

/// Which optional parts of the renderer a scene needs. Each one missing removes its bindings,
/// its buffers and its code from the programs (`*_none.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneFeatures {
    pub punctual_lights: bool,
    pub emitters: bool,
    pub env: EnvKind,
    pub textures: bool,
    pub normal_maps: bool,
    pub alpha_mask: bool,
    /// Some material has a specular (GGX) lobe: the glossy path, its buffers and chain exist.
    pub glossy: bool,
    /// Some object moves: the BVH is rebuilt each frame and object motion enters the motion vectors.
    pub animated: bool,
    /// Some texture is read at TEXCOORD_1 or through a KHR_texture_transform: the per-material
    /// coordinate table (`tex_uses`) exists.
    pub texture_uses: bool,
    /// Some mesh carries TEXCOORD_1 or COLOR_0: three more texels a triangle (`extras`).
    pub vertex_extras: bool,
    /// Some material transmits light (KHR_materials_transmission): the per-material glass table
    /// (`glass`) and the refraction code exist (shaders/common/transmission.wgsl).
    pub transmission: bool,
    /// Some mesh deforms over time (a skin or animated morph weights): each triangle's previous
    /// vertices (`tris_prev`) give the motion vectors (realtime/motion_vertices.wgsl).
    pub deforming: bool,
    /// Some mesh is stored once for several objects (prepare/instances.rs): the instance
    /// transforms, the top-level tree and the instanced draws exist.
    pub instances: bool,
}

/// How points move between frames, and so which motion module a program that reprojects is
/// composed with (shaders/realtime/motion_*.wgsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// Nothing moves.
    Static,
    /// Objects move rigidly: a point moves with its object's transform.
    Objects,
    /// Some mesh deforms: a point moves with its triangle's vertices.
    Vertices,
}

impl Motion {
    pub fn module(self) -> &'static str {
        match self {
            Motion::Static => "realtime/motion_static.wgsl",
            Motion::Objects => "realtime/motion_objects.wgsl",
            Motion::Vertices => "realtime/motion_vertices.wgsl",
        }
    }
}

impl SceneFeatures {
    /// Per-vertex previous positions where a mesh deforms, per-object motion where objects
    /// move, none otherwise.
    pub fn motion(&self) -> Motion {
        if self.deforming {
            Motion::Vertices
        } else if self.animated {
            Motion::Objects
        } else {
            Motion::Static
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvKind {
    None,
    Constant,
    Map,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    pub base_color: [f32; 4],
    pub emission: [f32; 3],
    pub metallic: f32,
    pub specular_color: [f32; 3],
    pub roughness: f32,
    pub specular_factor: f32,
    pub alpha_cutoff: f32,
    pub normal_scale: f32,
    pub flags: u32,
    pub tex: [i32; 4],
}

impl From<&crate::scene::Material> for GpuMaterial {
    fn from(m: &crate::scene::Material) -> GpuMaterial {
        let t = |r: Option<crate::scene::TextureRef>| r.map(|r| r.index as i32).unwrap_or(-1);
        let (mask, cutoff) = match m.alpha_mode {
            AlphaMode::Opaque => (0, 0.0),
            AlphaMode::Mask(c) => (MAT_ALPHA_MASK, c),
            AlphaMode::Blend => (MAT_ALPHA_BLEND, 0.0),
        };
        GpuMaterial {
            base_color: m.base_color.to_array(),
            emission: m.emission.to_array(),
            metallic: m.metallic,
            // The shaders' dielectric F0 is 0.04 x the specular colour (the F0 of ior 1.5);
            // another ior scales the colour by its F0 over that (KHR_materials_ior, with the
            // specular extension's min(F0 x colour, 1) applied in make_bsdf as before).
            specular_color: (m.specular_color * dielectric_f0(m.ior) / 0.04).to_array(),
            roughness: m.roughness,
            specular_factor: m.specular_factor,
            alpha_cutoff: cutoff,
            normal_scale: m.normal_scale,
            // An interface between two media has two sides, whatever doubleSided says.
            flags: mask | if m.double_sided || m.transmission > 0.0 { MAT_DOUBLE_SIDED } else { 0 },
            tex: [
                t(m.base_color_texture),
                t(m.metallic_roughness_texture),
                t(m.normal_texture),
                t(m.emissive_texture),
            ],
        }
    }
}

/// Normal-incidence reflectance of a dielectric of index `ior` in air.
pub fn dielectric_f0(ior: f32) -> f32 {
    ((ior - 1.0) / (ior + 1.0)).powi(2)
}

pub const MAT_DOUBLE_SIDED: u32 = 1;
/// Bits 8 and up of [`GpuMaterial::flags`]: the material's index (shaders/common/texcoords.wgsl
/// reads its row of [`PreparedScene::tex_uses`] by it).
pub const MAT_INDEX_SHIFT: u32 = 8;
/// As many materials as those bits count.
pub const MAX_MATERIALS: usize = 1 << (32 - MAT_INDEX_SHIFT);
pub const MAT_ALPHA_MASK: u32 = 2;
pub const MAT_ALPHA_BLEND: u32 = 4;

/// Everything ready for upload, with no GPU involved (so limits can be computed before a device
/// is requested, and so tests can inspect it).
pub struct PreparedScene {
    pub features: SceneFeatures,
    pub accel: Accel,
    /// Entries of the traversal stack this scene's programs are built with
    /// ([`accel::traversal_stack`]); fixed at load, and every rebuild of an animated scene's
    /// tree stays within it.
    pub traversal_stack: u32,
    /// World position the GPU scene is relative to.
    pub origin: DVec3,
    /// Length of the bounds' diagonal (scene units).
    pub extent: f64,
    pub tris: Vec<Vec4>,
    /// Animated scenes: the vertices of `tris` where they are at the shutter's open
    /// ([`PreparedScene::expose`]; `tris` are at its close), the same as `tris` while the
    /// shutter is closed (no motion blur).
    pub tris_open: Vec<Vec4>,
    /// [`SceneFeatures::deforming`]: the vertices of `tris` at the previous `animate` call, w 0;
    /// an instanced mesh's prototype slots hold w 1 (their points move with their instances).
    pub tris_prev: Vec<Vec4>,
    pub shading: Vec<Vec4>,
    pub tangents: Vec<Vec4>,
    /// [`SceneFeatures::vertex_extras`]: TEXCOORD_1 and COLOR_0, three texels (12 words) a
    /// triangle in BVH order ([`pack_extras`]).
    pub extras: Vec<[u32; 4]>,
    pub materials: Vec<GpuMaterial>,
    /// [`SceneFeatures::texture_uses`]: per material and texture slot (base colour,
    /// metallic-roughness, normal, emissive), two rows of the coordinates' affine map, the
    /// first's w the TEXCOORD set ([`pack_texture_uses`]).
    pub tex_uses: Vec<Vec4>,
    /// [`SceneFeatures::transmission`]: per material two rows, (transmission, ior, 1 if
    /// thin-walled, 0) and (absorption per metre rgb, 0) ([`pack_glass`]).
    pub glass: Vec<Vec4>,
    pub lights: Vec<GpuLight>,
    /// The light tree over the emissive triangles ([`crate::accel::light_tree`]), as
    /// shaders/common/emitters.wgsl reads it.
    pub emitters: Vec<crate::accel::light_tree::LightNode>,
    /// The emissive triangles' slots, the fixed part's first.
    pub emitter_slots: Vec<u32>,
    pub env_data: Vec<f32>,
    pub env_radiance: Vec3,
    /// width, height, marginal offset, conditional offset.
    pub env_size: [u32; 4],
    pub env_rotation_y_degrees: f32,
    /// W H / (sum(luminance x sin theta) 2 pi^2).
    pub env_pdf_norm: f32,
    pub tex_data: Vec<u32>,
    /// Input triangles dropped: non-finite vertices or zero area.
    pub dropped_triangles: usize,
    /// Per object: its world transform at `time`, and the rebased transform taking a point on
    /// it now to where it was at the previous `animate` call.
    world: Vec<DMat4>,
    pub prev_from_current: Vec<glam::Mat4>,
    flat: Vec<Flat>,
    pub time: f64,
    /// The time deforming objects (skins, morph targets) are posed at; None: their rest pose.
    pose_time: Option<f64>,
    /// Per object, the rebased transform from where a point is at the shutter's close (`time`)
    /// to where it is at its open; empty while no object moves during the shutter.
    open_from_close: Vec<glam::Mat4>,
    /// Per object, whether it moves or deforms (its triangles are in the rebuilt part).
    moving: Vec<bool>,
    /// An animated scene's part that is built once ([`assemble::StaticPart`]).
    split: Option<assemble::StaticPart>,
    /// The moving part's last tree, kept for refitting.
    moving_tree: Option<accel::RefitTree>,
    /// Whether the moving part's tree is refit while that stays within
    /// [`accel::REFIT_LIMIT`] of its built cost (true), or rebuilt whenever anything moves.
    pub refit: bool,
    /// Per object, the prototype it instances ([`SceneFeatures::instances`]); None where it is
    /// flattened in world space. Prototype p's triangles are `flat[objects + p]`.
    proto_of: Vec<Option<usize>>,
    protos: Vec<instances::Proto>,
    /// Per object [`INSTANCE_TEXELS`] texels (shaders/common/instances.wgsl), where the scene
    /// has instances.
    pub instances: Vec<Vec4>,
    /// The top-level tree over the instances' boxes (binary nodes), its leaves' objects and
    /// its depth; the entries of its traversal stack (fixed at load, as `traversal_stack`).
    pub tlas: Vec<u8>,
    pub tlas_order: Vec<u32>,
    tlas_depth: usize,
    tlas_tree: Option<accel::RefitTree>,
    pub tlas_stack: u32,
    /// The raster's instanced draws: the objects each prototype's draw names, and the draws.
    pub draw_list: Vec<u32>,
    pub draws: Vec<Draw>,
    /// Wall time of the last top-level tree build and instance packing.
    pub tlas_build_time: std::time::Duration,
    /// Whether the last `expose` changed world-space triangles (false where only instances
    /// moved: their triangles stay as they are on the GPU).
    pub geometry_moved: bool,
    /// The moving part is posed on the GPU (`gpu/posing.rs`) where
    /// [`PreparedScene::posing_supported`]: `expose` then leaves its triangles and tree to the
    /// GPU and asks for a pose in `pose_request`, except where `rebuild_posing` asks for one
    /// CPU flattening and rebuild.
    pub gpu_posing: bool,
    /// The (close, open) times the GPU poses the moving part at this frame.
    pub pose_request: Option<(f64, Option<f64>)>,
    /// The next `expose` flattens and rebuilds the moving part on the CPU (its refit on the
    /// GPU has degraded, or an object's transform started mirroring); cleared by that rebuild.
    pub rebuild_posing: bool,
    /// Bumped by every CPU flattening of the moving part (its slots and tree change).
    pub posing_epoch: u64,
    /// The GPU posed the moving part at the last `expose`.
    posed_last: bool,
    /// The GPU has posed the moving part since its last CPU flattening: `flat` is stale.
    flat_stale: bool,
}

pub use crate::limits::MAX_TRIANGLES;

impl PreparedScene {
    /// Whether a material some object uses has a specular (GGX) lobe: the glossy path, its
    /// buffers and chain exist. Importers append an unused default material, which does not count.
    pub fn glossy_materials(scene: &Scene) -> bool {
        let used: std::collections::HashSet<usize> =
            scene.objects.iter().map(|o| scene.meshes[o.mesh].material as usize).collect();
        scene.materials.iter().enumerate().filter(|(i, _)| used.contains(i)).any(|(_, m)| {
            let g = GpuMaterial::from(m);
            g.metallic > 0.0
                || m.transmission > 0.0
                || (g.specular_factor > 0.0 && g.specular_color.iter().any(|c| *c > 0.0))
        })
    }

    pub fn new(scene: &Scene, kind: BvhKind) -> Result<PreparedScene> {
        Self::with_instancing(scene, kind, Instancing::Auto)
    }

    /// [`PreparedScene::new`], storing shared meshes once as `instancing` says.
    pub fn with_instancing(
        scene: &Scene,
        kind: BvhKind,
        instancing: Instancing,
    ) -> Result<PreparedScene> {
        let origin = scene.origin();
        let extent =
            scene.bounds().map(|(lo, hi)| (hi - lo).length()).filter(|e| *e > 0.0).unwrap_or(1.0);
        let normal_maps = scene.materials.iter().any(|m| m.normal_texture.is_some());
        let texture_uses = scene
            .materials
            .iter()
            .any(|m| m.texture_refs().into_iter().flatten().any(|t| !t.is_plain()));
        let vertex_extras = scene.objects.iter().any(|o| {
            let m = &scene.meshes[o.mesh];
            !m.uvs1.is_empty() || !m.colors.is_empty()
        });
        let lights: Vec<GpuLight> = scene.lights.iter().map(|l| pack_light(l, origin)).collect();
        let mut features = SceneFeatures {
            punctual_lights: !lights.is_empty(),
            emitters: false,
            env: EnvKind::None,
            textures: !scene.textures.is_empty(),
            normal_maps,
            alpha_mask: scene.materials.iter().any(|m| m.alpha_mode != AlphaMode::Opaque),
            glossy: Self::glossy_materials(scene),
            animated: scene.is_animated(),
            texture_uses,
            vertex_extras,
            transmission: scene.materials.iter().any(|m| m.transmission > 0.0),
            deforming: scene.objects.iter().any(|o| o.deform.as_ref().is_some_and(|d| d.moves())),
            instances: false,
        };
        let (protos, proto_of) = instances::prototypes(scene, instancing);
        features.instances = !protos.is_empty();
        // Refused before flattening what would not fit: the objects flattened in world space
        // and each prototype once.
        let tris = |i: usize| scene.meshes[scene.objects[i].mesh].indices.len() / 3;
        let stored: usize =
            (0..scene.objects.len()).filter(|&i| proto_of[i].is_none()).map(tris).sum::<usize>()
                + protos.iter().map(|&i| tris(i)).sum::<usize>();
        if stored >= MAX_TRIANGLES {
            bail!("{stored} triangles: Hush handles at most {} per scene", MAX_TRIANGLES - 1);
        }
        let mut flat: Vec<Flat> = (0..scene.objects.len())
            .map(|i| match proto_of[i] {
                Some(_) => Flat::default(),
                None => flatten(scene, i, scene.objects[i].transform, origin, &features, None),
            })
            .collect();
        // A prototype in its mesh's own space (the first object that draws it names it).
        flat.extend(
            protos
                .iter()
                .map(|&i| flatten(scene, i, DMat4::IDENTITY, DVec3::ZERO, &features, None)),
        );
        let dropped: usize = flat.iter().map(|f| f.dropped).sum();
        if dropped > 0 {
            log::warn!("dropped {dropped} triangles with non-finite vertices or zero area");
        }
        let count: usize = flat.iter().map(|f| f.tris.len()).sum();
        if count >= MAX_TRIANGLES {
            bail!("{} triangles: Hush handles at most {} per scene", count, MAX_TRIANGLES - 1);
        }
        let world: Vec<DMat4> = scene.objects.iter().map(|o| o.transform).collect();
        if scene.materials.len() > MAX_MATERIALS {
            bail!(
                "{} materials: Hush handles at most {MAX_MATERIALS} per scene",
                scene.materials.len()
            );
        }
        let materials: Vec<GpuMaterial> = scene
            .materials
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let mut g = GpuMaterial::from(m);
                g.flags |= (i as u32) << MAT_INDEX_SHIFT;
                g
            })
            .collect();

        let mut env = EnvPack::default();
        let env_kind = match &scene.environment {
            Environment::None => EnvKind::None,
            Environment::Constant(c) if c.max_element() > 0.0 => {
                env.radiance = *c;
                EnvKind::Constant
            }
            Environment::Constant(_) => EnvKind::None,
            Environment::Map(map) => {
                if env.pack_map(map) {
                    EnvKind::Map
                } else {
                    EnvKind::None
                }
            }
        };
        let tex_data = pack_textures(scene);
        features.env = env_kind;
        let tex_uses = if texture_uses { pack_texture_uses(&scene.materials) } else { vec![] };
        let glass = if features.transmission { pack_glass(&scene.materials) } else { vec![] };
        let mut p = PreparedScene {
            features,
            accel: Accel::empty(kind),
            traversal_stack: kind.max_depth() as u32,
            origin,
            extent,
            tris: vec![],
            tris_open: vec![],
            tris_prev: vec![],
            shading: vec![],
            tangents: vec![],
            extras: vec![],
            materials,
            tex_uses,
            glass,
            lights,
            emitters: vec![],
            emitter_slots: vec![],
            env_data: env.data,
            env_radiance: env.radiance,
            env_size: env.size,
            env_rotation_y_degrees: env.rotation,
            env_pdf_norm: env.pdf_norm,
            tex_data,
            dropped_triangles: dropped,
            prev_from_current: vec![glam::Mat4::IDENTITY; world.len()],
            world,
            flat,
            time: 0.0,
            pose_time: None,
            open_from_close: vec![],
            moving: scene
                .objects
                .iter()
                .zip(&proto_of)
                .map(|(o, p)| o.moves() && p.is_none())
                .collect(),
            split: None,
            moving_tree: None,
            refit: true,
            protos: vec![
                instances::Proto {
                    root: 0,
                    slot_base: 0,
                    slots: 0,
                    bounds: obvhs::aabb::Aabb::empty()
                };
                protos.len()
            ],
            proto_of,
            instances: vec![],
            tlas: vec![],
            tlas_order: vec![],
            tlas_depth: 0,
            tlas_tree: None,
            tlas_stack: BvhKind::Bvh2.max_depth() as u32,
            draw_list: vec![],
            draws: vec![],
            geometry_moved: true,
            tlas_build_time: std::time::Duration::ZERO,
            gpu_posing: false,
            pose_request: None,
            rebuild_posing: false,
            posing_epoch: 0,
            posed_last: false,
            flat_stale: false,
        };
        p.assemble();
        p.place_instances();
        let placed = p.tlas_order.len();
        p.tlas_stack =
            accel::traversal_stack(BvhKind::Bvh2, p.tlas_depth, placed, p.features.animated);
        p.traversal_stack = match &p.split {
            // Rebuilt only where a world-space object moves (instances move the top level).
            None => {
                let rebuilt = p.moving.iter().any(|&m| m);
                accel::traversal_stack(kind, p.accel.depth, count, rebuilt)
            }
            Some(sp) => {
                let moving: usize = (0..p.world.len())
                    .filter(|&i| p.moving[i])
                    .map(|i| p.flat[i].tris.len() + p.flat[i].dropped)
                    .sum();
                accel::split_traversal_stack(kind, sp.depth, p.accel.depth, moving)
            }
        };
        p.features.emitters = !p.emitters.is_empty();
        Ok(p)
    }
}

impl PreparedScene {
    /// Repack lights and a procedural environment after the scene's lighting changed (same
    /// number of lights and the same environment kind and size; geometry untouched).
    pub fn repack_lighting(&mut self, scene: &Scene) {
        self.lights = scene.lights.iter().map(|l| pack_light(l, self.origin)).collect();
        if let Environment::Map(map) = &scene.environment {
            let mut env = EnvPack::default();
            if env.pack_map(map) && env.data.len() == self.env_data.len() {
                self.env_data = env.data;
                self.env_pdf_norm = env.pdf_norm;
            }
        }
    }

    /// Whether some object moves while the shutter is open ([`PreparedScene::expose`]).
    pub fn shutter_moves(&self) -> bool {
        !self.open_from_close.is_empty()
    }

    pub fn triangle_count(&self) -> usize {
        self.tris.len() / 3
    }

    /// The ray-offset epsilon of `offset_ray` in `shaders/common/math.wgsl`: 2^-17 of the extent.
    pub fn ray_epsilon(&self) -> f32 {
        (self.extent * 2f64.powi(-17)) as f32
    }
}
