//! BVH build (obvhs) and its GPU layouts.
//!
//! Two layouts are supported so their traversal speed can be compared on the machine at hand
//! (`hush-cli bench --bvh`): a binary BVH whose nodes hold both children's boxes (one 64-byte
//! fetch tests two boxes), and obvhs's compressed 8-wide CWBVH (Ylitie et al. 2017, 80-byte
//! nodes). [`BvhKind::DEFAULT`] is the one measured faster on the software driver.

use bytemuck::{Pod, Zeroable};
use obvhs::{BvhBuildParams, triangle::Triangle};
use std::time::{Duration, Instant};

pub mod light_tree;
mod refit;
pub use refit::{REFIT_LIMIT, RefitTree, build_refittable, refit};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BvhKind {
    Bvh2,
    Cwbvh,
}

impl BvhKind {
    /// Measured on llvmpipe (see docs/architecture.md, "BVH layouts").
    pub const DEFAULT: BvhKind = BvhKind::Cwbvh;

    pub fn name(self) -> &'static str {
        match self {
            BvhKind::Bvh2 => "bvh2",
            BvhKind::Cwbvh => "cwbvh",
        }
    }

    pub fn parse(s: &str) -> Option<BvhKind> {
        match s {
            "bvh2" => Some(BvhKind::Bvh2),
            "cwbvh" => Some(BvhKind::Cwbvh),
            _ => None,
        }
    }
}

/// A binary node as WGSL reads it (`shaders/common/bvh2.wgsl`): the two children's boxes. A
/// child with `count > 0` is a leaf of `count` triangles starting at `index`; with `count == 0`
/// it is the inner node `index`. Empty children have an inverted box, which no ray enters.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Bvh2GpuNode {
    pub lmin: [f32; 3],
    pub l_index: u32,
    pub lmax: [f32; 3],
    pub l_count: u32,
    pub rmin: [f32; 3],
    pub r_index: u32,
    pub rmax: [f32; 3],
    pub r_count: u32,
}

/// A BVH ready for upload.
pub struct Accel {
    pub kind: BvhKind,
    /// Node bytes in the layout of `kind`.
    pub nodes: Vec<u8>,
    pub node_count: usize,
    /// GPU triangle slot -> index of the input triangle. Triangles are uploaded in this order so
    /// that leaves address them directly.
    pub order: Vec<u32>,
    /// Wall time of the build (obvhs core build plus packing).
    pub build_time: Duration,
    /// The SAH tree came out deeper than the GPU traversal holds and this one was built by
    /// median splits instead ([`CWBVH_MAX_DEPTH`], [`BVH2_MAX_DEPTH`]).
    pub median_fallback: bool,
    /// Levels of nodes from the root to the deepest leaf (the root alone is 1): the traversal
    /// stack holds at most this many entries.
    pub depth: usize,
}

impl Accel {
    /// Placeholder before the first build (no nodes).
    pub fn empty(kind: BvhKind) -> Accel {
        Accel {
            kind,
            nodes: vec![],
            node_count: 0,
            order: vec![],
            build_time: Duration::ZERO,
            median_fallback: false,
            depth: 0,
        }
    }
}

/// Most triangles a leaf holds (obvhs collapses leaves up to it where the surface-area cost
/// says so).
pub const LEAF_TRIANGLES: u32 = 4;

fn params(max_leaf: u32) -> BvhBuildParams {
    // No spatial pre-splits: every triangle then sits in exactly one leaf, and the GPU can store
    // triangles in leaf order.
    BvhBuildParams {
        pre_split: false,
        max_prims_per_leaf: max_leaf,
        ..BvhBuildParams::medium_build()
    }
}

const EMPTY_MIN: [f32; 3] = [f32::MAX; 3];
const EMPTY_MAX: [f32; 3] = [-f32::MAX; 3];

