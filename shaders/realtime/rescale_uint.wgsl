// An integer texture at the new size (realtime/rescale.wgsl): the nearest old texel. The prelude
// aliases `Dst`, a write-only storage texture of its format.

var old: texture_2d<u32>;
var dst: Dst;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let size = textureDimensions(dst);
    if any(gid.xy >= size) {
        return;
    }
    let t = rescale_taps(vec2i(gid.xy), textureDimensions(old), size);
    textureStore(dst, vec2i(gid.xy), textureLoad(old, t.nearest, 0));
}
