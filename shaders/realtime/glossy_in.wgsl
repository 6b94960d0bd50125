// Glossy trace outputs as read by the composite and the debug views.
var tr_glossy: texture_2d<f32>;
var tr_reflection: texture_2d<f32>;
var tr_mirror: texture_2d<u32>;
// What the glossy path hit first: reflectance (rgba8) and normal (octahedral snorm16x2).
var tr_mirror_hit: texture_2d<u32>;

fn glossy_light(p: vec2i) -> vec3f {
    return textureLoad(tr_glossy, p, 0).rgb;
}