/// The deepest tree the GPU traversals hold. Each program's traversal stack is sized for its
/// scene ([`traversal_stack`], `TRAVERSAL_STACK` in shaders/common/cwbvh.wgsl and bvh2.wgsl)
/// and never past these; a tree deeper than its stack would lose the subtrees that overflow it:
/// missing geometry, silently.
pub const CWBVH_MAX_DEPTH: usize = 32;
pub const BVH2_MAX_DEPTH: usize = 64;

impl BvhKind {
    pub fn max_depth(self) -> usize {
        match self {
            BvhKind::Bvh2 => BVH2_MAX_DEPTH,
            BvhKind::Cwbvh => CWBVH_MAX_DEPTH,
        }
    }
}

/// Entries of the traversal stack the programs of a scene are built with. The stack is a
/// private array that lavapipe zero-fills at every traversal and indexes by a ladder over all
/// its entries, so its cost grows with its length: on cornell_diffuse (tree depth 2) the
/// reference tracer made 0.69 M samples/s with 32 entries, 0.78 with 24, 0.91 with 16 and 1.00
/// with 8. A static scene's stack holds its tree's depth (rounded up to 4). An animated scene
/// rebuilds its tree every frame with the same stack ([`build_within`]), so its stack also
/// holds what the median fallback can reach over `n` triangles (ceil(log2 n) + 1 binary levels,
/// each at most one level of any layout) and four levels of headroom for the SAH tree.
pub fn traversal_stack(kind: BvhKind, depth: usize, triangles: usize, animated: bool) -> u32 {
    let need = if animated { (depth + 4).max(median_depth_bound(triangles)) } else { depth };
    need.max(4).next_multiple_of(4).min(kind.max_depth()) as u32
}

/// The stack of an animated scene split into a static tree and a rebuilt one (`gpu::prepare`'s
/// assemble): the static tree's depth, or what any rebuild of the moving part's `triangles`
/// can reach (as [`traversal_stack`] reckons it), and one entry more for the second root
/// waiting under the first tree's traversal.
pub fn split_traversal_stack(
    kind: BvhKind,
    static_depth: usize,
    depth: usize,
    triangles: usize,
) -> u32 {
    let need = static_depth.max(depth + 4).max(median_depth_bound(triangles)) + 1;
    need.max(4).next_multiple_of(4).min(kind.max_depth()) as u32
}

/// The depth a median build ([`median_bvh2`], one triangle per leaf) reaches over `n` triangles
/// in either layout: ceil(log2 n) + 1.
fn median_depth_bound(n: usize) -> usize {
    n.max(1).next_power_of_two().trailing_zeros() as usize + 1
}

pub fn build(tris: &[Triangle], kind: BvhKind) -> Accel {
    build_within(tris, kind, kind.max_depth())
}

/// [`build`], with the SAH tree kept only where it is at most `max_depth` deep (a traversal
/// stack of that many entries holds it); the median tree otherwise.
pub fn build_within(tris: &[Triangle], kind: BvhKind, max_depth: usize) -> Accel {
    build_tree(tris, kind, max_depth, LEAF_TRIANGLES).0
}

