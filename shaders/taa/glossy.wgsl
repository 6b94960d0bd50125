// What TAA reads of the glossy chain (TaaSettings::current_glossy): the glossy temporal's
// output this frame and last frame (glossy light divided by the mirror demodulation), and
// whether this frame's continues last frame's at this pixel (glossy/temporal.wgsl, info.w).

var glossy_temporal: texture_2d<f32>;
var glossy_info: texture_2d<f32>;
var glossy_previous: texture_2d<f32>;

fn taa_glossy(p: vec2i, f_s: vec3f) -> TaaGlossy {
    if !has_surface(p) {
        return TaaGlossy(vec3f(0.0), vec3f(0.0), false, 0.0);
    }
    let t = textureLoad(glossy_temporal, p, 0);
    let info = textureLoad(glossy_info, p, 0);
    return TaaGlossy(f_s * demodulation(p), half_safe(t.rgb), info.w == 1.0, info.z);
}

// The light TAA followed at this pixel last frame (the glossy temporal's output there).
fn taa_glossy_previous(p: vec2i) -> vec3f {
    return half_safe(textureLoad(glossy_previous, p, 0).rgb);
}
