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

// A tangent-space direction (a normal map's xy) of texture slot k turned into the mesh's
// TEXCOORD frame: the frame of a mesh whose coordinates had the transform baked in, i.e. the
// unit directions along which the texture's u and v grow (the map's inverse's columns), u's
// with v's made perpendicular to it on the same side.
fn texture_frame(m: Material, k: u32, xy: vec2f) -> vec2f {
    let i = ((m.flags >> MAT_INDEX_SHIFT) * 4u + k) * 2u;
    let r0 = textureLoad(tex_use_texels, texel_at(i), 0);
    let r1 = textureLoad(tex_use_texels, texel_at(i + 1u), 0);
    // Inverse's columns up to 1 / det: (a11, -a10) and (-a01, a00); det's sign keeps them.
    let det = r0.x * r1.y - r0.y * r1.x;
    let cu = vec2f(r1.y, -r1.x) * sign(det);
    let cv = vec2f(-r0.y, r0.x) * sign(det);
    if dot(cu, cu) < 1e-20 {
        return xy;
    }
    let t = normalize(cu);
    let b = vec2f(-t.y, t.x) * select(1.0, -1.0, dot(vec2f(-t.y, t.x), cv) < 0.0);
    return t * xy.x + b * xy.y;
}
