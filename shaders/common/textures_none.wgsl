// The scene has no textures.
fn tex_sample(index: u32, uv: vec2f) -> vec4f {
    return vec4f(1.0);
}
