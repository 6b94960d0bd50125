// A denoiser that shows glossy light but offers none to follow (SVGF): TAA reads the light the
// composite showed (tr_glossy, realtime/glossy_in.wgsl) for the glossy term alone.

fn taa_glossy(p: vec2i, f_s: vec3f) -> TaaGlossy {
    return TaaGlossy(vec3f(0.0), vec3f(0.0), false, 0.0);
}

fn taa_glossy_previous(p: vec2i) -> vec3f {
    return vec3f(0.0);
}

// The composite's glossy term at this pixel: the denoiser's glossy light times F(w_s).
fn taa_glossy_term(p: vec2i, f_s: vec3f) -> vec3f {
    return half_safe(glossy_light(p) * f_s);
}