/// [`build_within`], with obvhs's binary tree the nodes were packed from (None for an empty
/// input), for [`refit`].
/// Leaves hold at most `max_leaf` primitives.
fn build_tree(
    tris: &[Triangle],
    kind: BvhKind,
    max_depth: usize,
    max_leaf: u32,
) -> (Accel, Option<obvhs::bvh2::Bvh2>) {
    let max_depth = max_depth.min(kind.max_depth());
    let start = Instant::now();
    if tris.is_empty() {
        let node = Bvh2GpuNode {
            lmin: EMPTY_MIN,
            l_index: 0,
            lmax: EMPTY_MAX,
            l_count: 1,
            rmin: EMPTY_MIN,
            r_index: 0,
            rmax: EMPTY_MAX,
            r_count: 1,
        };
        // An empty scene binds one node no ray can enter, in either layout's size.
        let mut nodes = bytemuck::bytes_of(&node).to_vec();
        nodes.resize(80, 0);
        let accel = Accel {
            kind: BvhKind::Bvh2,
            nodes,
            node_count: 1,
            order: vec![],
            build_time: start.elapsed(),
            median_fallback: false,
            depth: 1,
        };
        return (accel, None);
    }
    // obvhs's PLOC merges mutual nearest neighbours. Triangles that share one centroid (stacked
    // or nested copies) are all equally near each other: they merge one pair per pass (quadratic
    // time: 40,000 coincident triangles took 40 s) into a tree as deep as their count. Such input
    // goes straight to the median build, as does any tree still too deep for the GPU's stack.
    // Where neighbours' merge costs only tie (copies evenly spaced in a row) PLOC sees its boxes
    // jittered ([`TieBroken`]); other scenes build exactly as obvhs builds them.
    let survey = Survey::of(tris);
    let sah = match (survey.coincident > COINCIDENT_LIMIT, survey.tied > TIE_LIMIT) {
        (true, _) => None,
        (false, true) => {
            log::info!(
                "{} neighbour pairs of {} triangles share one merge cost: PLOC's boxes are jittered",
                survey.tied,
                tris.len()
            );
            sah_build(
                &tris
                    .iter()
                    .enumerate()
                    .map(|(i, t)| TieBroken::new(t.aabb(), i))
                    .collect::<Vec<_>>(),
                kind,
                max_depth,
                max_leaf,
            )
        }
        (false, false) => sah_build(tris, kind, max_depth, max_leaf),
    };
    let median_fallback = sah.is_none();
    let ((nodes, node_count, order, depth), tree) = sah.unwrap_or_else(|| {
        log::warn!(
            "the {} BVH over {} triangles is built by median splits, which trace slower: many triangles share one bounding box, and the SAH build would be too deep for the GPU's traversal stack",
            kind.name(),
            tris.len()
        );
        median_build(tris, kind, max_leaf)
    });
    let accel = Accel {
        kind,
        nodes,
        node_count,
        order,
        build_time: start.elapsed(),
        median_fallback,
        depth,
    };
    (accel, Some(tree))
}

/// Node bytes in the layout's GPU form, node count, triangle order and depth.
type Built = (Vec<u8>, usize, Vec<u32>, usize);

/// obvhs's PLOC build with its reinsertion optimisation (and, for the binary layout, leaf
/// collapsing), as its `build_*_from_tris` helpers do it but without their debug-build
/// validation, which panics on a tree deeper than obvhs's own stack. None where the tree is
/// deeper than the GPU traversal holds: checked before the reinsertion pass, which is slow on
/// deep trees, and after it.
fn sah_build<T: obvhs::Boundable>(
    prims: &[T],
    kind: BvhKind,
    max_depth: usize,
    max_leaf: u32,
) -> Option<(Built, obvhs::bvh2::Bvh2)> {
    let p = params(max_leaf);
    let mut bvh = obvhs::ploc::PlocBuilder::with_capacity(prims.len()).build(
        p.ploc_search_distance,
        prims,
        (0..prims.len() as u32).collect(),
        p.sort_precision,
        p.search_depth_threshold,
    );
    let reinsert = |bvh: &mut obvhs::bvh2::Bvh2, ratio: f32| {
        obvhs::bvh2::reinsertion::ReinsertionOptimizer::default().run(bvh, ratio, None)
    };
    match kind {
        BvhKind::Bvh2 => {
            if bvh2_depth(&bvh.nodes) > 2 * max_depth {
                return None;
            }
            reinsert(&mut bvh, p.reinsertion_batch_ratio);
            // PLOC's leaves hold one primitive each.
            if max_leaf > 1 {
                obvhs::bvh2::leaf_collapser::collapse(
                    &mut bvh,
                    p.max_prims_per_leaf,
                    p.collapse_traversal_cost,
                );
                reinsert(
                    &mut bvh,
                    p.reinsertion_batch_ratio * p.post_collapse_reinsertion_batch_ratio_multiplier,
                );
            }
            let nodes = pack_bvh2(&bvh.nodes);
            let depth = packed_bvh2_depth(&nodes);
            (depth <= max_depth).then(|| {
                let order = bvh.primitive_indices.clone();
                ((bytemuck::cast_slice(&nodes).to_vec(), nodes.len(), order, depth), bvh)
            })
        }
        BvhKind::Cwbvh => {
            // A CWBVH node spans up to three binary levels.
            if bvh2_depth(&bvh.nodes) > 3 * max_depth {
                return None;
            }
            reinsert(&mut bvh, p.reinsertion_batch_ratio);
            let cw = obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(
                &bvh,
                p.max_prims_per_leaf.clamp(1, 3),
                true,
                false,
            );
            let depth = cwbvh_depth(&cw.nodes);
            (depth <= max_depth).then(|| {
                let nodes = bytemuck::cast_slice(&cw.nodes).to_vec();
                ((nodes, cw.nodes.len(), cw.primitive_indices, depth), bvh)
            })
        }
    }
}

