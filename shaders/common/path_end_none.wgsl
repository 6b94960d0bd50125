// No radiance cache: a path never ends in one, and a vertex adds its light sample
// (common/path.wgsl's `vertex_light`; the cache's is cache/path_end.wgsl).
fn vertex_light(s: Surface, b: Bsdf, wo: vec3f, basis: mat3x3f, origin: vec3f, beta: vec3f, may_end: bool, reach: f32, rng: ptr<function, u32>) -> VertexLight {
    return VertexLight(next_event(s, b, wo, basis, origin, beta, rng), false);
}
