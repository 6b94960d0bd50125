//! The CPU half of uploading a scene: flatten objects into world-space triangles rebased around
//! the scene's centre, build the BVH, pack materials, lights, emitters, the environment and
//! textures into the layouts the shaders read (`shaders/common/*.wgsl`).

mod assemble;
mod instances;
pub mod posing;

pub use super::pack::GpuLight;
use super::pack::{EnvPack, pack_light, pack_textures};
use crate::accel::{self, Accel, BvhKind};
use crate::scene::{AlphaMode, Environment, Scene};
use anyhow::{Result, bail};
use bytemuck::{Pod, Zeroable};
use glam::{DMat3, DMat4, DVec3, Vec3, Vec4};
pub use instances::{Draw, INSTANCE_TEXELS, Instancing, NO_INSTANCE};
use obvhs::triangle::Triangle;

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
    /// (cumulative probability bits, triangle slot).
    pub emitters: Vec<[u32; 2]>,
    /// 1 / sum(area x luminance(emission)).
    pub emit_inv_total: f32,
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

/// One object's triangles in rebased world space, before the BVH orders them.
#[derive(Clone, Default)]
struct Flat {
    tris: Vec<Triangle>,
    /// Per triangle, its index among the mesh's triangles (degenerate ones are dropped).
    src: Vec<u32>,
    /// Per triangle, its vertices at the previous `animate` call; empty: where they are now.
    prev: Vec<[Vec3; 3]>,
    /// A deforming mesh's triangles at the shutter's open (`expose`); empty: carried there by
    /// the object's transform.
    open: Vec<[Vec3; 3]>,
    attrs: Vec<[Vec4; 4]>,
    tans: Vec<[Vec4; 3]>,
    extras: Vec<[[u32; 4]; 3]>,
    mats: Vec<u32>,
    dropped: usize,
}

/// `time`: the time a deforming object's mesh is posed at (None: its rest pose).
fn flatten(
    scene: &Scene,
    object: usize,
    transform: DMat4,
    origin: DVec3,
    features: &SceneFeatures,
    time: Option<f64>,
) -> Flat {
    let o = &scene.objects[object];
    let mesh = &scene.meshes[o.mesh];
    // A deforming mesh's posed vertices; the rest of it as it is stored.
    let posed = o.deform.as_ref().map(|d| d.pose_vertices(mesh, time));
    let (positions, normals, tangents) = match &posed {
        Some(p) => (&p.positions, &p.normals, &p.tangents),
        None => (&mesh.positions, &mesh.normals, &mesh.tangents),
    };
    let m3 = DMat3::from_mat4(transform);
    let flip = m3.determinant() < 0.0;
    let nmat = m3.inverse().transpose();
    let mat = if (mesh.material as usize) < scene.materials.len() { mesh.material } else { 0 };
    let n = mesh.indices.len() / 3;
    let mut f = Flat {
        tris: Vec::with_capacity(n),
        src: Vec::with_capacity(n),
        attrs: Vec::with_capacity(n),
        mats: Vec::with_capacity(n),
        ..Flat::default()
    };
    for (k, t) in mesh.indices.chunks_exact(3).enumerate() {
        // A mirroring transform reverses the winding; swap to keep the front face CCW.
        let idx = if flip { [t[0], t[2], t[1]] } else { [t[0], t[1], t[2]] };
        let p64 =
            idx.map(|i| transform.transform_point3(positions[i as usize].as_dvec3()) - origin);
        let p = p64.map(|v| v.as_vec3());
        // Degenerate: zero area, or so thin (area below 1e-12 of the longest edge squared)
        // that f32 arithmetic cannot resolve it; such a triangle cannot be hit reliably.
        let area2 = (p64[1] - p64[0]).cross(p64[2] - p64[0]).length();
        let edge2 = (p64[1] - p64[0])
            .length_squared()
            .max((p64[2] - p64[1]).length_squared())
            .max((p64[0] - p64[2]).length_squared());
        let area2_f32 = (p[1] - p[0]).cross(p[2] - p[0]).length();
        if !p.iter().all(|v| v.is_finite())
            || !(area2 > 1e-12 * edge2)
            || !(area2_f32 > 0.0)
            || !area2_f32.is_finite()
        {
            f.dropped += 1;
            continue;
        }
        f.tris.push(Triangle { v0: p[0].into(), v1: p[1].into(), v2: p[2].into() });
        f.src.push(k as u32);
        let n = idx.map(|i| {
            let n = normals.get(i as usize).copied().unwrap_or(Vec3::ZERO);
            let n = (nmat * n.as_dvec3()).normalize_or_zero().as_vec3();
            if n.is_finite() { n } else { Vec3::ZERO }
        });
        let uv = idx.map(|i| {
            let uv = mesh.uvs.get(i as usize).copied().unwrap_or_default();
            if uv.is_finite() { uv } else { glam::Vec2::ZERO }
        });
        // The fourth vec4's w carries the object index (as bits) for motion vectors.
        f.attrs.push([
            n[0].extend(uv[0].x),
            n[1].extend(uv[1].x),
            n[2].extend(uv[2].x),
            Vec4::new(uv[0].y, uv[1].y, uv[2].y, f32::from_bits(object as u32)),
        ]);
        if features.vertex_extras {
            f.extras.push(pack_extras(mesh, idx));
        }
        if features.normal_maps {
            f.tans.push(idx.map(|i| {
                let t = tangents.get(i as usize).copied().unwrap_or(Vec4::new(1.0, 0.0, 0.0, 1.0));
                let xyz = (m3 * t.truncate().as_dvec3()).normalize_or_zero().as_vec3();
                let w = if flip { -t.w } else { t.w };
                if xyz.is_finite() { xyz.extend(w) } else { Vec4::new(1.0, 0.0, 0.0, 1.0) }
            }));
        }
        f.mats.push(mat);
    }
    f
}

