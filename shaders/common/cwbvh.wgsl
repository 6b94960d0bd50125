// Traversal of obvhs's compressed 8-wide BVH (Ylitie et al. 2017, "Efficient Incoherent Ray
// Traversal on GPUs Through Compressed Wide BVHs", Algorithm 1 with the octant-ordered child
// priorities). A node is 80 bytes = five vec4u:
//   [0] p.xyz (f32 bits), e0 | e1 << 8 | e2 << 16 | imask << 24
//   [1] child_base_idx, primitive_base_idx, child_meta[0..4], child_meta[4..8]
//   [2] child_min_x (8 bytes), child_max_x (8 bytes); [3] the same for y; [4] for z.
// Nodes are read as texels (see tri_texels in geometry.wgsl).

var bvh_texels: texture_2d<u32>;

fn cw_node(i: u32) -> vec4u {
    return textureLoad(bvh_texels, texel_at(i), 0);
}

// Bit mask of hit children: inner children in the high byte (bit = 24 + traversal priority),
// leaf triangles in the low 24 bits; then the node's child and primitive base indices and its
// inner-child mask.
fn cw_intersect(node: u32, o: vec3f, inv_d: vec3f, oct_inv4: u32, tmax: f32) -> vec4u {
    let n0 = cw_node(node * 5u);
    let n1 = cw_node(node * 5u + 1u);
    let nx = cw_node(node * 5u + 2u);
    let ny = cw_node(node * 5u + 3u);
    let nz = cw_node(node * 5u + 4u);
    let p = bitcast<vec3f>(n0.xyz);
    let e = vec3u(n0.w & 0xffu, (n0.w >> 8u) & 0xffu, (n0.w >> 16u) & 0xffu);
    let extent = bitcast<vec3f>(e << vec3u(23u));
    let adj_inv = extent * inv_d;
    let adj_o = (p - o) * inv_d;
    let neg = inv_d < vec3f(0.0);
    var mask = 0u;
    // Children 0-3, then 4-7: each word holds one byte per child, unpacked four at a time.
    for (var h = 0u; h < 2u; h++) {
        let first = h == 0u;
        let metas = unpack4xU8(select(n1.w, n1.z, first));
        let qlo_x = vec4f(unpack4xU8(select(nx.y, nx.x, first)));
        let qlo_y = vec4f(unpack4xU8(select(ny.y, ny.x, first)));
        let qlo_z = vec4f(unpack4xU8(select(nz.y, nz.x, first)));
        let qhi_x = vec4f(unpack4xU8(select(nx.w, nx.z, first)));
        let qhi_y = vec4f(unpack4xU8(select(ny.w, ny.z, first)));
        let qhi_z = vec4f(unpack4xU8(select(nz.w, nz.z, first)));
        let tx0 = select(qlo_x, qhi_x, neg.x) * adj_inv.x + adj_o.x;
        let tx1 = select(qhi_x, qlo_x, neg.x) * adj_inv.x + adj_o.x;
        let ty0 = select(qlo_y, qhi_y, neg.y) * adj_inv.y + adj_o.y;
        let ty1 = select(qhi_y, qlo_y, neg.y) * adj_inv.y + adj_o.y;
        let tz0 = select(qlo_z, qhi_z, neg.z) * adj_inv.z + adj_o.z;
        let tz1 = select(qhi_z, qlo_z, neg.z) * adj_inv.z + adj_o.z;
        let tn = max(max(max(tx0, ty0), tz0), vec4f(0.0));
        let tf = min(min(min(tx1, ty1), tz1), vec4f(tmax));
        // An empty child has meta 0.
        let hit = (tn <= tf) & (metas != vec4u(0u));
        let is_inner = (metas & (metas << vec4u(1u)) & vec4u(0x10u)) != vec4u(0u);
        let bits = (metas >> vec4u(5u)) & vec4u(7u);
        let index = select(metas & vec4u(0x1fu), (metas ^ vec4u(oct_inv4 & 0xffu)) & vec4u(0x1fu), is_inner);
        let m = select(vec4u(0u), bits << index, hit);
        mask |= m.x | m.y | m.z | m.w;
    }
    return vec4u(mask, n1.x, n1.y, n0.w >> 24u);
}

