// Traversal of obvhs's compressed 8-wide BVH (Ylitie et al. 2017, "Efficient Incoherent Ray
// Traversal on GPUs Through Compressed Wide BVHs", Algorithm 1 with the octant-ordered child
// priorities). A node is 80 bytes = five vec4u:
//   [0] p.xyz (f32 bits), e0 | e1 << 8 | e2 << 16 | imask << 24
//   [1] child_base_idx, primitive_base_idx, child_meta[0..4], child_meta[4..8]
//   [2] child_min_x (8 bytes), child_max_x (8 bytes); [3] the same for y; [4] for z.

var<storage, read> cw_nodes: array<vec4u>;

fn cw_byte(lo: u32, hi: u32, i: u32) -> u32 {
    let w = select(hi, lo, i < 4u);
    return (w >> ((i & 3u) * 8u)) & 0xffu;
}

// Bit mask of hit children: inner children in the high byte (bit = 24 + traversal priority),
// leaf triangles in the low 24 bits.
fn cw_intersect(node: u32, o: vec3f, inv_d: vec3f, oct_inv4: u32, tmax: f32) -> u32 {
    let n0 = cw_nodes[node * 5u];
    let n1 = cw_nodes[node * 5u + 1u];
    let nx = cw_nodes[node * 5u + 2u];
    let ny = cw_nodes[node * 5u + 3u];
    let nz = cw_nodes[node * 5u + 4u];
    let p = bitcast<vec3f>(n0.xyz);
    let e = vec3u(n0.w & 0xffu, (n0.w >> 8u) & 0xffu, (n0.w >> 16u) & 0xffu);
    let extent = bitcast<vec3f>(e << vec3u(23u));
    let adj_inv = extent * inv_d;
    let adj_o = (p - o) * inv_d;
    let neg = inv_d < vec3f(0.0);
    var mask = 0u;
    for (var c = 0u; c < 8u; c++) {
        let cmeta = cw_byte(n1.z, n1.w, c);
        if cmeta == 0u {
            continue;
        }
        let qlo = vec3f(f32(cw_byte(nx.x, nx.y, c)), f32(cw_byte(ny.x, ny.y, c)), f32(cw_byte(nz.x, nz.y, c)));
        let qhi = vec3f(f32(cw_byte(nx.z, nx.w, c)), f32(cw_byte(ny.z, ny.w, c)), f32(cw_byte(nz.z, nz.w, c)));
        let t0 = select(qlo, qhi, neg) * adj_inv + adj_o;
        let t1 = select(qhi, qlo, neg) * adj_inv + adj_o;
        let tn = max(max3(t0), 0.0);
        let tf = min(min(min(t1.x, t1.y), t1.z), tmax);
        if tn <= tf {
            let is_inner = (cmeta & (cmeta << 1u) & 0x10u) != 0u;
            let bits = (cmeta >> 5u) & 7u;
            let index = select(cmeta & 0x1fu, (cmeta ^ (oct_inv4 & 0xffu)) & 0x1fu, is_inner);
            mask |= bits << index;
        }
    }
    return mask;
}

const CW_STACK: u32 = 32u;

fn traverse(o: vec3f, d: vec3f, tmax_in: f32, any_hit: bool) -> Hit {
    var hit = miss();
    var tmax = min(tmax_in, INF);
    let inv_d = safe_inverse(d);
    let oct_inv4 = select(0x04040404u, 0u, d.x < 0.0) | select(0x02020202u, 0u, d.y < 0.0)
        | select(0x01010101u, 0u, d.z < 0.0);
    var stack: array<vec2u, 32>;
    var sp = 0u;
    var cur = vec2u(0u, 0x80000000u);
    var prim = vec2u(0u);
    loop {
        while prim.y != 0u {
            let k = firstLeadingBit(prim.y);
            prim.y &= ~(1u << k);
            let slot = prim.x + k;
            let r = intersect_triangle(o, d, slot, tmax);
            if r.x < tmax && alpha_accept(slot, r.yz) {
                tmax = r.x;
                hit = Hit(r.x, slot, r.yz);
                if any_hit {
                    return hit;
                }
            }
        }
        if (cur.y & 0xff000000u) != 0u {
            let hits = cur.y;
            let off = firstLeadingBit(hits);
            cur.y &= ~(1u << off);
            if (cur.y & 0xff000000u) != 0u && sp < CW_STACK {
                stack[sp] = cur;
                sp += 1u;
            }
            let slot_index = (off - 24u) ^ (oct_inv4 & 0xffu);
            let rel = countOneBits(hits & ~(0xffffffffu << slot_index));
            let child = cur.x + rel;
            let m = cw_intersect(child, o, inv_d, oct_inv4, tmax);
            let c1 = cw_nodes[child * 5u + 1u];
            let imask = cw_nodes[child * 5u].w >> 24u;
            cur = vec2u(c1.x, (m & 0xff000000u) | imask);
            prim = vec2u(c1.y, m & 0x00ffffffu);
        } else {
            cur = vec2u(0u);
        }
        if prim.y == 0u && (cur.y & 0xff000000u) == 0u {
            if sp == 0u {
                break;
            }
            sp -= 1u;
            cur = stack[sp];
        }
    }
    return hit;
}
