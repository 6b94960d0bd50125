// The scene has no textures.
const HAS_TEXTURES: bool = false;

fn tex_sample(index: u32, uv: vec2f, lod: f32, xi: f32) -> vec4f {
    return vec4f(1.0);
}
