//! Refitting a tree to triangles that moved: the same topology and leaves, every box recomputed
//! bottom-up from the triangles' new positions. The binary layout refits obvhs's binary tree
//! (`refit_all`) and packs it again; the CWBVH is refit in place, each node's child boxes
//! quantized again as obvhs's conversion quantizes them (Ylitie et al. 2017 §3.1: the node's
//! origin is its box's minimum, its per-axis scale the power of two that spans the box in 255
//! steps, child planes rounded outwards): about 1 ms for 50,000 triangles (`bench --mode
//! animate`), a tenth of converting a binary tree. Where motion has stretched the boxes so that
//! the tree's surface-area cost has grown past [`REFIT_LIMIT`] times its cost when built, the
//! caller rebuilds instead.

use super::{Accel, BvhKind, pack_bvh2, packed_bvh2_depth};
use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::triangle::Triangle;
use std::time::Instant;

/// A refit tree's surface-area cost relative to its cost when built beyond which it is rebuilt
/// instead. Boxes that motion has grown overlap, and every ray pays for the overlap. Measured on
/// the 50,000-triangle skinned tube (tools/scripts/skinned_tube.py, CWBVH, reference tracer at
/// 128x128 on lavapipe), refit from its rest pose against rebuilt at each pose: cost ratio 1.08
/// traced 8% slower, 1.14 3%, 1.18 14%, 1.21 33%. 1.15 keeps the penalty near 10% and rebuilds
/// (42 ms of CPU for that tube) about once a second of its bending.
pub const REFIT_LIMIT: f32 = 1.15;

/// A built tree kept for refitting: obvhs's binary tree the GPU nodes were packed from, and its
/// cost when built.
pub struct RefitTree {
    tree: Tree,
    kind: BvhKind,
    depth: usize,
    /// Triangles it was built over (a refit needs the same number).
    pub triangles: usize,
    pub built_cost: f32,
    /// Its cost at the last refit (the built cost until one).
    pub last_cost: f32,
    /// Refits since it was built.
    pub refits: u32,
}

/// The tree in the form it is refit in.
enum Tree {
    Binary(obvhs::bvh2::Bvh2),
    /// The GPU nodes themselves and their leaf order (slot -> input triangle).
    Wide {
        nodes: Vec<CwBvhNode>,
        order: Vec<u32>,
    },
}

/// The surface-area heuristic's cost of a binary tree relative to its root's area: one unit per
/// inner node and one per triangle in a leaf, each weighed by the chance a ray through the root
/// meets its box (area ratio).
fn sah_cost(bvh: &obvhs::bvh2::Bvh2) -> f32 {
    let Some(root) = bvh.nodes.first() else { return 0.0 };
    let area = root.aabb.half_area().max(f32::MIN_POSITIVE);
    bvh.nodes
        .iter()
        .map(|n| n.aabb.half_area() * if n.prim_count > 0 { n.prim_count as f32 } else { 1.0 })
        .sum::<f32>()
        / area
}

/// [`super::build_within`] with leaves of at most `max_leaf` primitives, keeping what a later
/// [`refit`] needs (None for an empty input).
pub fn build_refittable(
    tris: &[Triangle],
    kind: BvhKind,
    max_depth: usize,
    max_leaf: u32,
) -> (Accel, Option<RefitTree>) {
    let (accel, bvh) = super::build_tree(tris, kind, max_depth, max_leaf);
    let tree = bvh.map(|bvh| {
        let (tree, built_cost) = match accel.kind {
            BvhKind::Bvh2 => {
                let cost = sah_cost(&bvh);
                (Tree::Binary(bvh), cost)
            }
            BvhKind::Cwbvh => {
                let mut nodes: Vec<CwBvhNode> = bytemuck::pod_collect_to_vec(&accel.nodes);
                let cost = refit_wide(&mut nodes, &accel.order, tris);
                (Tree::Wide { nodes, order: accel.order.clone() }, cost)
            }
        };
        RefitTree {
            tree,
            kind: accel.kind,
            depth: accel.depth,
            triangles: tris.len(),
            built_cost,
            last_cost: built_cost,
            refits: 0,
        }
    });
    (accel, tree)
}

