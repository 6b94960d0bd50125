// The denoiser offers no matte light to follow: every pixel reads as disoccluded, so TAA keeps
// its own average of the composite (a plain TAA).

fn taa_matte_light(p: vec2i) -> vec3f {
    return vec3f(0.0);
}

fn taa_matte_state(p: vec2i) -> u32 {
    return REASON_DISOCCLUDED;
}
