// Uniform radiance from every direction (Params.env_radiance), sampled uniformly on the sphere.
fn env_radiance(d: vec3f) -> vec3f {
    return params.env_radiance.rgb;
}

fn env_pdf(d: vec3f) -> f32 {
    return 0.25 * INV_PI;
}

fn sample_env(u: vec2f) -> LightSample {
    let z = 1.0 - 2.0 * u.x;
    let r = sqrt(max(0.0, 1.0 - z * z));
    let phi = 2.0 * PI * u.y;
    let wi = vec3f(r * cos(phi), r * sin(phi), z);
    let pdf = 0.25 * INV_PI;
    return LightSample(wi, INF, params.env_radiance.rgb / pdf, pdf);
}
