//! BVH build (obvhs) and its GPU layouts.
//!
//! Two layouts are supported so their traversal speed can be compared on the machine at hand
//! (`hush-cli bench --bvh`): a binary BVH whose nodes hold both children's boxes (one 64-byte
//! fetch tests two boxes), and obvhs's compressed 8-wide CWBVH (Ylitie et al. 2017, 80-byte
//! nodes). [`BvhKind::DEFAULT`] is the one measured faster on the software driver.

use bytemuck::{Pod, Zeroable};
use obvhs::{BvhBuildParams, triangle::Triangle};
use std::time::{Duration, Instant};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BvhKind {
    Bvh2,
    Cwbvh,
}

impl BvhKind {
    /// Measured on llvmpipe (see README, "BVH layouts").
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
}

impl Accel {
    /// Placeholder before the first build (no nodes).
    pub fn empty(kind: BvhKind) -> Accel {
        Accel { kind, nodes: vec![], node_count: 0, order: vec![], build_time: Duration::ZERO }
    }
}

fn params() -> BvhBuildParams {
    // No spatial pre-splits: every triangle then sits in exactly one leaf, and the GPU can store
    // triangles in leaf order.
    BvhBuildParams { pre_split: false, max_prims_per_leaf: 4, ..BvhBuildParams::medium_build() }
}

const EMPTY_MIN: [f32; 3] = [f32::MAX; 3];
const EMPTY_MAX: [f32; 3] = [-f32::MAX; 3];

pub fn build(tris: &[Triangle], kind: BvhKind) -> Accel {
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
        return Accel { kind: BvhKind::Bvh2, nodes, node_count: 1, order: vec![], build_time: start.elapsed() };
    }
    match kind {
        BvhKind::Bvh2 => {
            let mut core = Duration::ZERO;
            let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(tris, params(), &mut core);
            let nodes = pack_bvh2(&bvh.nodes);
            Accel {
                kind,
                node_count: nodes.len(),
                nodes: bytemuck::cast_slice(&nodes).to_vec(),
                order: bvh.primitive_indices.clone(),
                build_time: start.elapsed(),
            }
        }
        BvhKind::Cwbvh => {
            let mut core = Duration::ZERO;
            let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(tris, params(), &mut core);
            Accel {
                kind,
                node_count: bvh.nodes.len(),
                nodes: bytemuck::cast_slice(&bvh.nodes).to_vec(),
                order: bvh.primitive_indices.clone(),
                build_time: start.elapsed(),
            }
        }
    }
}

/// obvhs's BVH2 (each node its own box, children adjacent) -> nodes holding both child boxes.
fn pack_bvh2(nodes: &[obvhs::bvh2::node::Bvh2Node]) -> Vec<Bvh2GpuNode> {
    let root = &nodes[0];
    let child = |n: &obvhs::bvh2::node::Bvh2Node, gpu_index: u32| -> ([f32; 3], [f32; 3], u32, u32) {
        let (lo, hi) = (n.aabb.min.to_array(), n.aabb.max.to_array());
        if n.prim_count > 0 { (lo, hi, n.first_index, n.prim_count) } else { (lo, hi, gpu_index, 0) }
    };
    if root.prim_count > 0 {
        let (lmin, lmax, l_index, l_count) = child(root, 0);
        return vec![Bvh2GpuNode { lmin, l_index, lmax, l_count, rmin: EMPTY_MIN, r_index: 0, rmax: EMPTY_MAX, r_count: 1 }];
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
