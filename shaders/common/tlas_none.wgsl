// A scene without instances: every triangle is in the scene's trees (common/cwbvh.wgsl or
// bvh2.wgsl), in world space.
fn traverse(o: vec3f, d: vec3f, tmax: f32, any_hit: bool) -> Hit {
    return traverse_from(0u, DYNAMIC_ROOT, o, d, tmax, any_hit);
}
