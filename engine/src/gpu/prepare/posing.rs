//! What posing on the GPU needs of a prepared scene (`gpu/posing.rs`, shaders/accel/pose.wgsl,
//! pose_slots.wgsl, refit.wgsl): the moving part's vertices at rest with their influences and
//! morph displacements, each triangle slot's three vertices, the moving tree's nodes by level,
//! and at each time the joint matrices and morph weights. Built from the last CPU flattening,
//! whose slots, winding and tree the GPU then keeps until the next one.

use super::{PreparedScene, rebased};
use crate::scene::{MAX_INFLUENCES, Scene};
use glam::{Mat3, Mat4, Vec3, Vec4};
use obvhs::cwbvh::node::CwBvhNode;

/// Texels of one joint matrix: its four columns, then its normal matrix's three.
pub const MATRIX_TEXELS: usize = 7;

/// One posed object, whose matrices and weights follow the previous object's.
#[derive(Clone, Debug)]
pub struct PosedObject {
    /// Its index among the scene's objects.
    pub object: usize,
    /// Whether its joints place it (a skin); otherwise its transform is its one matrix.
    skinned: bool,
    /// Its transform mirrored when flattened (the slots keep that winding).
    flip: bool,
}

/// The moving part as the GPU poses it ([`PreparedScene::posing_layout`]).
pub struct PosingLayout {
    /// Per vertex: position (w: the posed object's index, bits), normal, tangent.
    pub rest: Vec<Vec4>,
    /// Per vertex: joints 0-3, 4-7 (global matrix indices), weights 0-3, 4-7 (bits).
    pub influences: Vec<[u32; 4]>,
    /// Per posed object two records: (first delta record, targets, first weight, first
    /// vertex), (vertices, 0, 0, 0).
    pub object_records: Vec<[u32; 4]>,
    /// Per object, target and vertex: position, normal, tangent displacements.
    pub deltas: Vec<Vec4>,
    /// Per moving slot its three vertices.
    pub slot_verts: Vec<[u32; 4]>,
    pub slot_base: u32,
    /// The moving tree's first node among the scene's, its nodes (references global, as
    /// uploaded), and its nodes grouped by depth, deepest first: (first, count) into
    /// `level_nodes`.
    pub node_base: u32,
    pub nodes: Vec<u8>,
    pub level_nodes: Vec<u32>,
    pub levels: Vec<(u32, u32)>,
    /// Its surface-area cost when built; a refit past [`crate::accel::REFIT_LIMIT`] times it
    /// is rebuilt on the CPU.
    pub built_cost: f32,
    pub objects: Vec<PosedObject>,
    /// Matrices and weights of one shutter end.
    pub matrices: u32,
    pub weights: u32,
}

impl PreparedScene {
    /// Whether this scene's moving part can be posed on the GPU: deforming meshes in an
    /// animated CWBVH scene whose moving triangles emit nothing (the emitter table samples
    /// triangles by their area when flattened).
    pub fn posing_supported(&self) -> bool {
        let Some(sp) = &self.split else { return false };
        self.features.deforming
            && self.accel.kind == crate::accel::BvhKind::Cwbvh
            && self.tris.len() / 3 > sp.slots
            && self.moving_tree.is_some()
            // Emitters are listed by slot, the static part's first: the last is the moving
            // part's if any is.
            && self.emitter_slots.last().is_none_or(|&e| (e as usize) < sp.slots)
    }

    /// The moving tree's surface-area cost when built and at its last CPU refit, relative to
    /// its root's area ([`crate::accel::refit`]).
    pub fn moving_tree_costs(&self) -> Option<(f32, f32)> {
        self.moving_tree.as_ref().map(|t| (t.built_cost, t.last_cost))
    }

