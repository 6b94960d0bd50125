// The edge-stopping features every later stage reads, in one texel: linear depth (-1 off
// surfaces), its screen-space gradient (matte/common.wgsl: depth_gradient) and the G-buffer's
// octahedral normal.

var out_features: texture_storage_2d<rgba32float, write>;

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
    let dz = depth_gradient(p, z);
    textureStore(out_features, p, vec4f(z, dz, textureLoad(gb_normal, p, 0).xy));
}
