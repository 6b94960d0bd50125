// No specular lobe in the scene: no glossy light to mix.
fn store_glossy(p: vec2i, c: vec3f) {}
