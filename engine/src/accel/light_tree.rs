//! A light tree over the scene's emissive triangles (Conty Estevez and Kulla 2018, "Importance
//! sampling of many lights with adaptive tree splitting"): each node bounds its emitters'
//! positions (a box), the directions they emit into (a cone of half-angle θ_o around an axis;
//! one-sided triangles add θ_e = π/2) and their power. A light sample walks down from the root,
//! taking each child with probability proportional to its importance to the shaded point and
//! normal (§4.3, with pbrt-v4's conservative bound of θ'), so lamps far away, facing away or
//! below the surface's horizon are seldom chosen, and never one whose every emitter faces away.
//! The probability of one emitter, which MIS with BSDF sampling needs where a path hits it,
//! walks the other way, from its leaf up through the parents.
//!
//! shaders/common/light_tree.wgsl mirrors [`importance`], [`LightTree::sample`] and
//! [`LightTree::pmf`] on this layout; tests/light_tree.rs checks that both agree. Written here
//! because no crate builds a light tree into a GPU layout (pbrt-v4's and Cycles' are C++).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use std::f32::consts::PI;

/// `LightNode::child` of a leaf: this bit, and the emitter's triangle slot below it.
pub const LEAF: u32 = 0x8000_0000;
/// Splits evaluated per axis (Conty Estevez and Kulla §4.4 bin the centroids as SAH builders
/// do; 12 as pbrt-v4's BVH).
const BINS: usize = 12;
/// Below this depth a node splits by its cost; deeper, at the median (a bound on the GPU walk).
const COST_DEPTH: usize = 40;

/// One node, 64 bytes: four texels of the scene's `emitter_texels` (shaders/common/light_tree.wgsl
/// `light_node` reads the first three, a leaf's area the fourth).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct LightNode {
    /// The sphere around the emitters' box: what the importance bounds positions by (its
    /// centre and radius rather than the box: the walk evaluates two nodes a level).
    pub centre: [f32; 3],
    pub radius: f32,
    pub axis: [f32; 3],
    /// Cosine and sine of θ_o, the emission cone's half-angle around `axis` (cos -1: every
    /// direction).
    pub cos_o: f32,
    pub sin_o: f32,
    /// Sum of area x luminance(emission) of the emitters below (one-sided power over π).
    pub power: f32,
    /// Interior: the right child (the left is the next node). Leaf: [`LEAF`] | triangle slot.
    pub child: u32,
    /// The parent (the root's is 0).
    pub parent: u32,
    /// A leaf's triangle area (its point is uniform in area); 0 for an interior node.
    pub area: f32,
    pub pad: [u32; 3],
}

/// An emissive triangle: its vertices (at both ends of the shutter where it moves), the
/// luminance of its emission and its triangle slot.
#[derive(Clone, Debug)]
pub struct Emitter {
    pub vertices: Vec<Vec3>,
    /// Normal (counter-clockwise face, the one that emits) at each end of the shutter.
    pub normals: Vec<Vec3>,
    pub area: f32,
    pub luminance: f32,
    pub slot: u32,
}

impl Emitter {
    /// The triangle (v0, v1, v2) at the shutter's close and, where it moves, `open` at its open.
    pub fn triangle(v: [Vec3; 3], open: Option<[Vec3; 3]>, luminance: f32, slot: u32) -> Emitter {
        let normal = |v: [Vec3; 3]| (v[1] - v[0]).cross(v[2] - v[0]);
        let c = normal(v);
        let mut e = Emitter {
            vertices: v.to_vec(),
            normals: vec![c.normalize_or_zero()],
            area: 0.5 * c.length(),
            luminance,
            slot,
        };
        if let Some(o) = open {
            e.vertices.extend(o);
            e.normals.push(normal(o).normalize_or_zero());
        }
        e
    }

    fn power(&self) -> f32 {
        self.area * self.luminance
    }
}

/// A cone of directions: every direction within θ_o of `axis` (cos_o = cos θ_o).
#[derive(Clone, Copy, Debug)]
struct Cone {
    axis: Vec3,
    cos_o: f32,
}

impl Cone {
    const ALL: Cone = Cone { axis: Vec3::Z, cos_o: -1.0 };