fn median_build(tris: &[Triangle], kind: BvhKind, max_leaf: u32) -> (Built, obvhs::bvh2::Bvh2) {
    let p = params(max_leaf);
    match kind {
        BvhKind::Bvh2 => {
            let bvh = median_bvh2(tris, p.max_prims_per_leaf as usize);
            let nodes = pack_bvh2(&bvh.nodes);
            let depth = packed_bvh2_depth(&nodes);
            let order = bvh.primitive_indices.clone();
            ((bytemuck::cast_slice(&nodes).to_vec(), nodes.len(), order, depth), bvh)
        }
        BvhKind::Cwbvh => {
            // obvhs's CWBVH leaves hold at most 3 triangles.
            let bvh = median_bvh2(tris, 1);
            let cw = obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(
                &bvh,
                p.max_prims_per_leaf.clamp(1, 3),
                true,
                false,
            );
            let nodes = bytemuck::cast_slice(&cw.nodes).to_vec();
            ((nodes, cw.nodes.len(), cw.primitive_indices, cwbvh_depth(&cw.nodes)), bvh)
        }
    }
}

/// Triangles sharing one centroid beyond which PLOC is not tried (see [`build`]); real scenes
/// stack a few copies at most.
const COINCIDENT_LIMIT: usize = 32;

/// A triangle's box as PLOC sees it where merge costs tie ([`Survey`]): enlarged by a pseudo-
/// random 0 to 1e-5 of its largest side. Where neighbours' costs tie exactly (a row of evenly
/// spaced copies), every node picks the same side and PLOC merges one pair per pass: 20,000
/// copies in a row took 4.9 s to build, jittered 0.06 s. An enlarged box only makes the tree's
/// bounds conservative. Only such input is jittered: any other tree would change which rays a
/// triangle's edge loses to its neighbour, and so the images.
struct TieBroken(obvhs::aabb::Aabb);

impl TieBroken {
    fn new(b: obvhs::aabb::Aabb, i: usize) -> TieBroken {
        let r = (i as u32).wrapping_mul(0x9E37_79B9).rotate_left(13).wrapping_mul(0x85EB_CA6B) >> 8;
        // The largest side rather than the diagonal's length, which overflows f32 for a box
        // whose sides are finite (and inf x 0 is NaN, which PLOC refuses).
        let pad = b.diagonal().max_element() * 1e-5 * (r as f32 / (1 << 24) as f32);
        TieBroken(obvhs::aabb::Aabb::new(b.min - pad, b.max + pad))
    }
}

impl obvhs::Boundable for TieBroken {
    fn aabb(&self) -> obvhs::aabb::Aabb {
        self.0
    }
}

/// What PLOC would meet, from the triangles in Morton order (PLOC's own order): the most that
/// share one centroid, and the most neighbour pairs with one merge cost (the half area of the
/// union of consecutive boxes, bit for bit). Repeated costs are what copies of a mesh laid out
/// at even steps produce, and once PLOC has merged each copy into one node they tie along the
/// whole row.
struct Survey {
    coincident: usize,
    tied: usize,
}