// `cur` is a group of a node's children still to visit: (child base, hit bits << 24 | the node's
// inner-child mask, which places each child after the base); the stack holds such groups. Its
// length, TRAVERSAL_STACK, comes from the scene (engine/src/accel, traversal_stack): lavapipe
// pays for every entry at every traversal.

// The closest accepted hit in the tree rooted at node `root`, then in the one rooted at `second`
// (none: 0xffffffff). The scene's tree is rooted at node 0; an animated scene's moving objects
// have a tree of their own (engine/src/gpu/prepare/assemble.rs), rooted at DYNAMIC_ROOT; a mesh
// stored once for its instances has one at its own root (common/tlas.wgsl).
alias TraversalStack = array<vec2u, TRAVERSAL_STACK>;

fn traverse_from(root: u32, second: u32, o: vec3f, d: vec3f, tmax_in: f32, any_hit: bool) -> Hit {
    var stack: TraversalStack;
    return traverse_with(&stack, root, second, o, d, tmax_in, any_hit);
}

// traverse_from on a stack the caller holds: one that traverses many trees per ray (the
// instances', common/tlas.wgsl) declares it once, where each declaration costs lavapipe a
// zero fill of every entry.
fn traverse_with(stack: ptr<function, TraversalStack>, root: u32, second: u32, o: vec3f, d: vec3f, tmax_in: f32, any_hit: bool) -> Hit {
    var hit = miss();
    var tmax = min(tmax_in, INF);
    let inv_d = safe_inverse(d);
    // Stochastic transparency's draw for this ray (common/alpha_mask.wgsl).
    let ray = alpha_ray(o, d);
    let oct_inv4 = select(0x04040404u, 0u, d.x < 0.0) | select(0x02020202u, 0u, d.y < 0.0)
        | select(0x01010101u, 0u, d.z < 0.0);
    var sp = 0u;
    // A root as the one hit child of a virtual parent; the second waits at the stack's bottom
    // until the first tree is done.
    if second != 0xffffffffu {
        (*stack)[0] = vec2u(second, 0x80000000u);
        sp = 1u;
    }
    var cur = vec2u(root, 0x80000000u);
    var prim = vec2u(0u);
    loop {
        while prim.y != 0u {
            let k = firstLeadingBit(prim.y);
            prim.y &= ~(1u << k);
            let slot = prim.x + k;
            let r = intersect_triangle(o, d, slot, tmax);
            if r.x < tmax && alpha_accept(slot, r.yz, ray) {
                tmax = r.x;
                hit = Hit(r.x, slot, r.yz, NO_INSTANCE);
                if any_hit {
                    return hit;
                }
            }
        }
        if (cur.y & 0xff000000u) != 0u {
            let hits = cur.y;
            let off = firstLeadingBit(hits);
            cur.y &= ~(1u << off);
            if (cur.y & 0xff000000u) != 0u && sp < TRAVERSAL_STACK {
                (*stack)[sp] = cur;
                sp += 1u;
            }
            let slot_index = (off - 24u) ^ (oct_inv4 & 0xffu);
            let rel = countOneBits(hits & ~(0xffffffffu << slot_index));
            let child = cur.x + rel;
            let m = cw_intersect(child, o, inv_d, oct_inv4, tmax);
            cur = vec2u(m.y, (m.x & 0xff000000u) | m.w);
            prim = vec2u(m.z, m.x & 0x00ffffffu);
        } else {
            cur = vec2u(0u);
        }
        if prim.y == 0u && (cur.y & 0xff000000u) == 0u {
            if sp == 0u {
                break;
            }
            sp -= 1u;
            cur = (*stack)[sp];
        }
    }
    return hit;
}
