// No alpha-masked or blended material in the scene: every intersection is a hit.
fn alpha_accept(slot: u32, b: vec2f, ray: u32) -> bool {
    return true;
}

fn alpha_ray(o: vec3f, d: vec3f) -> u32 {
    return 0u;
}

fn alpha_raster(pixel: vec2u, frame_index: u32) -> u32 {
    return 0u;
}
