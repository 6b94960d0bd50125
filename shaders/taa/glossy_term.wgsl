// The composite's glossy term at this pixel: the denoiser's glossy light (realtime/glossy_in.wgsl,
// or realtime/glossy_in_none.wgsl's zero in a scene without glossy buffers) times F(w_s), for
// TaaSettings::moving_glossy.

fn taa_glossy_term(p: vec2i, f_s: vec3f) -> vec3f {
    return half_safe(glossy_light(p) * f_s);
}
