// The edge-stopping features every later stage reads, in one texel: linear depth, its
// screen-space gradient (|dz/dx| + |dz/dy|, one-sided where a silhouette is on one side; depth
// -1 off surfaces) and the G-buffer's octahedral normal.

var out_features: texture_storage_2d<rgba32float, write>;

fn depth_at(q: vec2i) -> f32 {
    if !in_bounds(q) || !has_surface(q) {
        return -1.0;
    }
    let x = position_at(q);
    return dot(x - frame.cam_pos.xyz, frame.cam_fwd.xyz) / length(frame.cam_fwd.xyz);
}

fn gradient(z: f32, a: f32, b: f32) -> f32 {
    var g = 1e30;
    if a >= 0.0 {
        g = abs(a - z);
    }
    if b >= 0.0 {
        g = min(g, abs(b - z));
    }
    return select(g, 0.0, g >= 1e30);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let z = depth_at(p);
    if z < 0.0 {
        textureStore(out_features, p, vec4f(-1.0, 0.0, 0.0, 0.0));
        return;
    }
    let dz = gradient(z, depth_at(p - vec2i(1, 0)), depth_at(p + vec2i(1, 0))) + gradient(z, depth_at(p - vec2i(0, 1)), depth_at(p + vec2i(0, 1)));
    textureStore(out_features, p, vec4f(z, dz, textureLoad(gb_normal, p, 0).xy));
}