impl Survey {
    fn of(tris: &[Triangle]) -> Survey {
        use obvhs::aabb::Aabb;
        let boxes: Vec<Aabb> = tris.iter().map(|t| t.aabb()).collect();
        let total = boxes.iter().fold(Aabb::empty(), |a, b| a.union(b));
        let span = total.diagonal().as_dvec3().max(glam::DVec3::splat(f64::MIN_POSITIVE));
        let mut keys: Vec<(u64, [u32; 3], u32)> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let c = b.center();
                let unit = ((c.as_dvec3() - total.min.as_dvec3()) / span)
                    .clamp(glam::DVec3::ZERO, glam::DVec3::ONE);
                (
                    obvhs::ploc::morton::morton_encode_u64_unorm(unit),
                    c.to_array().map(f32::to_bits),
                    i as u32,
                )
            })
            .collect();
        keys.sort_unstable();
        let coincident = keys.chunk_by(|a, b| a.1 == b.1).map(|run| run.len()).max().unwrap_or(0);
        let mut costs: Vec<u32> = keys
            .windows(2)
            .map(|w| boxes[w[0].2 as usize].union(&boxes[w[1].2 as usize]).half_area().to_bits())
            .collect();
        costs.sort_unstable();
        let tied = costs.chunk_by(|a, b| a == b).map(|run| run.len()).max().unwrap_or(0);
        Survey { coincident, tied }
    }
}

/// Neighbour pairs sharing one merge cost beyond which PLOC's input is jittered (see [`build`]).
/// PLOC's time grows with the square of a tied row (10,000 copies: 1.1 s, 20,000: 4.9 s), so
/// rows this short cost at most 0.2 s together; the staircase, the most repetitive scene tested,
/// has 104 such pairs and keeps obvhs's tree.
const TIE_LIMIT: usize = 4096;

/// Depth of an obvhs BVH2 (the root alone is 1).
fn bvh2_depth(nodes: &[obvhs::bvh2::node::Bvh2Node]) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(0usize, 1usize)];
    while let Some((i, d)) = stack.pop() {
        deepest = deepest.max(d);
        let n = &nodes[i];
        if n.prim_count == 0 {
            stack.push((n.first_index as usize, d + 1));
            stack.push((n.first_index as usize + 1, d + 1));
        }
    }
    deepest
}

/// Depth of a packed binary BVH ([`Bvh2GpuNode`]) in nodes (the root alone is 1).
fn packed_bvh2_depth(nodes: &[Bvh2GpuNode]) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(0usize, 1usize)];
    while let Some((i, d)) = stack.pop() {
        deepest = deepest.max(d);
        let n = &nodes[i];
        for (index, count) in [(n.l_index, n.l_count), (n.r_index, n.r_count)] {
            if count == 0 {
                stack.push((index as usize, d + 1));
            }
        }
    }
    deepest
}

/// Depth of a CWBVH in nodes (the root alone is 1).
fn cwbvh_depth(nodes: &[obvhs::cwbvh::node::CwBvhNode]) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(0usize, 1usize)];
    while let Some((i, d)) = stack.pop() {
        deepest = deepest.max(d);
        for ch in 0..8 {
            if !nodes[i].is_child_empty(ch) && !nodes[i].is_leaf(ch) {
                stack.push((nodes[i].child_node_index(ch) as usize, d + 1));
            }
        }
    }
    deepest
}

