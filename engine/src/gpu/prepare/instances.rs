//! Meshes stored once for the objects that draw them (two-level acceleration).
//!
//! Where several objects draw one mesh, its triangles are flattened once in the mesh's own space
//! with a tree of their own (a "prototype", placed after the world-space triangles' static part
//! by `assemble`), and each of those objects is an instance: a transform and a box in a
//! top-level binary tree over the instances (`tlas`), refit whenever one of them moves (rebuilt
//! past the refit limit). Rays
//! go through the world-space trees, then the top-level one, into each instance's mesh in its
//! space (shaders/common/tlas.wgsl); the raster draws each prototype instanced
//! (shaders/realtime/gbuffer.wgsl). Objects stay flattened in world space where instancing
//! does not pay ([`Instancing::Auto`]), where their mesh emits light (the emitter table samples
//! world-space triangles) and where they deform (skins and morph targets are posed into world
//! space). In a scene whose meshes deform, the prototypes' previous vertices carry w = 1, which
//! tells the per-vertex motion (shaders/realtime/motion_vertices.wgsl) to move their points by
//! their instances' transforms.

use super::{PreparedScene, rebased};
use crate::accel::{self, BvhKind};
use crate::scene::Scene;
use glam::{Mat4, Vec3A, Vec4};
use obvhs::aabb::Aabb;
use obvhs::triangle::Triangle;

/// Whether a mesh that several objects draw is stored once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Instancing {
    /// Where flattening every object would store at least twice the triangles that storing each
    /// shared mesh once does; one level otherwise. Two levels cost a ray a traversal of each
    /// instance's tree it enters: the level with every object an instance traced 0.52 M rays/s
    /// on lavapipe against 2.6 with one level; `crowd:400` 0.6 against 1.2 to 1.4 flattened, in
    /// 1.3 MiB instead of 83.5.
    #[default]
    Auto,
    /// Every object flattened in world space.
    Never,
    /// Every object that can be an instance is one, shared or not (tests compare the two
    /// levels' hits against `Never`).
    Always,
}

impl Instancing {
    pub fn parse(s: &str) -> Option<Instancing> {
        match s {
            "auto" => Some(Instancing::Auto),
            "never" => Some(Instancing::Never),
            "always" => Some(Instancing::Always),
            _ => None,
        }
    }
}

/// Texels per object in [`PreparedScene::instances`] (`INSTANCE_TEXELS` in
/// shaders/common/instances.wgsl).
pub const INSTANCE_TEXELS: usize = 10;
const INSTANCE_FLAG: u32 = 1;
const INSTANCE_MIRRORED: u32 = 2;
/// The draw list's entry for world-space triangles (`NO_INSTANCE` in the shaders).
pub const NO_INSTANCE: u32 = u32::MAX;

/// A mesh stored once: its tree's root node, its triangle slots and its box, in its own space.
#[derive(Clone, Debug)]
pub(crate) struct Proto {
    pub root: u32,
    pub slot_base: u32,
    pub slots: u32,
    pub bounds: Aabb,
}

/// One instanced draw of the raster: a prototype's vertices, and the range of the draw list
/// that names its objects.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Draw {
    pub vertices: std::ops::Range<u32>,
    pub instances: std::ops::Range<u32>,
}

/// The prototypes (each named by the first object that draws its mesh) and, per object, the
/// prototype it instances (None: flattened in world space).
pub(super) fn prototypes(scene: &Scene, mode: Instancing) -> (Vec<usize>, Vec<Option<usize>>) {
    let mut of_mesh = vec![None; scene.meshes.len()];
    let mut protos = vec![];
    let proto_of = plan(scene, mode)
        .into_iter()
        .enumerate()
        .map(|(i, mesh)| {
            mesh.map(|m| {
                *of_mesh[m].get_or_insert_with(|| {
                    protos.push(i);
                    protos.len() - 1
                })
            })
        })
        .collect();
    (protos, proto_of)
}

/// Per object, the mesh it instances (None: flattened in world space).
fn plan(scene: &Scene, mode: Instancing) -> Vec<Option<usize>> {
    let n = scene.objects.len();
    if mode == Instancing::Never {
        return vec![None; n];
    }
    let emits = |mesh: usize| {
        let m = scene.meshes[mesh].material as usize;
        scene.materials.get(m).is_some_and(|m| m.emission.max_element() > 0.0)
    };
    let eligible: Vec<bool> =
        scene.objects.iter().map(|o| o.deform.is_none() && !emits(o.mesh)).collect();
    let mut users = vec![0usize; scene.meshes.len()];
    for (o, _) in scene.objects.iter().zip(&eligible).filter(|(_, e)| **e) {
        users[o.mesh] += 1;
    }
    let tris = |mesh: usize| scene.meshes[mesh].indices.len() / 3;
    let shared = |i: usize| eligible[i] && users[scene.objects[i].mesh] >= 2;
    if mode == Instancing::Auto {
        let flat: usize = scene.objects.iter().map(|o| tris(o.mesh)).sum();
        let once: usize =
            (0..n).filter(|&i| !shared(i)).map(|i| tris(scene.objects[i].mesh)).sum::<usize>()
                + (0..scene.meshes.len()).filter(|&m| users[m] >= 2).map(tris).sum::<usize>();
        if flat < 2 * once {
            return vec![None; n];
        }
    }
    (0..n)
        .map(|i| {
            let on = if mode == Instancing::Always { eligible[i] } else { shared(i) };
            on.then_some(scene.objects[i].mesh)
        })
        .collect()
}

