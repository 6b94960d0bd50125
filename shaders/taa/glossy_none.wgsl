// No glossy chain in this scene: TAA has no glossy light to follow, and every pixel's glossy
// term is zero, which any history follows.

struct TaaGlossy {
    factor: vec3f,
    light: vec3f,
    own: bool,
    n: f32,
}

fn taa_glossy(p: vec2i, f_s: vec3f) -> TaaGlossy {
    return TaaGlossy(vec3f(0.0), vec3f(0.0), true, 3.0e38);
}

fn taa_glossy_previous(p: vec2i) -> vec3f {
    return vec3f(0.0);
}
