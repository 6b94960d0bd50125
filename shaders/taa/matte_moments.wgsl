// What TAA reads of the progressive filter's matte light (denoise/progressive.rs): the light the
// composite shows (the last a-trous level's output) and its moments texel (m1, m2, samples, and
// in w the frames since the pixel's history last restarted), read as the state taa/matte.wgsl
// reads: a pixel with no history (w < 1) or fewer than two samples as disoccluded, else the
// frames as its length. The filter reprojects each pixel's own texel (the nearest), so a settled
// pixel's history is its own. A single sample is mostly what the a-trous levels filled in around
// it; following it cost 64 frames at 1/64 spp 0.5-2% FLIP (docs/decisions.md).

var matte_temporal: texture_2d<f32>;
var matte_moments: texture_2d<f32>;

fn taa_matte_light(p: vec2i) -> vec3f {
    return textureLoad(matte_temporal, p, 0).rgb;
}

fn taa_matte_state(p: vec2i) -> u32 {
    let m = textureLoad(matte_moments, p, 0);
    let frames = m.w;
    // The length above the 8 flag bits: at most 2^24 - 1.
    return select(REASON_DISOCCLUDED, u32(min(frames, 16777215.0)) << 8u, frames >= 1.0 && m.z >= 2.0);
}
