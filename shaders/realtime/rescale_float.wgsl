// A float history at the new size (realtime/rescale.wgsl). The prelude aliases
// `Dst`, a write-only storage texture of the history's format.

var old: texture_2d<f32>;
var dst: Dst;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let size = textureDimensions(dst);
    if any(gid.xy >= size) {
        return;
    }
    let t = rescale_taps(vec2i(gid.xy), textureDimensions(old), size);
    var v = vec4f(0.0);
    for (var i = 0; i < 4; i++) {
        // Skipped, not multiplied by 0: a zero weight on a non-finite texel would still be NaN.
        if t.w[i] > 0.0 {
            v += t.w[i] * textureLoad(old, t.texel[i], 0);
        }
    }
    textureStore(dst, vec2i(gid.xy), v);
}
