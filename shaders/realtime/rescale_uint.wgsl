// An integer texture at the new size (realtime/rescale.wgsl, entry point in
// rescale_main.wgsl): the nearest old texel.

var old: texture_2d<u32>;

fn rescale_texel(t: RescaleTaps) -> vec4u {
    return textureLoad(old, t.nearest, 0);
}