    /// The moving part's layout for the GPU, from its last CPU flattening; None where
    /// [`PreparedScene::posing_supported`] is false.
    pub fn posing_layout(&self, scene: &Scene) -> Option<PosingLayout> {
        if !self.posing_supported() {
            return None;
        }
        let sp = self.split.as_ref()?;
        let (moving, _) = self.moving_objects();
        let mut l = PosingLayout {
            rest: vec![],
            influences: vec![],
            object_records: vec![],
            deltas: vec![],
            slot_verts: vec![],
            slot_base: sp.slots as u32,
            node_base: sp.nodes as u32,
            nodes: self.accel.nodes[sp.node_bytes..].to_vec(),
            level_nodes: vec![],
            levels: vec![],
            built_cost: self.moving_tree.as_ref().map_or(0.0, |t| t.built_cost),
            objects: vec![],
            matrices: 0,
            weights: 0,
        };
        // Per moving object its first vertex, and its triangles' first input index.
        let mut vertex_base = vec![];
        let mut input_base = vec![];
        let mut inputs = 0u32;
        for (k, &i) in moving.iter().enumerate() {
            let o = &scene.objects[i];
            let mesh = &scene.meshes[o.mesh];
            let deform = o.deform.as_deref();
            let skinned = deform
                .is_some_and(|d| !d.skin.is_empty() && mesh.joints.len() == mesh.positions.len());
            let targets = deform
                .and_then(|d| d.morph.as_ref())
                .map_or(0, |m| m.weights.len().min(mesh.targets.len()));
            let first = l.rest.len() as u32 / 3;
            let n = mesh.positions.len() as u32;
            let flip = glam::DMat3::from_mat4(self.world[i]).determinant() < 0.0;
            l.object_records.push([l.deltas.len() as u32 / 3, targets as u32, l.weights, first]);
            l.object_records.push([n, 0, 0, 0]);
            let joints = if skinned { deform.map_or(1, |d| d.skin.len()) } else { 1 };
            for v in 0..mesh.positions.len() {
                let nrm = mesh.normals.get(v).copied().unwrap_or(Vec3::Z);
                let tan = mesh.tangents.get(v).copied().unwrap_or(Vec4::new(1.0, 0.0, 0.0, 1.0));
                l.rest.push(mesh.positions[v].extend(f32::from_bits(k as u32)));
                l.rest.push(nrm.extend(0.0));
                l.rest.push(tan);
                let (mut js, mut ws) = ([l.matrices; MAX_INFLUENCES], [0.0; MAX_INFLUENCES]);
                if skinned {
                    for h in 0..MAX_INFLUENCES {
                        js[h] = l.matrices + (mesh.joints[v][h] as u32).min(joints as u32 - 1);
                        ws[h] = mesh.weights[v][h];
                    }
                } else {
                    ws[0] = 1.0;
                }
                let bits = |w: &[f32]| [0, 1, 2, 3].map(|c| w[c].to_bits());
                l.influences.push([js[0], js[1], js[2], js[3]]);
                l.influences.push([js[4], js[5], js[6], js[7]]);
                l.influences.push(bits(&ws[..4]));
                l.influences.push(bits(&ws[4..]));
            }
            for t in &mesh.targets[..targets] {
                for v in 0..mesh.positions.len() {
                    let at = |d: &[Vec3]| d.get(v).copied().unwrap_or(Vec3::ZERO).extend(0.0);
                    l.deltas.extend([at(&t.positions), at(&t.normals), at(&t.tangents)]);
                }
            }
            l.objects.push(PosedObject { object: i, skinned, flip });
            l.matrices += joints as u32;
            l.weights += targets as u32;
            vertex_base.push(first);
            input_base.push(inputs);
            inputs += self.flat[i].tris.len() as u32;
        }
        // Each slot's input triangle -> its object, mesh triangle and winding.
        for &global in &self.accel.order[sp.slots..] {
            let input = global - sp.inputs;
            let k = input_base.partition_point(|&b| b <= input) - 1;
            let i = moving[k];
            let j = (input - input_base[k]) as usize;
            let t = self.flat[i].src[j] as usize;
            let mesh = &scene.meshes[scene.objects[i].mesh];
            let idx = &mesh.indices[t * 3..t * 3 + 3];
            let idx =
                if l.objects[k].flip { [idx[0], idx[2], idx[1]] } else { [idx[0], idx[1], idx[2]] };
            let b = vertex_base[k];
            l.slot_verts.push([b + idx[0], b + idx[1], b + idx[2], 0]);
        }
        // Levels: each node's depth from the moving root (local node 0).
        let nodes: &[CwBvhNode] = bytemuck::cast_slice(&l.nodes);
        let mut depth = vec![0u32; nodes.len()];
        let mut by_depth: Vec<Vec<u32>> = vec![];
        for i in 0..nodes.len() {
            // obvhs places a node's children after it: a parent's depth is known first.
            let d = depth[i] as usize;
            if by_depth.len() <= d {
                by_depth.resize(d + 1, vec![]);
            }
            by_depth[d].push(i as u32);
            let n = &nodes[i];
            for c in 0..8 {
                if !n.is_child_empty(c) && !n.is_leaf(c) {
                    let child = (n.child_node_index(c) - l.node_base) as usize;
                    if child < depth.len() {
                        depth[child] = depth[i] + 1;
                    }
                }
            }
        }
        for level in by_depth.iter().rev() {
            l.levels.push((l.level_nodes.len() as u32, level.len() as u32));
            l.level_nodes.extend_from_slice(level);
        }
        Some(l)
    }

    /// The joint matrices ([`MATRIX_TEXELS`] each) and morph weights of `layout`'s objects at
    /// `time`, rebased to the scene's origin; a matrix that is not finite in f32 is the
    /// identity. Whether some object's transform now mirrors where its slots were wound
    /// otherwise (then the slots must be flattened again).
    pub fn posing_pose(
        &self,
        scene: &Scene,
        layout: &PosingLayout,
        time: f64,
        out: &mut Vec<Vec4>,
        weights: &mut Vec<f32>,
    ) -> bool {
        let mut rewound = false;
        let first = out.len();
        for p in &layout.objects {
            let o = &scene.objects[p.object];
            let now = o.transform_at(time);
            rewound |= (glam::DMat3::from_mat4(now).determinant() < 0.0) != p.flip;
            let placed = rebased(now, self.origin);
            let mut push = |m: Mat4| {
                let m = if m.is_finite() { m } else { Mat4::IDENTITY };
                let n = Mat3::from_mat4(m).inverse().transpose();
                let n = if n.is_finite() { n } else { Mat3::IDENTITY };
                out.extend([m.x_axis, m.y_axis, m.z_axis, m.w_axis]);
                out.extend([n.x_axis.extend(0.0), n.y_axis.extend(0.0), n.z_axis.extend(0.0)]);
            };
            let deform = o.deform.as_deref();
            match deform.filter(|_| p.skinned) {
                Some(d) => d.skin.iter().for_each(|j| push(placed * j.matrix(Some(time)))),
                None => push(placed),
            }
            let targets = scene.meshes[o.mesh].targets.len();
            if let Some(m) = deform.and_then(|d| d.morph.as_ref()) {
                let w = m.weights_at(Some(time));
                let n = targets.min(m.weights.len());
                weights.extend((0..n).map(|k| w.get(k).copied().unwrap_or(0.0)));
            }
        }
        debug_assert_eq!(out.len() - first, layout.matrices as usize * MATRIX_TEXELS);
        rewound
    }
}
