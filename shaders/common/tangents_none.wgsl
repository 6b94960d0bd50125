// The scene has no normal maps.
fn apply_normal_map(slot: u32, b: vec2f, ns: vec3f, tc: TexCoords, m: Material) -> vec3f {
    return ns;
}
