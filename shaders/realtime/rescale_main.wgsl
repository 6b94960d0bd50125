// The resampling of one texture (realtime/rescale.wgsl). `old` and `rescale_texel` come from
// rescale_float.wgsl or rescale_uint.wgsl; the prelude aliases `Dst`, a write-only storage
// texture of the texture's format.

var dst: Dst;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let size = textureDimensions(dst);
    if any(gid.xy >= size) {
        return;
    }
    let t = rescale_taps(vec2i(gid.xy), textureDimensions(old), size);
    textureStore(dst, vec2i(gid.xy), rescale_texel(t));
}
