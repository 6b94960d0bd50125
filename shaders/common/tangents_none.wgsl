// The scene has no normal maps.
fn apply_normal_map(slot: u32, b: vec2f, ns: vec3f, uv: vec2f, m: Material) -> vec3f {
    return ns;
}
