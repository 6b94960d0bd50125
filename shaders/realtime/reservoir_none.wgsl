// No reservoirs (the supersampling's extra samples, a frame without light reuse): every matte
// light sample is resampled on its own (realtime/area_light.wgsl, resample_area_light).

const HAS_RESERVOIRS: bool = false;

fn reservoir_clear(px: vec2u) {}

fn reservoir_direct(px: vec2u, p: vec3f, ns: vec3f, ng: vec3f, origin: vec3f, eps: f32, m: u32, rng: ptr<function, u32>) -> vec3f {
    return vec3f(0.0);
}
