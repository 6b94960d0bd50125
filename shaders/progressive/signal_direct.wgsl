// The punctual direct light and what the camera sees of the environment. It carries the
// material, so the a-trous levels only fill pixels without a sample; accumulated and
// reprojected it stays right where the camera moves and the pixel was not traced.
fn signal_input(p: vec2i) -> vec3f {
    return textureLoad(tr_direct, p, 0).rgb;
}
