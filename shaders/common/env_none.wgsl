// The scene has no environment: misses are black.
fn env_radiance(d: vec3f) -> vec3f {
    return vec3f(0.0);
}

fn env_pdf(d: vec3f) -> f32 {
    return 0.0;
}

fn sample_env(u: vec2f) -> LightSample {
    return no_light();
}
