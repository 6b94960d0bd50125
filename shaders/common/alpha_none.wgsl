// No alpha-masked material in the scene: every intersection is a hit.
fn alpha_accept(slot: u32, b: vec2f) -> bool {
    return true;
}