/// A triangle's TEXCOORD_1 and COLOR_0 (shaders/common/attributes.wgsl): the three vertices'
/// TEXCOORD_1 as f32 bits, then their colours as two unorm16x2 words each (RG, BA). A mesh
/// without TEXCOORD_1 stores its TEXCOORD_0 there, one without COLOR_0 white.
fn pack_extras(mesh: &crate::scene::Mesh, idx: [u32; 3]) -> [[u32; 4]; 3] {
    let uv = idx.map(|i| {
        let i = i as usize;
        let uv = mesh.uvs1.get(i).or(mesh.uvs.get(i)).copied().unwrap_or_default();
        if uv.is_finite() { uv } else { glam::Vec2::ZERO }
    });
    let unorm16 = |x: f32| (x.clamp(0.0, 1.0) * 65535.0).round() as u32;
    let c = idx.map(|i| {
        let c = mesh.colors.get(i as usize).copied().unwrap_or(Vec4::ONE);
        [unorm16(c.x) | unorm16(c.y) << 16, unorm16(c.z) | unorm16(c.w) << 16]
    });
    let b = |x: f32| x.to_bits();
    [
        [b(uv[0].x), b(uv[0].y), b(uv[1].x), b(uv[1].y)],
        [b(uv[2].x), b(uv[2].y), c[0][0], c[0][1]],
        [c[1][0], c[1][1], c[2][0], c[2][1]],
    ]
}

/// Per material and texture slot, the rows of the map from the mesh's coordinates to the
/// texture's (shaders/common/texcoords.wgsl), the first row's w the TEXCOORD set.
fn pack_texture_uses(materials: &[crate::scene::Material]) -> Vec<Vec4> {
    let mut v = Vec::with_capacity(materials.len() * 8);
    for m in materials {
        for t in m.texture_refs() {
            let t = t.unwrap_or(crate::scene::TextureRef::new(0));
            let (a, o) = (t.transform.matrix2, t.transform.translation);
            v.push(Vec4::new(a.x_axis.x, a.y_axis.x, o.x, t.set as f32));
            v.push(Vec4::new(a.x_axis.y, a.y_axis.y, o.y, 0.0));
        }
    }
    v
}

