// One level of a CWBVH refit, deepest level first: each node's child boxes from its leaves'
// triangles (both shutter ends) or its inner children's exact boxes, then quantized again as
// obvhs's conversion quantizes them (Ylitie et al. 2017 §3.1: the node's origin is its box's
// minimum, its per-axis scale the power of two that spans the box in 255 steps, child planes
// rounded outwards). The same topology and leaves as accel/refit.rs's CPU refit. Each node also
// writes its surface-area cost (its box, and each leaf child's box times its triangles), which
// accel/refit_cost.wgsl sums.
//
// A node is 20 words (shaders/common/cwbvh.wgsl): p.xyz, e bytes | imask << 24, child base,
// primitive base, child_meta (2 words), child min/max x, y, z (2 words each).

struct RefitParams {
    first: u32,
    count: u32,
    // The moving part's first node and slot among the scene's (its nodes' references are
    // global).
    node_base: u32,
    slot_base: u32,
    // 1 where `posed_open` holds the shutter's open ends.
    open: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

var<uniform> refit_params: RefitParams;
var<storage, read> level_nodes: array<u32>;
var<storage, read> tris: array<vec4f>;
var<storage, read> posed_open: array<vec4f>;
var<storage, read_write> refit_nodes: array<u32>;
// Per node its exact box: min, max.
var<storage, read_write> exact: array<vec4f>;
var<storage, read_write> node_cost: array<f32>;

fn half_area(lo: vec3f, hi: vec3f) -> f32 {
    let d = max(hi - lo, vec3f(0.0));
    return d.x * d.y + d.y * d.z + d.z * d.x;
}

fn byte_of(words: vec2u, c: u32) -> u32 {
    return (words[c >> 2u] >> ((c & 3u) * 8u)) & 0xffu;
}

// The smallest power of two e with 255 e >= x (x > 0, finite).
fn scale_for(x: f32) -> f32 {
    let q = max(x, 1e-20) / 255.0;
    let b = bitcast<u32>(q);
    var e = bitcast<f32>((b & 0x7f800000u) + select(0u, 0x00800000u, (b & 0x007fffffu) != 0u));
    if e * 255.0 < x {
        e *= 2.0;
    }
    return e;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if gid.x >= refit_params.count {
        return;
    }
    let node = level_nodes[refit_params.first + gid.x];
    let b = node * 20u;
    let imask = refit_nodes[b + 3u] >> 24u;
    let child_base = refit_nodes[b + 4u];
    let prim_base = refit_nodes[b + 5u];
    let metas = vec2u(refit_nodes[b + 6u], refit_nodes[b + 7u]);
    var lo: array<vec3f, 8>;
    var hi: array<vec3f, 8>;
    var box_lo = vec3f(3.0e38);
    var box_hi = vec3f(-3.0e38);
    var cost = 0.0;
    for (var c = 0u; c < 8u; c++) {
        let m = byte_of(metas, c);
        var l = vec3f(3.0e38);
        var h = vec3f(-3.0e38);
        if m != 0u {
            if (imask & (1u << c)) == 0u {
                let first = prim_base + (m & 31u);
                let count = countOneBits(m & 0xe0u);
                for (var k = 0u; k < count; k++) {
                    let s = first + k;
                    for (var v = 0u; v < 3u; v++) {
                        let p = tris[s * 3u + v].xyz;
                        l = min(l, p);
                        h = max(h, p);
                        if refit_params.open != 0u {
                            let q = posed_open[(s - refit_params.slot_base) * 3u + v].xyz;
                            l = min(l, q);
                            h = max(h, q);
                        }
                    }
                }
                cost += half_area(l, h) * f32(count);
            } else {
                let slot = (m & 31u) - 24u;
                let rel = countOneBits(imask & ~(0xffffffffu << slot));
                let child = child_base + rel - refit_params.node_base;
                l = exact[child * 2u].xyz;
                h = exact[child * 2u + 1u].xyz;
            }
            box_lo = min(box_lo, l);
            box_hi = max(box_hi, h);
        }
        lo[c] = l;
        hi[c] = h;
    }
    exact[node * 2u] = vec4f(box_lo, 0.0);
    exact[node * 2u + 1u] = vec4f(box_hi, 0.0);
    node_cost[node] = cost + half_area(box_lo, box_hi);
    let ext = box_hi - box_lo;
    let e = vec3f(scale_for(ext.x), scale_for(ext.y), scale_for(ext.z));
    let rcp = 1.0 / e;
    let eb = bitcast<vec3u>(e) >> vec3u(23u);
    refit_nodes[b] = bitcast<u32>(box_lo.x);
    refit_nodes[b + 1u] = bitcast<u32>(box_lo.y);
    refit_nodes[b + 2u] = bitcast<u32>(box_lo.z);
    refit_nodes[b + 3u] = eb.x | (eb.y << 8u) | (eb.z << 16u) | (imask << 24u);
    // Planes: min x, max x, min y, max y, min z, max z, two words each; an empty child keeps
    // its bytes.
    for (var axis = 0u; axis < 3u; axis++) {
        for (var half = 0u; half < 2u; half++) {
            var words = vec2u(refit_nodes[b + 8u + axis * 4u], refit_nodes[b + 9u + axis * 4u]);
            var words_hi = vec2u(refit_nodes[b + 10u + axis * 4u], refit_nodes[b + 11u + axis * 4u]);
            for (var c = half * 4u; c < half * 4u + 4u; c++) {
                if byte_of(metas, c) == 0u {
                    continue;
                }
                let ql = u32(clamp(floor((lo[c][axis] - box_lo[axis]) * rcp[axis]), 0.0, 255.0));
                let qh = u32(clamp(ceil((hi[c][axis] - box_lo[axis]) * rcp[axis]), 0.0, 255.0));
                let shift = (c & 3u) * 8u;
                let keep = ~(0xffu << shift);
                words[half] = (words[half] & keep) | (ql << shift);
                words_hi[half] = (words_hi[half] & keep) | (qh << shift);
            }
            refit_nodes[b + 8u + axis * 4u + half] = words[half];
            refit_nodes[b + 10u + axis * 4u + half] = words_hi[half];
        }
    }
}
