// The scene has no TEXCOORD_1 and no COLOR_0.
fn tri_uv1(slot: u32, b: vec2f) -> vec2f {
    return vec2f(0.0);
}

fn tri_color(slot: u32, b: vec2f) -> vec4f {
    return vec4f(1.0);
}
