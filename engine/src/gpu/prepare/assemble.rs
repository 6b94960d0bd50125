//! The flattened objects in the order the GPU reads them: a BVH over their triangles, then every
//! per-triangle array in BVH leaf order, and the emitter CDF.
//!
//! A static scene is one tree over everything, built once. In an animated scene the objects
//! that never move are built once into a static tree whose nodes and triangles lead the GPU
//! arrays, and only the moving objects' tree is rebuilt when they move: its nodes and triangles
//! follow the static ones (node and triangle indices rebased past them), the traversal visits
//! its root after the static tree's (`DYNAMIC_ROOT`, shaders/common/cwbvh.wgsl and bvh2.wgsl),
//! and only that tail is rewritten on the GPU (`GpuScene::update_geometry`); what it saves is
//! measured at `StaticPart`. Every moving object is still rebuilt, all together, whenever
//! anything moves.

use super::{Flat, PreparedScene};
use crate::accel::light_tree::{Emitter, LightTree};
use crate::accel::{self, Accel, Bvh2GpuNode, BvhKind};
use glam::{Vec3, Vec3A, Vec4};
use obvhs::triangle::Triangle;

/// What an animated scene's static objects hold of the GPU arrays, from their start: their
/// triangle slots, input triangles, BVH nodes and emitters. The moving objects' part follows.
/// Rebuilding and uploading only that part costs the living room with one 1,008-triangle node
/// turning 1.07 ms a frame where the whole tree took 121.6 ms (CWBVH; binary BVH 1.37 against
/// 97.8 ms; `bench --mode animate` on lavapipe).
#[derive(Clone, Debug, Default)]
pub(crate) struct StaticPart {
    pub slots: usize,
    pub inputs: u32,
    pub nodes: usize,
    pub node_bytes: usize,
    pub depth: usize,
    /// (luminance of the emission, slot) of its emissive triangles.
    emitters: Vec<(f32, u32)>,
}

/// One part's tree and emitters, its indices already global.
pub(super) struct Part {
    pub(super) accel: Accel,
    emitters: Vec<(f32, u32)>,
}

/// Bytes of one node in `kind`'s GPU layout.
fn node_size(kind: BvhKind) -> usize {
    match kind {
        BvhKind::Bvh2 => std::mem::size_of::<Bvh2GpuNode>(),
        BvhKind::Cwbvh => 80,
    }
}

/// One node no ray enters, in `kind`'s layout: inverted boxes (binary) or no children (CWBVH).
fn empty_node(kind: BvhKind) -> Vec<u8> {
    match kind {
        BvhKind::Bvh2 => {
            let (lo, hi) = ([f32::MAX; 3], [-f32::MAX; 3]);
            let n = Bvh2GpuNode {
                lmin: lo,
                l_index: 0,
                lmax: hi,
                l_count: 1,
                rmin: lo,
                r_index: 0,
                rmax: hi,
                r_count: 1,
            };
            bytemuck::bytes_of(&n).to_vec()
        }
        BvhKind::Cwbvh => vec![0; 80],
    }
}

/// Shift a part's node references past `node_base` nodes and its triangle references past
/// `slot_base` slots. Binary nodes: a child with a count is a triangle range, else a node.
/// CWBVH nodes: the child base index (bytes 16..20) and the primitive base index (20..24).
fn rebase_nodes(kind: BvhKind, bytes: &mut [u8], node_base: u32, slot_base: u32) {
    if node_base == 0 && slot_base == 0 {
        return;
    }
    let add = |b: &mut [u8], at: usize, v: u32| {
        let x = bytemuck::pod_read_unaligned::<u32>(&b[at..at + 4]).wrapping_add(v);
        b[at..at + 4].copy_from_slice(&x.to_le_bytes());
    };
    for n in bytes.chunks_exact_mut(node_size(kind)) {
        match kind {
            BvhKind::Bvh2 => {
                // Bvh2GpuNode: l_index at 12, l_count at 28, r_index at 44, r_count at 60.
                for (index, count) in [(12, 28), (44, 60)] {
                    let c = bytemuck::pod_read_unaligned::<u32>(&n[count..count + 4]);
                    add(n, index, if c > 0 { slot_base } else { node_base });
                }
            }
            BvhKind::Cwbvh => {
                add(n, 16, node_base);
                add(n, 20, slot_base);
            }
        }
    }
}

