// A scene with instances: after the scene's own trees (world-space triangles), a binary tree
// over the instanced objects' world boxes (engine/src/gpu/prepare/instances.rs, refit when
// they move), of binary nodes (Bvh2Node, common/geometry.wgsl), whose leaves' ranges index
// tlas_order_texels (objects, four to a texel). A ray that enters an object's box is carried
// into its mesh's space by the object's inverse transform and traverses the mesh's tree from
// its root; the direction is carried unnormalised, so t is the same along both rays.
var tlas_texels: texture_2d<u32>;
var tlas_order_texels: texture_2d<u32>;

fn traverse(o: vec3f, d: vec3f, tmax_in: f32, any_hit: bool) -> Hit {
    var hit = traverse_from(0u, DYNAMIC_ROOT, o, d, tmax_in, any_hit);
    if any_hit && hit.tri != NO_HIT {
        return hit;
    }
    var tmax = min(min(tmax_in, INF), hit.t);
    let inv_d = safe_inverse(d);
    // TLAS_STACK comes from the scene (PreparedScene::tlas_stack).
    var stack: array<u32, TLAS_STACK>;
    var sp = 0u;
    // One stack for every instance's tree (traverse_with).
    var mesh_stack: TraversalStack;
    var item = 0u;
    var is_leaf = false;
    var count = 0u;
    loop {
        if is_leaf {
            for (var i = 0u; i < count; i++) {
                let k = item + i;
                let inst = textureLoad(tlas_order_texels, texel_at(k / 4u), 0)[k % 4u];
                let x = mesh_from_world(inst);
                var h = traverse_with(&mesh_stack, inst_root(inst), 0xffffffffu, affine_point(x, o), affine_vector(x, d), tmax, any_hit);
                if h.tri != NO_HIT && h.t < tmax {
                    tmax = h.t;
                    h.inst = inst;
                    hit = h;
                    if any_hit {
                        return hit;
                    }
                }
            }
            is_leaf = false;
        } else {
            let n = bvh2_node_in(tlas_texels, item);
            let tl = intersect_box(o, inv_d, n.lmin, n.lmax, tmax);
            let tr = intersect_box(o, inv_d, n.rmin, n.rmax, tmax);
            let hl = tl < INF;
            let hr = tr < INF;
            if hl || hr {
                // The nearer child first; the other waits on the stack.
                var first = vec2u(n.l_index, n.l_count);
                var second = vec2u(n.r_index, n.r_count);
                if !hl || (hr && tr < tl) {
                    first = vec2u(n.r_index, n.r_count);
                    second = vec2u(n.l_index, n.l_count);
                }
                if hl && hr && sp < TLAS_STACK {
                    stack[sp] = second.x | (min(second.y, 255u) << 24u);
                    sp += 1u;
                }
                item = first.x;
                count = first.y;
                is_leaf = count > 0u;
                continue;
            }
        }
        if sp == 0u {
            break;
        }
        sp -= 1u;
        let s = stack[sp];
        item = s & 0xffffffu;
        count = s >> 24u;
        is_leaf = count > 0u;
    }
    return hit;
}
