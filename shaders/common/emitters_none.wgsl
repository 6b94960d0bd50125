// The scene has no emissive triangles.
fn emitter_pdf_area(emission: vec3f) -> f32 {
    return 0.0;
}

fn sample_emitter(p: vec3f, u: vec3f) -> LightSample {
    return no_light();
}
