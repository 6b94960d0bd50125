// No radiance cache this frame: no prior (cache/prior.wgsl).

fn cache_prior_at(p: vec2i) -> vec4f {
    return vec4f(0.0);
}

fn cache_prior_m2_at(p: vec2i) -> f32 {
    return 0.0;
}
