// TEXCOORD_1 and COLOR_0, three texels per triangle (engine/src/gpu/prepare.rs, pack_extras):
// the vertices' TEXCOORD_1 as f32 bits, then their colours as unorm16 pairs (RG, BA).
var extra_texels: texture_2d<u32>;

fn tri_uv1(slot: u32, b: vec2f) -> vec2f {
    let a = textureLoad(extra_texels, texel_at(slot * 3u), 0);
    let c = textureLoad(extra_texels, texel_at(slot * 3u + 1u), 0);
    let w = vec3f(1.0 - b.x - b.y, b.x, b.y);
    return w.x * bitcast<vec2f>(a.xy) + w.y * bitcast<vec2f>(a.zw) + w.z * bitcast<vec2f>(c.xy);
}

fn tri_color(slot: u32, b: vec2f) -> vec4f {
    let c = textureLoad(extra_texels, texel_at(slot * 3u + 1u), 0);
    let d = textureLoad(extra_texels, texel_at(slot * 3u + 2u), 0);
    let w = vec3f(1.0 - b.x - b.y, b.x, b.y);
    let c0 = vec4f(unpack2x16unorm(c.z), unpack2x16unorm(c.w));
    let c1 = vec4f(unpack2x16unorm(d.x), unpack2x16unorm(d.y));
    let c2 = vec4f(unpack2x16unorm(d.z), unpack2x16unorm(d.w));
    return w.x * c0 + w.y * c1 + w.z * c2;
}
