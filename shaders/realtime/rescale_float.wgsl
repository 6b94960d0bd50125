// A float history at the new size (realtime/rescale.wgsl, entry point in rescale_main.wgsl):
// bilinear over the old texels on the nearest one's surface.

var old: texture_2d<f32>;

fn rescale_texel(t: RescaleTaps) -> vec4f {
    var v = vec4f(0.0);
    for (var i = 0; i < 4; i++) {
        // Skipped, not multiplied by 0: a zero weight on a non-finite texel would still be NaN.
        if t.w[i] > 0.0 {
            v += t.w[i] * textureLoad(old, t.texel[i], 0);
        }
    }
    return v;
}
