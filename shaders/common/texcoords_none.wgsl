// Every texture is read at TEXCOORD_0 as stored.
fn texture_uv(m: Material, k: u32, t: TexCoords) -> vec2f {
    return t.uv0;
}

// Untransformed: the texture's frame is the mesh's.
fn texture_frame(m: Material, k: u32, xy: vec2f) -> vec2f {
    return xy;
}
