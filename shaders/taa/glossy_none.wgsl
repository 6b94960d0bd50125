// No glossy light to follow: a scene without glossy buffers, or a denoiser that offers none
// (SVGF, the progressive filter).

fn taa_glossy(p: vec2i, f_s: vec3f) -> TaaGlossy {
    return TaaGlossy(vec3f(0.0), vec3f(0.0), false, 0.0);
}

fn taa_glossy_previous(p: vec2i) -> vec3f {
    return vec3f(0.0);
}