/// A box's corners carried by `m`, as a box.
fn carried(m: Mat4, b: &Aabb) -> Aabb {
    let mut out = Aabb::empty();
    for k in 0..8 {
        let c = Vec3A::select(glam::BVec3A::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), b.max, b.min);
        out.extend(m.transform_point3a(c));
    }
    out
}

/// The three rows of an affine matrix, as the shaders read them.
fn rows(m: Mat4) -> [Vec4; 3] {
    let t = m.transpose();
    [t.x_axis, t.y_axis, t.z_axis]
}

impl PreparedScene {
    /// Every instance's transforms (at the shutter's close and open) and the top-level tree
    /// over their boxes; the raster's draw list. An object whose transform is not invertible
    /// in f32 (a zero scale, a non-finite entry) is left out: it draws nothing, and nothing
    /// non-finite reaches the GPU.
    pub(super) fn place_instances(&mut self) {
        if !self.features.instances {
            return;
        }
        let start = std::time::Instant::now();
        let n = self.world.len();
        self.instances.clear();
        self.instances.resize(n * INSTANCE_TEXELS, Vec4::ZERO);
        let mut boxes = Vec::new();
        let mut placed: Vec<Vec<u32>> = vec![Vec::new(); self.protos.len()];
        let mut objects = Vec::new();
        for i in 0..n {
            let Some(p) = self.proto_of[i] else { continue };
            let proto = &self.protos[p];
            if proto.slots == 0 {
                continue;
            }
            let close = rebased(self.world[i], self.origin);
            let open = self.open_from_close.get(i).map_or(close, |m| *m * close);
            let inv = close.inverse();
            let det = close.determinant();
            if !(close.is_finite() && open.is_finite() && inv.is_finite() && det != 0.0) {
                continue;
            }
            let at = i * INSTANCE_TEXELS;
            self.instances[at..at + 3].copy_from_slice(&rows(close));
            self.instances[at + 3..at + 6].copy_from_slice(&rows(inv));
            self.instances[at + 6..at + 9].copy_from_slice(&rows(open));
            let flags = INSTANCE_FLAG | if det < 0.0 { INSTANCE_MIRRORED } else { 0 };
            self.instances[at + 9] =
                Vec4::new(f32::from_bits(flags), f32::from_bits(proto.root), 0.0, 0.0);
            let b = carried(close, &proto.bounds).union(&carried(open, &proto.bounds));
            // A box as the degenerate triangle from its min to its max (as assemble's swept
            // boxes are): the tree bounds it exactly.
            boxes.push(Triangle { v0: b.min, v1: b.max, v2: b.min });
            objects.push(i as u32);
            placed[p].push(i as u32);
        }
        // Refit while the moved boxes keep the tree within the refit limit of its built cost
        // (as the moving world-space part is, assemble.rs); rebuilt otherwise.
        let max_depth = self.tlas_stack as usize;
        let refitted = self
            .tlas_tree
            .as_mut()
            .filter(|t| t.triangles == boxes.len())
            .and_then(|t| accel::refit(t, &boxes))
            .filter(|a| a.depth <= max_depth);
        // One instance a leaf: entering one costs a traversal of its mesh's tree, so no ray
        // should pay it for a neighbour's box.
        let tree = refitted.unwrap_or_else(|| {
            let (a, tree) = accel::build_refittable(&boxes, BvhKind::Bvh2, max_depth, 1);
            self.tlas_tree = tree;
            a
        });
        self.tlas_depth = tree.depth;
        self.tlas = tree.nodes;
        self.tlas_order =
            tree.order.iter().map(|&k| objects.get(k as usize).copied().unwrap_or(0)).collect();
        // Entry 0 draws the world-space triangles; each prototype's objects follow.
        self.draw_list = vec![NO_INSTANCE];
        self.draws.clear();
        for (proto, objs) in self.protos.iter().zip(&placed) {
            let first = self.draw_list.len() as u32;
            self.draw_list.extend_from_slice(objs);
            self.draws.push(Draw {
                vertices: proto.slot_base * 3..(proto.slot_base + proto.slots) * 3,
                instances: first..self.draw_list.len() as u32,
            });
        }
        self.tlas_build_time = start.elapsed();
    }

    /// The triangle slots the prototypes hold (between the world-space static part and the
    /// moving part); an empty range without instances.
    pub fn proto_slots(&self) -> std::ops::Range<u32> {
        match (self.protos.first(), self.protos.last()) {
            (Some(a), Some(b)) => a.slot_base..b.slot_base + b.slots,
            _ => 0..0,
        }
    }

    /// Append each prototype's triangles and tree (in its own space) after what the arrays
    /// hold; their nodes and slots are rebased past it, and the roots recorded.
    pub(super) fn append_protos(&mut self) {
        let objects = self.world.len();
        for p in 0..self.protos.len() {
            let slot_base = self.tris.len() / 3;
            let node_base = self.accel.node_count;
            let inputs = self.accel.order.len() as u32;
            let part = self.append_part(&[objects + p], inputs, slot_base, node_base, true, false);
            let f = &self.flat[objects + p];
            let bounds = f.tris.iter().fold(Aabb::empty(), |b, t| b.union(&t.aabb()));
            self.protos[p] = Proto {
                root: node_base as u32,
                slot_base: slot_base as u32,
                slots: (self.tris.len() / 3 - slot_base) as u32,
                bounds,
            };
            let a = &mut self.accel;
            a.nodes.extend_from_slice(&part.accel.nodes);
            a.node_count += part.accel.node_count;
            a.order.extend_from_slice(&part.accel.order);
            a.depth = a.depth.max(part.accel.depth);
        }
    }
}
