// Where each texture of a material is read (engine/src/gpu/prepare.rs, pack_texture_uses): per
// material and texture slot two texels, the rows of an affine map (KHR_texture_transform's
// offset x rotation x scale, or the identity) applied to the TEXCOORD set in the first's w.
var tex_use_texels: texture_2d<f32>;

fn texture_uv(m: Material, k: u32, t: TexCoords) -> vec2f {
    let i = ((m.flags >> MAT_INDEX_SHIFT) * 4u + k) * 2u;
    let r0 = textureLoad(tex_use_texels, texel_at(i), 0);
    let r1 = textureLoad(tex_use_texels, texel_at(i + 1u), 0);
    let uv = vec3f(select(t.uv0, t.uv1, r0.w > 0.5), 1.0);
    return vec2f(dot(r0.xyz, uv), dot(r1.xyz, uv));
}
