// No radiance cache: a path never ends in one (common/path.wgsl's `path_end`; the cache's is
// cache/path_end.wgsl).
fn path_end(s: Surface, b: Bsdf, wo: vec3f, basis: mat3x3f, origin: vec3f) -> vec4f {
    return vec4f(0.0);
}