impl PreparedScene {
    /// Objects that move (rebuilt with every change) and those that never do.
    pub(super) fn moving_objects(&self) -> (Vec<usize>, Vec<usize>) {
        (0..self.world.len()).partition(|&i| self.moving[i])
    }

    /// The BVH and the GPU arrays: everything at once for a static scene; for an animated one,
    /// the static part at its first call and the moving part at every call.
    pub(super) fn assemble(&mut self) {
        let (moving, still) = self.moving_objects();
        // Instanced meshes' prototypes follow the world-space static part
        // (prepare/instances.rs), and are built once with it.
        let protos = !self.protos.is_empty();
        if moving.is_empty() {
            self.clear_arrays();
            let all: Vec<usize> = (0..self.world.len()).collect();
            let part = self.append_part(&all, 0, 0, 0, protos, false);
            self.accel = part.accel;
            self.append_protos();
            self.set_emitters(part.emitters, 0);
            return;
        }
        let kind = self.accel.kind;
        let sp = match self.split.clone() {
            Some(sp) => sp,
            None => {
                self.clear_arrays();
                let part = self.append_part(&still, 0, 0, 0, true, false);
                self.accel = part.accel;
                self.append_protos();
                let sp = StaticPart {
                    slots: self.tris.len() / 3,
                    inputs: self.accel.order.len() as u32,
                    nodes: self.accel.node_count,
                    node_bytes: self.accel.nodes.len(),
                    depth: self.accel.depth,
                    emitters: part.emitters,
                };
                self.split = Some(sp.clone());
                sp
            }
        };
        self.truncate_arrays(sp.slots);
        let part = self.append_part(&moving, sp.inputs, sp.slots, sp.nodes, true, true);
        let a = &mut self.accel;
        a.kind = kind;
        a.nodes.truncate(sp.node_bytes);
        a.nodes.extend_from_slice(&part.accel.nodes);
        a.node_count = sp.nodes + part.accel.node_count;
        a.order.truncate(sp.slots);
        a.order.extend_from_slice(&part.accel.order);
        a.build_time = part.accel.build_time;
        a.median_fallback = part.accel.median_fallback;
        a.depth = sp.depth.max(part.accel.depth);
        let emitters = sp.emitters.iter().copied().chain(part.emitters).collect();
        self.set_emitters(emitters, sp.emitters.len());
    }

    /// The root of the moving objects' tree, which the traversal visits after the static
    /// one's; None for a static scene.
    pub fn dynamic_root(&self) -> Option<u32> {
        self.split.as_ref().map(|sp| sp.nodes as u32)
    }

    /// Input triangles of an animated scene's static part: the moving objects' triangles are
    /// numbered from here (the index in `tris`' second w); 0 for a static scene.
    pub fn static_inputs(&self) -> u32 {
        self.split.as_ref().map_or(0, |sp| sp.inputs)
    }

    /// How much of the GPU arrays never changes after the first upload: (triangle slots,
    /// node bytes); (0, 0) for a static scene, which rewrites everything it changes.
    pub fn static_prefix(&self) -> (usize, usize) {
        self.split.as_ref().map_or((0, 0), |sp| (sp.slots, sp.node_bytes))
    }

    fn clear_arrays(&mut self) {
        self.truncate_arrays(0);
        self.accel.nodes.clear();
        self.accel.order.clear();
    }

    /// Keep the first `slots` triangles of every per-triangle array.
    fn truncate_arrays(&mut self, slots: usize) {
        self.tris.truncate(3 * slots);
        self.tris_open.truncate(3 * slots);
        self.tris_prev.truncate(3 * slots);
        self.shading.truncate(4 * slots);
        self.tangents.truncate(3 * slots);
        self.extras.truncate(3 * slots);
    }

