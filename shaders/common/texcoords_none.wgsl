// Every texture is read at TEXCOORD_0 as stored.
fn texture_uv(m: Material, k: u32, t: TexCoords) -> vec2f {
    return t.uv0;
}
