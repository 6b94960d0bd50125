// The scene has no emissive triangles.
fn emitter_pdf_area(slot: u32, p: vec3f, n: vec3f) -> f32 {
    return 0.0;
}

fn sample_emitter(p: vec3f, n: vec3f, u: vec3f) -> LightSample {
    return no_light();
}

fn emitter_point(slot: u32, b2: vec2f, p: vec3f) -> EmitterPoint {
    return EmitterPoint(vec3f(0.0, 0.0, 1.0), 0.0, vec3f(0.0), 0.0);
}

fn choose_emitter(p: vec3f, n: vec3f, u: f32) -> EmitterChoice {
    return EmitterChoice(NO_EMITTER, 0.0);
}