    /// The smallest cone holding both (pbrt-v4's `DirectionCone::Union`).
    fn union(a: Option<Cone>, b: Cone) -> Cone {
        let Some(a) = a else { return b };
        let (ta, tb) = (a.cos_o.clamp(-1.0, 1.0).acos(), b.cos_o.clamp(-1.0, 1.0).acos());
        let td = a.axis.dot(b.axis).clamp(-1.0, 1.0).acos();
        if (td + tb).min(PI) <= ta {
            return a;
        }
        if (td + ta).min(PI) <= tb {
            return b;
        }
        let to = 0.5 * (ta + td + tb);
        if to >= PI {
            return Cone::ALL;
        }
        let wr = a.axis.cross(b.axis);
        if wr.length_squared() < 1e-12 {
            return Cone::ALL;
        }
        let axis = glam::Quat::from_axis_angle(wr.normalize(), to - ta) * a.axis;
        // Rounding must not leave either cone outside: widen by a little.
        Cone { axis: axis.normalize(), cos_o: (to + 1e-4).min(PI).cos() }
    }
}

/// What a set of emitters spans: box, cone and power.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    lo: Vec3,
    hi: Vec3,
    cone: Option<Cone>,
    power: f32,
}

impl Bounds {
    const EMPTY: Bounds =
        Bounds { lo: Vec3::splat(f32::MAX), hi: Vec3::splat(f32::MIN), cone: None, power: 0.0 };

    fn of(e: &Emitter) -> Bounds {
        let mut b = Bounds::EMPTY;
        for v in &e.vertices {
            b.lo = b.lo.min(*v);
            b.hi = b.hi.max(*v);
        }
        for n in &e.normals {
            b.cone = Some(Cone::union(b.cone, Cone { axis: *n, cos_o: 1.0 }));
        }
        b.power = e.power();
        b
    }

    /// The node of these bounds under `parent` (its child and area still to set).
    fn node(&self, parent: u32) -> LightNode {
        let cone = self.cone.unwrap_or(Cone::ALL);
        LightNode {
            centre: (0.5 * (self.lo + self.hi)).to_array(),
            radius: 0.5 * (self.hi - self.lo).length(),
            axis: cone.axis.to_array(),
            cos_o: cone.cos_o,
            sin_o: (1.0 - cone.cos_o * cone.cos_o).max(0.0).sqrt(),
            power: self.power,
            parent,
            ..Default::default()
        }
    }

    fn add(&mut self, o: &Bounds) {
        self.lo = self.lo.min(o.lo);
        self.hi = self.hi.max(o.hi);
        if let Some(c) = o.cone {
            self.cone = Some(Cone::union(self.cone, c));
        }
        self.power += o.power;
    }

    /// Conty Estevez and Kulla's eq. (13) without the regularisation: power x the cone's
    /// orientation measure M_Ω x the box's surface area.
    fn cost(&self) -> f32 {
        let Some(c) = self.cone else { return 0.0 };
        let d = (self.hi - self.lo).max(Vec3::ZERO);
        let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
        let to = c.cos_o.clamp(-1.0, 1.0).acos();
        let tw = (to + 0.5 * PI).min(PI);
        let (so, co) = to.sin_cos();
        let m = 2.0 * PI * (1.0 - co)
            + 0.5 * PI * (2.0 * tw * so - (to - 2.0 * tw).cos() - 2.0 * to * so + co);
        self.power * m * area.max(1e-12)
    }
}

/// The tree, nodes in depth-first order (the root first; a node's left child follows it).
#[derive(Clone, Debug, Default)]
pub struct LightTree {
    pub nodes: Vec<LightNode>,
    /// The leaf of each emitter, in the order they were given.
    pub leaf_of: Vec<u32>,
    /// The root's bounds (what a join of two trees unites).
    root: Option<Bounds>,
}

