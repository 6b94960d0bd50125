// The scene has no emissive triangles.
fn emitter_pdf_area(slot: u32, p: vec3f, n: vec3f) -> f32 {
    return 0.0;
}

fn sample_emitter(p: vec3f, n: vec3f, u: vec3f) -> LightSample {
    return no_light();
}
