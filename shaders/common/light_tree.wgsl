// The light tree over the emissive triangles (engine/src/accel/light_tree.rs: Conty Estevez and
// Kulla 2018, "Importance sampling of many lights with adaptive tree splitting"): from the root,
// each step takes a child with probability proportional to its importance to the shaded point
// and normal. Nodes in depth-first order; a node's left child follows it. Binds
// `emitter_texels` alone, so that tests/light_tree.rs runs it against the CPU walk.

// Node i is four texels of `emitter_texels` (rows of 4096 texels, 1024 nodes; the layout of
// light_tree.rs `LightNode`, as words):
//   0: centre.xyz, radius: the sphere around the emitters' box;
//   1: axis.xyz, cos θ_o: the emission cone around `axis`;
//   2: sin θ_o, power (sum of area x luminance below), child, parent. Interior: `child` is the
//      right child (the left one follows the node). Leaf: LIGHT_LEAF | triangle slot;
//   3: a leaf's triangle area.
// Texels rather than a storage buffer: the software driver reads a buffer at per-lane addresses
// one word and one lane at a time, and the walk reads two nodes a level (engine/src/gpu/texels.rs).
var emitter_texels: texture_2d<u32>;

const LIGHT_LEAF: u32 = 0x80000000u;
// The tree's build bounds its depth (light_tree.rs: 40 levels by cost, then medians).
const LIGHT_TREE_MAX_DEPTH: u32 = 64u;
// The largest f32 below 1.
const LIGHT_U_MAX: f32 = 0.99999994;
// Nodes a texel row holds: engine/src/gpu/texels.rs TEXEL_ROW / 4.
const LIGHT_NODES_ROW_SHIFT: u32 = 10u;

fn light_texel(i: u32, k: u32) -> vec4u {
    let row = i >> LIGHT_NODES_ROW_SHIFT;
    let x = ((i & ((1u << LIGHT_NODES_ROW_SHIFT) - 1u)) << 2u) | k;
    return textureLoad(emitter_texels, vec2u(x, row), 0);
}

// What the walk reads of a node: its bounds (texels 0 to 2).
struct LightNode {
    centre: vec3f,
    radius: f32,
    axis: vec3f,
    cos_o: f32,
    sin_o: f32,
    power: f32,
    child: u32,
    parent: u32,
}

fn light_node(i: u32) -> LightNode {
    let a = light_texel(i, 0u);
    let b = light_texel(i, 1u);
    let c = light_texel(i, 2u);
    return LightNode(
        bitcast<vec3f>(a.xyz),
        bitcast<f32>(a.w),
        bitcast<vec3f>(b.xyz),
        bitcast<f32>(b.w),
        bitcast<f32>(c.x),
        bitcast<f32>(c.y),
        c.z,
        c.w,
    );
}

fn light_child(i: u32) -> u32 {
    return light_texel(i, 2u).z;
}

fn light_parent(i: u32) -> u32 {
    return light_texel(i, 2u).w;
}

// A leaf's triangle area.
fn light_leaf_area(i: u32) -> f32 {
    return bitcast<f32>(light_texel(i, 3u).x);
}

// cos(max(0, a - b)) and sin(max(0, a - b)) from the sines and cosines of a and b.
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        return 1.0;
    }
    return cos_a * cos_b + sin_a * sin_b;
}

fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        return 0.0;
    }
    return sin_a * cos_b - cos_a * sin_b;
}

// Conty Estevez and Kulla eq. (3), bounded as pbrt-v4 does: power x cos θ' / d² x cos θ'_i,
// zero only where no emitter of the node faces p (light_tree.rs `importance`). n = 0: no
// normal term.
fn light_importance(node: LightNode, p: vec3f, n: vec3f) -> f32 {
    let v = p - node.centre;
    let dist2 = dot(v, v);
    let r2 = node.radius * node.radius;
    if dist2 <= r2 {
        return node.power / max(r2, 1e-12);
    }
    let inv_dist = inverseSqrt(dist2);
    let wi = v * inv_dist;
    let sin_b = node.radius * inv_dist;
    let cos_b = sqrt(max(1.0 - sin_b * sin_b, 0.0));
    let cos_w = dot(node.axis, wi);
    let sin_w = sqrt(max(1.0 - cos_w * cos_w, 0.0));
    let cos_x = cos_sub_clamped(sin_w, cos_w, node.sin_o, node.cos_o);
    let sin_x = sin_sub_clamped(sin_w, cos_w, node.sin_o, node.cos_o);
    let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
    if cos_p <= 0.0 {
        return 0.0;
    }
    var imp = node.power * cos_p / dist2;
    if any(n != vec3f(0.0)) {
        let cos_i = abs(dot(wi, n));
        let sin_i = sqrt(max(1.0 - cos_i * cos_i, 0.0));
        imp *= cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
    }
    return max(imp, 0.0);
}

// The probability of interior node i's left child at p, n (its right child is `right`);
// negative where neither child can light p.
fn light_left_probability(i: u32, right: u32, p: vec3f, n: vec3f) -> f32 {
    let il = light_importance(light_node(i + 1u), p, n);
    let ir = light_importance(light_node(right), p, n);
    if il + ir <= 0.0 {
        return -1.0;
    }
    return il / (il + ir);
}

struct LeafChoice {
    node: u32,
    // 0 where the walk found no light.
    pmf: f32,
}

// The walk down from the root with one number u in [0, 1), rescaled at each step.
fn light_tree_sample(p: vec3f, n: vec3f, u0: f32) -> LeafChoice {
    var i = 0u;
    var pmf = 1.0;
    var u = u0;
    for (var depth = 0u; depth < LIGHT_TREE_MAX_DEPTH; depth++) {
        let child = light_child(i);
        if (child & LIGHT_LEAF) != 0u {
            return LeafChoice(i, pmf);
        }
        let pl = light_left_probability(i, child, p, n);
        if pl < 0.0 {
            break;
        }
        if u < pl {
            u = min(u / pl, LIGHT_U_MAX);
            i = i + 1u;
            pmf *= pl;
        } else {
            u = min((u - pl) / (1.0 - pl), LIGHT_U_MAX);
            i = child;
            pmf *= 1.0 - pl;
        }
    }
    return LeafChoice(0u, 0.0);
}

// The probability that light_tree_sample at p, n chooses `leaf`: the walk up to the root.
fn light_tree_pmf(leaf: u32, p: vec3f, n: vec3f) -> f32 {
    var pmf = 1.0;
    var i = leaf;
    for (var depth = 0u; depth < LIGHT_TREE_MAX_DEPTH && i != 0u; depth++) {
        let parent = light_parent(i);
        let pl = light_left_probability(parent, light_child(parent), p, n);
        if pl < 0.0 {
            return 0.0;
        }
        pmf *= select(1.0 - pl, pl, i == parent + 1u);
        i = parent;
    }
    return pmf;
}
