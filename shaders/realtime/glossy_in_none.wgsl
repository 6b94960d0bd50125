// No glossy buffers in this scene.
fn glossy_light(p: vec2i) -> vec3f {
    return vec3f(0.0);
}