    /// Build a tree over `objects`' triangles and append them, in its leaf order, to the GPU
    /// arrays. Input indices start at `input_base`, slots at `slot_base`, nodes at `node_base`;
    /// `split`: the tree is one of two, and leaves the traversal one stack entry; `refit`: it is
    /// the moving part, whose last tree is refit rather than rebuilt where that stays good
    /// enough ([`accel::refit`]).
    pub(super) fn append_part(
        &mut self,
        objects: &[usize],
        input_base: u32,
        slot_base: usize,
        node_base: usize,
        split: bool,
        refit: bool,
    ) -> Part {
        let kind = self.accel.kind;
        // An instanced mesh's prototype (appended alone by `append_protos`): its points move
        // with their instances' transforms, which its previous vertices' w = 1 says
        // (realtime/motion_vertices.wgsl).
        let prototype = objects.iter().all(|&i| i >= self.world.len());
        let n: usize = objects.iter().map(|&i| self.flat[i].tris.len()).sum();
        let mut tris_in: Vec<Triangle> = Vec::with_capacity(n);
        let mut attrs: Vec<&[glam::Vec4; 4]> = Vec::with_capacity(n);
        let mut tans: Vec<&[glam::Vec4; 3]> = vec![];
        let mut extras: Vec<&[[u32; 4]; 3]> = vec![];
        let mut mats: Vec<u32> = Vec::with_capacity(n);
        let mut open_in: Vec<Triangle> = vec![];
        let mut prev: Vec<[Vec3; 3]> = vec![];
        self.tris.reserve(3 * n);
        self.tris_open.reserve(if self.features.animated { 3 * n } else { 0 });
        self.tris_prev.reserve(if self.features.deforming { 3 * n } else { 0 });
        self.shading.reserve(4 * n);
        for &i in objects {
            let f: &Flat = &self.flat[i];
            tris_in.extend_from_slice(&f.tris);
            attrs.extend(f.attrs.iter());
            tans.extend(f.tans.iter());
            extras.extend(f.extras.iter());
            mats.extend_from_slice(&f.mats);
            if !f.open.is_empty() {
                open_in.extend(f.open.iter().map(|v| Triangle {
                    v0: v[0].into(),
                    v1: v[1].into(),
                    v2: v[2].into(),
                }));
            } else if let Some(m) = self.open_from_close.get(i) {
                let to = |v: Vec3A| Vec3A::from(m.transform_point3(v.into()));
                open_in.extend(f.tris.iter().map(|t| Triangle {
                    v0: to(t.v0),
                    v1: to(t.v1),
                    v2: to(t.v2),
                }));
            }
            if self.features.deforming {
                if prototype {
                    prev.extend(f.tris.iter().map(|_| [Vec3::ZERO; 3]));
                } else if f.prev.is_empty() {
                    prev.extend(f.tris.iter().map(|t| [t.v0, t.v1, t.v2].map(Vec3::from)));
                } else {
                    prev.extend_from_slice(&f.prev);
                }
            }
        }
        let max_depth = self.traversal_stack as usize - split as usize;
        // With motion, the tree is built over each triangle's box at both ends of the shutter:
        // a degenerate triangle from the box's min to its max has exactly that box.
        let swept: Vec<Triangle>;
        let boxes = if open_in.is_empty() {
            &tris_in
        } else {
            swept = tris_in
                .iter()
                .zip(&open_in)
                .map(|(c, o)| {
                    let b = c.aabb().union(&o.aabb());
                    Triangle { v0: b.min, v1: b.max, v2: b.min }
                })
                .collect();
            &swept
        };
        let mut accel = if split && tris_in.is_empty() {
            Accel { kind, nodes: empty_node(kind), node_count: 1, depth: 1, ..Accel::empty(kind) }
        } else if refit {
            // The moving part: refit its last tree where that stays good enough.
            let refitted = match self.moving_tree.as_mut().filter(|_| self.refit) {
                Some(tree) => accel::refit(tree, boxes).filter(|a| a.depth <= max_depth),
                None => None,
            };
            refitted.unwrap_or_else(|| {
                let (a, tree) =
                    accel::build_refittable(boxes, kind, max_depth, accel::LEAF_TRIANGLES);
                self.moving_tree = tree;
                a
            })
        } else {
            accel::build_within(boxes, kind, max_depth)
        };
        if accel.depth > max_depth {
            // Not reachable: the stack of an animated scene holds any median tree over its
            // triangles ([`accel::traversal_stack`]).
            log::error!(
                "the rebuilt BVH is {} levels deep; the traversal holds {}: geometry will be missing",
                accel.depth,
                max_depth
            );
        }
        if split {
            rebase_nodes(kind, &mut accel.nodes, node_base as u32, slot_base as u32);
        }
        let mut emitters = vec![];
        for (local, &orig) in accel.order.iter().enumerate() {
            let (t, i) = (&tris_in[orig as usize], orig as usize);
            let global = input_base + orig;
            let v = |a: Vec3A| Vec3::from(a);
            self.tris.push(v(t.v0).extend(f32::from_bits(mats[i])));
            self.tris.push(v(t.v1).extend(f32::from_bits(global)));
            self.tris.push(v(t.v2).extend(0.0));
            if self.features.animated {
                let o = open_in.get(i).unwrap_or(t);
                self.tris_open.extend([
                    v(o.v0).extend(0.0),
                    v(o.v1).extend(0.0),
                    v(o.v2).extend(0.0),
                ]);
            }
            if let Some(p) = prev.get(i) {
                self.tris_prev.extend(p.map(|v| v.extend(if prototype { 1.0 } else { 0.0 })));
            }
            self.shading.extend_from_slice(attrs[i]);
            if self.features.normal_maps {
                self.tangents.extend_from_slice(tans[i]);
            }
            if self.features.vertex_extras {
                self.extras.extend_from_slice(extras[i]);
            }
            // Emissive triangles and the luminance of their emission (the light tree weighs them
            // by area x luminance, one-sided power up to a constant pi).
            let lum = self
                .materials
                .get(mats[i] as usize)
                .map_or(0.0, |m| crate::quality::luminance(Vec3::from_slice(&m.emission)));
            if lum > 0.0 {
                emitters.push((lum, (slot_base + local) as u32));
            }
        }
        for o in accel.order.iter_mut() {
            *o += input_base;
        }
        Part { accel, emitters }
    }

