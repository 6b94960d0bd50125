// No material transmits: every BSDF is opaque (common/bsdf.wgsl never calls these).
fn with_glass(b: Bsdf, m: Material, ms: MaterialSample, front: bool) -> Bsdf {
    return b;
}

fn glass_absorption(m: Material, front: bool, t: f32) -> vec3f {
    return vec3f(1.0);
}

fn glass_eval(b: Bsdf, wo: vec3f, wi: vec3f) -> BsdfEval {
    return BsdfEval(vec3f(0.0), 0.0);
}

fn glass_sample(b: Bsdf, wo: vec3f, u_lobe: f32, u: vec2f) -> BsdfSample {
    return BsdfSample(vec3f(0.0, 0.0, 1.0), vec3f(0.0), 0.0, false);
}
