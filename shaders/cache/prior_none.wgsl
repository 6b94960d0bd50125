// No radiance cache this frame: no prior (cache/prior.wgsl).

fn cache_prior_at(p: vec2i) -> vec4f {
    return vec4f(0.0);
}