    /// The light tree over (luminance, slot) pairs, the first `fixed` of the static
    /// part; each emitter's third vertex's w names its leaf (+ 1, as a float: 0 is no leaf),
    /// which an emitter hit needs for its MIS weight (shaders/common/emitters.wgsl).
    fn set_emitters(&mut self, list: Vec<(f32, u32)>, fixed: usize) {
        let vertices = |at: &[Vec4], slot: u32| {
            let v = |k: usize| at[3 * slot as usize + k].truncate();
            [v(0), v(1), v(2)]
        };
        let emitters: Vec<Emitter> = list
            .iter()
            .map(|&(luminance, slot)| {
                let moves = self.tris_open.len() == self.tris.len();
                let open = moves.then(|| vertices(&self.tris_open, slot));
                Emitter::triangle(vertices(&self.tris, slot), open, luminance, slot)
            })
            .collect();
        let tree = LightTree::build_split(&emitters, fixed);
        for (e, &leaf) in emitters.iter().zip(&tree.leaf_of) {
            let named = if leaf == u32::MAX { 0.0 } else { leaf as f32 + 1.0 };
            self.tris[3 * e.slot as usize + 2].w = named;
        }
        self.emitter_slots = list.iter().map(|e| e.1).collect();
        self.emitters = tree.nodes;
    }
}
