// The glossy light, reprojected with its surface (no reflection motion vectors here).
fn signal_input(p: vec2i) -> vec3f {
    return textureLoad(tr_glossy, p, 0).rgb;
}
