// Glossy outputs of the trace pass where no stage reads the reflection data (the raw frame, the
// progressive filter): the glossy light and its secondary hit distance alone. The light is the
// one realtime/trace_glossy.wgsl writes; the virtual position, the mirror direction and what the
// glossy path hit are neither written nor allocated.
var out_glossy: texture_storage_2d<rgba16float, write>;

const HAS_GLOSSY: bool = true;

fn write_glossy(px: vec2u, light: vec3f, t: f32, primary: vec3f, mirror: vec3f, hit_reflectance: vec3f, hit_normal: vec3f, representative_t: f32) {
    textureStore(out_glossy, px, vec4f(half_safe(light), min(t, 65000.0)));
}
