// Stage (7): the final sparse bilateral, with the per-pixel radius of stage (5); it fills
// disocclusions and removes low-frequency noise.
@group(0) @binding(44) var filter_in: texture_2d<f32>;
@group(0) @binding(52) var radius_in: texture_2d<f32>;
@group(0) @binding(50) var out_matte: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    var v = textureLoad(filter_in, p, 0).rgb;
    if stage_on(STAGE_BILATERAL) {
        v = sparse_bilateral(p, textureLoad(radius_in, p, 0).r);
    }
    textureStore(out_matte, p, vec4f(half_safe(v), 1.0));
}
