// The scene has no punctual lights.
struct LightSample {
    wi: vec3f,
    dist: f32,
    li: vec3f,
    pdf: f32,
}

fn no_light() -> LightSample {
    return LightSample(vec3f(0.0, 0.0, 1.0), 0.0, vec3f(0.0), 0.0);
}

fn sample_punctual(i: u32, p: vec3f) -> LightSample {
    return no_light();
}