impl LightTree {
    /// Build over `emitters` (those of no power are left out: no sample could bring their
    /// light, and a BSDF sample that hits one weighs 1).
    pub fn build(emitters: &[Emitter]) -> LightTree {
        let mut tree =
            LightTree { nodes: vec![], leaf_of: vec![u32::MAX; emitters.len()], root: None };
        let mut prims: Vec<(usize, Bounds)> = emitters
            .iter()
            .enumerate()
            .filter(|(_, e)| e.power() > 0.0 && e.power().is_finite())
            .map(|(i, e)| (i, Bounds::of(e)))
            .collect();
        if prims.is_empty() {
            return tree;
        }
        // (range of prims, parent, whether it is its parent's right child, depth)
        let mut todo = vec![(0..prims.len(), 0u32, false, 0usize)];
        while let Some((range, parent, right, depth)) = todo.pop() {
            let me = tree.nodes.len() as u32;
            if right {
                tree.nodes[parent as usize].child = me;
            }
            let mut b = Bounds::EMPTY;
            prims[range.clone()].iter().for_each(|(_, p)| b.add(p));
            if me == 0 {
                tree.root = Some(b);
            }
            let mut node = b.node(parent);
            if range.len() == 1 {
                let e = prims[range.start].0;
                node.child = LEAF | emitters[e].slot;
                node.area = emitters[e].area;
                tree.leaf_of[e] = me;
                tree.nodes.push(node);
                continue;
            }
            tree.nodes.push(node);
            let mid = range.start + split(&mut prims[range.clone()], &b, depth < COST_DEPTH);
            // The left child next: it is taken first.
            todo.push((mid..range.end, me, true, depth + 1));
            todo.push((range.start..mid, me, false, depth + 1));
        }
        tree
    }

    /// Build over `emitters`, the first `fixed` of which never move: those get a subtree of
    /// their own, the same at every call, so that their leaves keep their numbers while the
    /// others' subtree is built again each frame (the triangles that name their leaves are
    /// uploaded again only where they move).
    pub fn build_split(emitters: &[Emitter], fixed: usize) -> LightTree {
        let (a, b) = (Self::build(&emitters[..fixed]), Self::build(&emitters[fixed..]));
        if a.nodes.is_empty() || b.nodes.is_empty() {
            return Self::build(emitters);
        }
        let (Some(mut root), Some(other)) = (a.root, b.root) else {
            return Self::build(emitters);
        };
        root.add(&other);
        let right = 1 + a.nodes.len() as u32;
        let mut tree = LightTree {
            nodes: vec![LightNode { child: right, ..root.node(0) }],
            leaf_of: vec![],
            root: Some(root),
        };
        for (part, base) in [(&a, 1u32), (&b, right)] {
            tree.nodes.extend(part.nodes.iter().enumerate().map(|(i, n)| {
                let mut n = *n;
                n.parent = if i == 0 { 0 } else { n.parent + base };
                if n.child & LEAF == 0 {
                    n.child += base;
                }
                n
            }));
            tree.leaf_of.extend(part.leaf_of.iter().map(|&l| l.saturating_add(base)));
        }
        tree
    }

    /// Choose a leaf for point p with normal n (zero: none) from u in [0, 1): the leaf and its
    /// probability, or None where no emitter can light p.
    pub fn sample(&self, p: Vec3, n: Vec3, mut u: f32) -> Option<(u32, f32)> {
        let mut i = 0usize;
        let mut pmf = 1.0;
        while self.nodes.get(i)?.child & LEAF == 0 {
            let (l, r) = (i + 1, self.nodes[i].child as usize);
            let pl = left_probability(&self.nodes[l], &self.nodes[r], p, n)?;
            if u < pl {
                u = (u / pl).min(ONE_BELOW);
                i = l;
                pmf *= pl;
            } else {
                u = ((u - pl) / (1.0 - pl)).min(ONE_BELOW);
                i = r;
                pmf *= 1.0 - pl;
            }
        }
        Some((i as u32, pmf))
    }

    /// The probability that [`LightTree::sample`] chooses `leaf` at p, n.
    pub fn pmf(&self, leaf: u32, p: Vec3, n: Vec3) -> f32 {
        let mut pmf = 1.0;
        let mut i = leaf as usize;
        while i != 0 {
            let parent = self.nodes[i].parent as usize;
            let (l, r) = (parent + 1, self.nodes[parent].child as usize);
            let Some(pl) = left_probability(&self.nodes[l], &self.nodes[r], p, n) else {
                return 0.0;
            };
            pmf *= if i == l { pl } else { 1.0 - pl };
            i = parent;
        }
        pmf
    }

    /// The deepest leaf's depth (the root's is 0).
    pub fn depth(&self) -> usize {
        depth(&self.nodes)
    }
}

/// The deepest leaf's depth in a tree's `nodes` (parents come before their children).
pub fn depth(nodes: &[LightNode]) -> usize {
    let mut depth = vec![0usize; nodes.len()];
    for i in 1..nodes.len() {
        depth[i] = depth[nodes[i].parent as usize] + 1;
    }
    depth.into_iter().max().unwrap_or(0)
}

/// The largest f32 below 1.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

fn left_probability(l: &LightNode, r: &LightNode, p: Vec3, n: Vec3) -> Option<f32> {
    let (il, ir) = (importance(l, p, n), importance(r, p, n));
    (il + ir > 0.0).then(|| il / (il + ir))
}