/// Refit CWBVH `nodes` in place to `tris` (input order; `order` maps leaf slots to them), from
/// the last node back (obvhs places a node's children after it); returns the surface-area cost
/// as [`sah_cost`] counts it (each node, and each leaf child by its triangles).
fn refit_wide(nodes: &mut [CwBvhNode], order: &[u32], tris: &[Triangle]) -> f32 {
    let mut exact = vec![Aabb::empty(); nodes.len()];
    let mut cost = 0.0f32;
    for i in (0..nodes.len()).rev() {
        let n = &nodes[i];
        let mut child = [Aabb::empty(); 8];
        for (c, b) in child.iter_mut().enumerate() {
            if n.is_child_empty(c) {
                continue;
            }
            *b = if n.is_leaf(c) {
                let (first, count) = n.child_primitives(c);
                let b = (first..first + count)
                    .fold(Aabb::empty(), |b, s| b.union(&tris[order[s as usize] as usize].aabb()));
                cost += b.half_area() * count as f32;
                b
            } else {
                exact[n.child_node_index(c) as usize]
            };
        }
        let aabb = child.iter().fold(Aabb::empty(), |a, b| a.union(b));
        exact[i] = aabb;
        cost += aabb.half_area();
        quantize(&mut nodes[i], aabb, &child);
    }
    let root = exact.first().map_or(1.0, |b| b.half_area()).max(f32::MIN_POSITIVE);
    cost / root
}

/// A node's origin and scale for `aabb`, and its children's planes for `child`, as obvhs's
/// bvh2_to_cwbvh writes them.
fn quantize(node: &mut CwBvhNode, aabb: Aabb, child: &[Aabb; 8]) {
    let p = aabb.min;
    let e = ((aabb.max - aabb.min).max(Vec3A::splat(1e-20)) * (1.0 / 255.0)).log2().ceil().exp2();
    let rcp = 1.0 / e;
    node.p = p.into();
    node.e = [e.x, e.y, e.z].map(|c| (c.to_bits() >> 23) as u8);
    for (c, b) in child.iter().enumerate() {
        if node.is_child_empty(c) {
            continue;
        }
        let lo = ((b.min - p) * rcp).floor().clamp(Vec3A::ZERO, Vec3A::splat(255.0));
        let hi = ((b.max - p) * rcp).ceil().clamp(Vec3A::ZERO, Vec3A::splat(255.0));
        (node.child_min_x[c], node.child_min_y[c], node.child_min_z[c]) =
            (lo.x as u8, lo.y as u8, lo.z as u8);
        (node.child_max_x[c], node.child_max_y[c], node.child_max_z[c]) =
            (hi.x as u8, hi.y as u8, hi.z as u8);
    }
}

/// `tree` refit to `tris` (the same triangles it was built over, moved) and packed: the nodes
/// and the leaf order in the GPU layout; None (the tree unchanged) where the count differs or
/// the refit tree's cost exceeds [`REFIT_LIMIT`] times its built cost.
pub fn refit(tree: &mut RefitTree, tris: &[Triangle]) -> Option<Accel> {
    if tris.len() != tree.triangles || tris.is_empty() {
        return None;
    }
    let start = Instant::now();
    let (nodes, node_count, order, cost): (Vec<u8>, usize, Vec<u32>, f32) = match &mut tree.tree {
        Tree::Binary(bvh) => {
            for i in 0..bvh.nodes.len() {
                let n = &bvh.nodes[i];
                if n.prim_count > 0 {
                    let (first, count) = (n.first_index as usize, n.prim_count as usize);
                    let b = bvh.primitive_indices[first..first + count]
                        .iter()
                        .fold(Aabb::empty(), |b, &p| b.union(&tris[p as usize].aabb()));
                    bvh.nodes[i].set_aabb(b);
                }
            }
            bvh.refit_all();
            let cost = sah_cost(bvh);
            let packed = pack_bvh2(&bvh.nodes);
            debug_assert_eq!(packed_bvh2_depth(&packed), tree.depth);
            let bytes = bytemuck::cast_slice(&packed).to_vec();
            (bytes, packed.len(), bvh.primitive_indices.clone(), cost)
        }
        Tree::Wide { nodes, order } => {
            let cost = refit_wide(nodes, order, tris);
            (bytemuck::cast_slice(nodes).to_vec(), nodes.len(), order.clone(), cost)
        }
    };
    tree.last_cost = cost;
    if !(cost <= REFIT_LIMIT * tree.built_cost) {
        return None;
    }
    tree.refits += 1;
    Some(Accel {
        kind: tree.kind,
        nodes,
        node_count,
        order,
        build_time: start.elapsed(),
        median_fallback: false,
        // A refit keeps the topology.
        depth: tree.depth,
    })
}
