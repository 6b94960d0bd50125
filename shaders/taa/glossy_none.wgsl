// No glossy chain in this scene: every pixel's glossy term is zero, and TAA has no glossy light
// to follow.

fn taa_glossy(p: vec2i, f_s: vec3f) -> TaaGlossy {
    return TaaGlossy(vec3f(0.0), vec3f(0.0), false, 0.0);
}

fn taa_glossy_previous(p: vec2i) -> vec3f {
    return vec3f(0.0);
}

fn taa_glossy_term(p: vec2i, f_s: vec3f) -> vec3f {
    return vec3f(0.0);
}