/// Per material the two rows of shaders/common/transmission.wgsl's glass table.
fn pack_glass(materials: &[crate::scene::Material]) -> Vec<Vec4> {
    let mut v = Vec::with_capacity(materials.len() * 2);
    for m in materials {
        let thin = if m.thickness > 0.0 { 0.0 } else { 1.0 };
        v.push(Vec4::new(m.transmission, m.ior, thin, 0.0));
        let sigma = if m.transmission > 0.0 { m.absorption() } else { Vec3::ZERO };
        v.push(sigma.extend(0.0));
    }
    v
}

/// Each triangle of `now` where it was in `before` (the same object's previous flattening): the
/// same mesh triangle's vertices, or its current ones where `before` had dropped it.
fn previous_vertices(before: &Flat, now: &Flat) -> Vec<[Vec3; 3]> {
    // Both lists of mesh triangles ascend: one walk matches them.
    let mut j = 0;
    now.src
        .iter()
        .zip(&now.tris)
        .map(|(&k, t)| {
            while j < before.src.len() && before.src[j] < k {
                j += 1;
            }
            let t = if before.src.get(j) == Some(&k) { &before.tris[j] } else { t };
            [t.v0, t.v1, t.v2].map(Vec3::from)
        })
        .collect()
}

/// f32 matrix of a rebased world transform.
fn rebased(m: DMat4, origin: DVec3) -> glam::Mat4 {
    (DMat4::from_translation(-origin) * m).as_mat4()
}

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
            emit_inv_total: 0.0,
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

    /// Move animated objects to `time` seconds (an instant exposure): re-flatten them, rebuild
    /// the BVH and the per-object motion (`prev_from_current`) that the G-buffer's motion vectors
    /// read. Returns false (and changes nothing) for a static scene.
    pub fn animate(&mut self, scene: &Scene, time: f64) -> bool {
        self.expose(scene, time, None)
    }

    /// [`animate`] to `time`, the shutter's close, with the shutter open since scene time
    /// `open` (None: an instant). Objects whose transform differs between the two move linearly
    /// between them during the exposure (shaders/common/motion_blur.wgsl): the BVH is built over
    /// each triangle's box at both ends and `tris_open` holds the open ends. One rebuild, where
    /// anything changed; returns whether it did.
    ///
    /// [`animate`]: PreparedScene::animate
    pub fn expose(&mut self, scene: &Scene, time: f64, open: Option<f64>) -> bool {
        let on_gpu = self.gpu_posing && !self.rebuild_posing && self.posing_supported();
        let (moved, instances_moved, posed) = self.move_objects(scene, time, on_gpu);
        let swept = self.open_shutter(scene, open, on_gpu);
        // Instances move by their transforms alone: the world-space triangles are rebuilt only
        // where one of them moved or swept.
        let world = moved || (swept && !on_gpu && self.moving.iter().any(|&m| m));
        if world {
            self.assemble();
            if self.split.is_some() {
                self.posing_epoch += 1;
            }
            self.rebuild_posing = false;
        }
        if instances_moved || swept {
            self.place_instances();
        }
        self.geometry_moved = world;
        // The GPU poses again while anything moves, and once more after it stops, so that
        // the previous vertices catch up with the current ones.
        let pose = on_gpu && (posed || self.posed_last || swept);
        self.pose_request = pose.then_some((time, open.filter(|_| self.shutter_moves())));
        self.posed_last = on_gpu && (posed || swept);
        moved || instances_moved || swept || posed
    }

    /// Move every object to `time`: whether world-space triangles moved, whether instances
    /// did, and whether the moving part moved on the GPU (`on_gpu`: it is posed there and
    /// only its transforms are kept here).
    fn move_objects(&mut self, scene: &Scene, time: f64, on_gpu: bool) -> (bool, bool, bool) {
        let mut moved = false;
        let mut instances_moved = false;
        let mut posed = false;
        // The CPU flattening after GPU poses: the last one it made is stale.
        let stale = self.flat_stale && !on_gpu;
        let repose = self.pose_time != Some(time);
        for (i, o) in scene.objects.iter().enumerate().take(self.world.len()) {
            let now = o.transform_at(time);
            let before = self.world[i];
            self.prev_from_current[i] = if o.animation.is_some() {
                rebased(before, self.origin) * rebased(now, self.origin).inverse()
            } else {
                glam::Mat4::IDENTITY
            };
            let deforms = repose && o.deform.as_ref().is_some_and(|d| d.moves());
            if self.proto_of[i].is_some() {
                if now != before {
                    self.world[i] = now;
                    instances_moved = true;
                }
            } else if on_gpu && self.moving[i] {
                posed |= (o.animation.is_some() && now != before) || deforms;
                self.world[i] = now;
            } else if (o.animation.is_some() && now != before)
                || deforms
                || (stale && self.moving[i])
            {
                let mut f = flatten(scene, i, now, self.origin, &self.features, Some(time));
                if stale {
                    let t = self.pose_time.unwrap_or(time);
                    self.flat[i] = flatten(scene, i, before, self.origin, &self.features, Some(t));
                }
                if self.features.deforming {
                    f.prev = previous_vertices(&self.flat[i], &f);
                }
                self.flat[i] = f;
                self.world[i] = now;
                moved = true;
            } else if !self.flat[i].prev.is_empty() {
                // Still since the last call: no motion left to show.
                self.flat[i].prev.clear();
                moved = true;
            }
        }
        self.time = time;
        self.pose_time = Some(time);
        self.flat_stale = if on_gpu { self.flat_stale || posed } else { false };
        (moved, instances_moved, posed)
    }

    /// The per-object transforms from the close to `open` (empty while nothing moves during the
    /// shutter); whether they changed.
    fn open_shutter(&mut self, scene: &Scene, open: Option<f64>, on_gpu: bool) -> bool {
        let mut open_from_close = vec![];
        let mut deformed = false;
        // Deforming meshes posed on the GPU sweep there: every frame while the shutter is
        // open on them.
        let mut swept_on_gpu = false;
        if let Some(t) = open.filter(|_| self.features.animated) {
            let deforms = |o: &crate::scene::Object| o.deform.as_ref().is_some_and(|d| d.moves());
            let moving = scene.objects.iter().enumerate().take(self.world.len()).any(|(i, o)| {
                (o.animation.is_some() && o.transform_at(t) != self.world[i])
                    || (deforms(o) && t != self.time)
            });
            if moving {
                swept_on_gpu = on_gpu;
                open_from_close = scene
                    .objects
                    .iter()
                    .enumerate()
                    .take(self.world.len())
                    .map(|(i, o)| {
                        rebased(o.transform_at(t), self.origin)
                            * rebased(self.world[i], self.origin).inverse()
                    })
                    .collect();
                // A deforming mesh's vertices at the open, triangle by triangle: no transform
                // takes its close to its open.
                for (i, o) in scene.objects.iter().enumerate().take(self.world.len()) {
                    if deforms(o) && !on_gpu {
                        let at_open = flatten(
                            scene,
                            i,
                            o.transform_at(t),
                            self.origin,
                            &self.features,
                            Some(t),
                        );
                        self.flat[i].open = previous_vertices(&at_open, &self.flat[i]);
                        deformed = true;
                    }
                }
            }
        }
        if !deformed {
            for f in &mut self.flat {
                f.open.clear();
            }
        }
        let changed = deformed || swept_on_gpu || open_from_close != self.open_from_close;
        self.open_from_close = open_from_close;
        changed
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
