// Closest hits for a list of rays: the BVH check against obvhs's CPU traversal, and the rays/s
// benchmark. Rays: (origin, tmax), (direction, 0). Hits: (t, input triangle index, b1, b2).

struct RaycastParams {
    count: u32,
    any_hit: u32,
    pad0: u32,
    pad1: u32,
}

var<uniform> params: RaycastParams;
var<storage, read> rays: array<vec4f>;
var<storage, read_write> hits: array<vec4f>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let i = gid.x + gid.y * 65535u * 64u;
    if i >= params.count {
        return;
    }
    let o = rays[i * 2u];
    let d = rays[i * 2u + 1u];
    let h = traverse(o.xyz, d.xyz, o.w, params.any_hit != 0u);
    if h.tri == NO_HIT {
        hits[i] = vec4f(-1.0, bitcast<f32>(NO_HIT), 0.0, 0.0);
    } else {
        hits[i] = vec4f(h.t, tris[h.tri * 3u + 1u].w, h.b.x, h.b.y);
    }
}