/// A BVH2 of depth at most ceil(log2(n / leaf)) + 1: each node splits its triangles at the
/// median centroid along the centroids' longest axis (ties by index, so coincident triangles
/// split too). Written here because obvhs builds only by PLOC, whose tree has no depth bound;
/// this one is the fallback where that tree is too deep for the GPU's traversal stack.
fn median_bvh2(tris: &[Triangle], leaf: usize) -> obvhs::bvh2::Bvh2 {
    use obvhs::{aabb::Aabb, bvh2::node::Bvh2Node};
    let boxes: Vec<Aabb> = tris.iter().map(|t| t.aabb()).collect();
    let centre: Vec<glam::Vec3A> = boxes.iter().map(|b| b.center()).collect();
    let mut prims: Vec<u32> = (0..tris.len() as u32).collect();
    let mut nodes = vec![Bvh2Node::default()];
    let mut stack = vec![(0usize, 0usize, tris.len())];
    while let Some((ni, s, e)) = stack.pop() {
        let bounds = prims[s..e].iter().fold(Aabb::empty(), |b, &i| b.union(&boxes[i as usize]));
        if e - s <= leaf.max(1) {
            nodes[ni] = Bvh2Node::new(bounds, (e - s) as u32, s as u32);
            continue;
        }
        let mut cb = Aabb::empty();
        for &i in &prims[s..e] {
            cb.extend(centre[i as usize]);
        }
        let axis = cb.largest_axis();
        let mid = (s + e) / 2;
        prims[s..e].select_nth_unstable_by(mid - s, |&a, &b| {
            centre[a as usize][axis].total_cmp(&centre[b as usize][axis]).then(a.cmp(&b))
        });
        let first = nodes.len();
        nodes.push(Bvh2Node::default());
        nodes.push(Bvh2Node::default());
        nodes[ni] = Bvh2Node::new(bounds, 0, first as u32);
        stack.push((first, s, mid));
        stack.push((first + 1, mid, e));
    }
    obvhs::bvh2::Bvh2 { nodes, primitive_indices: prims, ..Default::default() }
}

/// obvhs's BVH2 (each node its own box, children adjacent) -> nodes holding both child boxes.
fn pack_bvh2(nodes: &[obvhs::bvh2::node::Bvh2Node]) -> Vec<Bvh2GpuNode> {
    let root = &nodes[0];
    let child =
        |n: &obvhs::bvh2::node::Bvh2Node, gpu_index: u32| -> ([f32; 3], [f32; 3], u32, u32) {
            let (lo, hi) = (n.aabb.min.to_array(), n.aabb.max.to_array());
            if n.prim_count > 0 {
                (lo, hi, n.first_index, n.prim_count)
            } else {
                (lo, hi, gpu_index, 0)
            }
        };
    if root.prim_count > 0 {
        let (lmin, lmax, l_index, l_count) = child(root, 0);
        return vec![Bvh2GpuNode {
            lmin,
            l_index,
            lmax,
            l_count,
            rmin: EMPTY_MIN,
            r_index: 0,
            rmax: EMPTY_MAX,
            r_count: 1,
        }];
    }
    // Breadth-first numbering of inner nodes: gpu[i] holds obvhs inner node inner[i].
    let mut inner = vec![0usize];
    let mut gpu_of = std::collections::HashMap::new();
    gpu_of.insert(0usize, 0u32);
    let mut i = 0;
    while i < inner.len() {
        let n = &nodes[inner[i]];
        for c in [n.first_index as usize, n.first_index as usize + 1] {
            if nodes[c].prim_count == 0 {
                gpu_of.insert(c, inner.len() as u32);
                inner.push(c);
            }
        }
        i += 1;
    }
    inner
        .iter()
        .map(|&ni| {
            let n = &nodes[ni];
            let (a, b) = (n.first_index as usize, n.first_index as usize + 1);
            let (lmin, lmax, l_index, l_count) = child(&nodes[a], *gpu_of.get(&a).unwrap_or(&0));
            let (rmin, rmax, r_index, r_count) = child(&nodes[b], *gpu_of.get(&b).unwrap_or(&0));
            Bvh2GpuNode { lmin, l_index, lmax, l_count, rmin, r_index, rmax, r_count }
        })
        .collect()
}

#[cfg(test)]
mod tests;
