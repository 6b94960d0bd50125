// Traversal of the binary BVH whose nodes hold both children's boxes (engine/src/accel).

// Four texels per node (Bvh2Node, common/geometry.wgsl).
var bvh_texels: texture_2d<u32>;

fn bvh2_node(i: u32) -> Bvh2Node {
    return bvh2_node_in(bvh_texels, i);
}

// Closest accepted hit along o + t d, t in (0, tmax), in the tree rooted at node `root`, then
// in the one rooted at `second` (none: 0xffffffff). With `any_hit`, the first accepted hit.
// The scene's tree is rooted at node 0; an animated scene's moving objects have a tree of their
// own (engine/src/gpu/prepare/assemble.rs), rooted at DYNAMIC_ROOT; a mesh stored once for its
// instances has one at its own root (common/tlas.wgsl).
alias TraversalStack = array<u32, TRAVERSAL_STACK>;

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
    // TRAVERSAL_STACK comes from the scene (engine/src/accel, traversal_stack).
    var sp = 0u;
    // The second root waits at the stack's bottom until the first tree is done.
    if second != 0xffffffffu {
        (*stack)[0] = second;
        sp = 1u;
    }
    // Items are (index, count) pairs packed: leaves have their count in the high 8 bits.
    var item = root;
    var is_leaf = false;
    var count = 0u;
    loop {
        if is_leaf {
            for (var i = 0u; i < count; i++) {
                let slot = item + i;
                let r = intersect_triangle(o, d, slot, tmax);
                if r.x < tmax && alpha_accept(slot, r.yz, ray) {
                    tmax = r.x;
                    hit = Hit(r.x, slot, r.yz, NO_INSTANCE);
                    if any_hit {
                        return hit;
                    }
                }
            }
            is_leaf = false;
        } else {
            let n = bvh2_node(item);
            let tl = intersect_box(o, inv_d, n.lmin, n.lmax, tmax);
            let tr = intersect_box(o, inv_d, n.rmin, n.rmax, tmax);
            let hl = tl < INF;
            let hr = tr < INF;
            if hl || hr {
                // Visit the nearer child first; push the other.
                var first_i = n.l_index;
                var first_c = n.l_count;
                var second_i = n.r_index;
                var second_c = n.r_count;
                if !hl || (hr && tr < tl) {
                    first_i = n.r_index;
                    first_c = n.r_count;
                    second_i = n.l_index;
                    second_c = n.l_count;
                }
                if hl && hr && sp < TRAVERSAL_STACK {
                    (*stack)[sp] = second_i | (min(second_c, 255u) << 24u);
                    sp += 1u;
                }
                item = first_i;
                count = first_c;
                is_leaf = first_c > 0u;
                continue;
            }
        }
        if sp == 0u {
            break;
        }
        sp -= 1u;
        let e = (*stack)[sp];
        item = e & 0xffffffu;
        count = e >> 24u;
        is_leaf = count > 0u;
    }
    return hit;
}
