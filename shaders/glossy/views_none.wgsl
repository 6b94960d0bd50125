// No glossy chain (no specular lobe in the scene): its views are black.
fn glossy_chain_view(view: u32, p: vec2i) -> vec4f {
    return vec4f(0.0);
}
