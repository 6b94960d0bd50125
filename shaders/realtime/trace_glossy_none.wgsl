// No material has a specular lobe: no glossy path, no glossy buffers.
const HAS_GLOSSY: bool = false;

fn write_glossy(px: vec2u, light: vec3f, t: f32, primary: vec3f, mirror: vec3f, hit_reflectance: vec3f, hit_normal: vec3f, representative_t: f32) {}