/// cos(max(0, a - b)) from the sines and cosines of a and b.
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b { 1.0 } else { cos_a * cos_b + sin_a * sin_b }
}

/// sin(max(0, a - b)).
fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b { 0.0 } else { sin_a * cos_b - cos_a * sin_b }
}

/// A node's importance to point p with normal n (zero: no normal term): power x cos θ' / d²
/// x cos θ'_i (Conty Estevez and Kulla eq. (3)), where θ' bounds from below the angle between
/// any emitter's normal and its direction to p, and θ'_i that between n (either side) and any
/// direction to the node; d² is at least the node's bounding sphere's radius², so the
/// importance of a node around p stays finite. Zero only where no emitter of the node faces p.
pub fn importance(node: &LightNode, p: Vec3, n: Vec3) -> f32 {
    let v = p - Vec3::from(node.centre);
    let dist2 = v.length_squared();
    let r2 = node.radius * node.radius;
    if dist2 <= r2 {
        // p within the bounding sphere: every direction may reach it.
        return node.power / r2.max(1e-12);
    }
    let inv_dist = dist2.sqrt().recip();
    let wi = v * inv_dist;
    let sin_b = node.radius * inv_dist;
    let cos_b = (1.0 - sin_b * sin_b).max(0.0).sqrt();
    let cos_w = Vec3::from(node.axis).dot(wi);
    let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
    let (cos_o, sin_o) = (node.cos_o, node.sin_o);
    let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
    let sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
    let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
    // θ_e = π/2: beyond it no one-sided emitter sends light.
    if cos_p <= 0.0 {
        return 0.0;
    }
    let mut imp = node.power * cos_p / dist2;
    if n != Vec3::ZERO {
        let cos_i = wi.dot(n).abs();
        let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
        imp *= cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
    }
    imp.max(0.0)
}

/// Sort `prims` into two non-empty halves and return the first's length: at the cheapest of
/// the binned splits on the three axes (`by_cost`), else at the median of the widest axis.
fn split(prims: &mut [(usize, Bounds)], b: &Bounds, by_cost: bool) -> usize {
    let centre = |p: &Bounds| 0.5 * (p.lo + p.hi);
    let (mut clo, mut chi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for (_, p) in prims.iter() {
        clo = clo.min(centre(p));
        chi = chi.max(centre(p));
    }
    let extent = chi - clo;
    let widest = extent.max_element();
    let mut best: Option<(f32, usize, usize)> = None; // cost, axis, bins on the left
    if by_cost && widest > 0.0 {
        let box_extent = (b.hi - b.lo).max_element();
        for axis in 0..3 {
            if extent[axis] <= 0.0 {
                continue;
            }
            let mut bins = [Bounds::EMPTY; BINS];
            for (_, p) in prims.iter() {
                bins[bin(centre(p)[axis], clo[axis], extent[axis])].add(p);
            }
            // Eq. (13)'s regularisation: thin boxes split across their long side.
            let k_r = box_extent / (b.hi[axis] - b.lo[axis]).max(1e-12);
            for cut in 1..BINS {
                let (mut l, mut r) = (Bounds::EMPTY, Bounds::EMPTY);
                bins[..cut].iter().for_each(|x| l.add(x));
                bins[cut..].iter().for_each(|x| r.add(x));
                if l.cone.is_none() || r.cone.is_none() {
                    continue;
                }
                let cost = k_r * (l.cost() + r.cost());
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, cut));
                }
            }
        }
    }
    if let Some((_, axis, cut)) = best {
        let left = |p: &Bounds| bin(centre(p)[axis], clo[axis], extent[axis]) < cut;
        let mut mid = 0;
        for i in 0..prims.len() {
            if left(&prims[i].1) {
                prims.swap(i, mid);
                mid += 1;
            }
        }
        if mid > 0 && mid < prims.len() {
            return mid;
        }
    }
    let axis = if widest > 0.0 { extent.max_position() } else { 0 };
    let mid = prims.len() / 2;
    prims.select_nth_unstable_by(mid, |a, b| centre(&a.1)[axis].total_cmp(&centre(&b.1)[axis]));
    mid
}

fn bin(x: f32, lo: f32, extent: f32) -> usize {
    (((x - lo) / extent * BINS as f32) as usize).min(BINS - 1)
}

#[cfg(test)]
mod tests;
