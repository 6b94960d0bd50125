// The light tree over the emissive triangles (engine/src/accel/light_tree.rs: Conty Estevez and
// Kulla 2018, "Importance sampling of many lights with adaptive tree splitting"): from the root,
// each step takes a child with probability proportional to its importance to the shaded point
// and normal. Nodes in depth-first order; a node's left child follows it. Binds `emitters`
// alone, so that tests/light_tree.rs runs it against the CPU walk.

struct LightNode {
    // The sphere around the emitters' box.
    centre: vec3f,
    radius: f32,
    axis: vec3f,
    // Cosine and sine of the emission cone's half-angle around `axis`.
    cos_o: f32,
    sin_o: f32,
    // Sum of area x luminance(emission) below (one-sided power over pi).
    power: f32,
    // Interior: the right child. Leaf: LIGHT_LEAF | triangle slot.
    child: u32,
    parent: u32,
    // A leaf's triangle area.
    area: f32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

const LIGHT_LEAF: u32 = 0x80000000u;
// The tree's build bounds its depth (light_tree.rs: 40 levels by cost, then medians).
const LIGHT_TREE_MAX_DEPTH: u32 = 64u;
// The largest f32 below 1.
const LIGHT_U_MAX: f32 = 0.99999994;

var<storage, read> emitters: array<LightNode>;

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

// The probability of node i's left child at p, n; negative where neither child can light p.
fn light_left_probability(i: u32, p: vec3f, n: vec3f) -> f32 {
    let il = light_importance(emitters[i + 1u], p, n);
    let ir = light_importance(emitters[emitters[i].child], p, n);
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
        if (emitters[i].child & LIGHT_LEAF) != 0u {
            return LeafChoice(i, pmf);
        }
        let pl = light_left_probability(i, p, n);
        if pl < 0.0 {
            break;
        }
        if u < pl {
            u = min(u / pl, LIGHT_U_MAX);
            i = i + 1u;
            pmf *= pl;
        } else {
            u = min((u - pl) / (1.0 - pl), LIGHT_U_MAX);
            i = emitters[i].child;
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
        let parent = emitters[i].parent;
        let pl = light_left_probability(parent, p, n);
        if pl < 0.0 {
            return 0.0;
        }
        pmf *= select(1.0 - pl, pl, i == parent + 1u);
        i = parent;
    }
    return pmf;
}
