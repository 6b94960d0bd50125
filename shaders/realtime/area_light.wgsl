// The area lights of the real-time trace's next-event estimate (emissive triangles and the
// environment; punctual lights are evaluated exhaustively into `direct`), shared by the trace
// (realtime/trace.wgsl) and the radiance cache's secondary samples (cache/update.wgsl).

fn area_groups() -> u32 {
    return select(0u, 1u, HAS_EMITTERS) + select(0u, 1u, HAS_ENV);
}

// One sample of the non-delta lights (emitters or environment, chosen uniformly).
fn sample_area_light(p: vec3f, rng: ptr<function, u32>) -> LightSample {
    let n = area_groups();
    let u = rand(rng);
    var s: LightSample;
    if HAS_EMITTERS && (!HAS_ENV || u < 0.5) {
        s = sample_emitter(p, vec3f(rand(rng), rand(rng), rand(rng)));
    } else {
        s = sample_env(rand2(rng));
    }
    s.li *= f32(n);
    s.pdf /= f32(n);
    return s;
}
