// Nothing moves while the shutter is open (a static scene): a triangle's vertices are where the
// BVH holds them, and a hit is where its world position sample is (Moon et al. eq. (2), M = I).
fn tri_vertex(i: u32) -> vec3f {
    return tri_texel(i).xyz;
}

fn set_ray_time(t: f32) {
}

fn shutter_time() -> f32 {
    return 1.0;
}

fn normal_at_ray_time(slot: u32, n: vec3f) -> vec3f {
    return n;
}

fn compensated_position(hit: Hit, p: vec3f) -> vec3f {
    return p;
}
