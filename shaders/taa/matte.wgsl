// What TAA reads of the denoiser's matte light (TaaSettings::current_light): its temporal
// output this frame (light before any spatial filter) and its state, as the matte temporal
// writes `matte/reason`: the REASON_* flags in the low 8 bits, the history length above them.

var matte_temporal: texture_2d<f32>;
var matte_reason: texture_2d<u32>;

fn taa_matte_light(p: vec2i) -> vec3f {
    return textureLoad(matte_temporal, p, 0).rgb;
}

fn taa_matte_state(p: vec2i) -> u32 {
    return textureLoad(matte_reason, p, 0).x;
}
