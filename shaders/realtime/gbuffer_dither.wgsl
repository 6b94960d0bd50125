// The G-buffer keeps a material in 8 bits a channel (passes/gbuffer.rs). Rounded to the nearest
// code, a constant colour comes out off by the same amount every frame, and every mean of the
// frames keeps that offset: the Cornell box's white 0.725 is stored as 0.7230 (sRGB, -0.27%), a
// dielectric's F0 of 0.04 as 0.0392 (linear, -2%). Each frame instead stores one of the two codes
// around the value, the upper one with the probability that makes the stored value's expectation
// the value itself (in linear terms, which the composite multiplies by), so the jittered frames
// that TAA and the still-view means average converge to the material. The noise this adds to one
// frame is under one code (1/255 in sRGB or linear). Only the colours the light is multiplied by
// (base colour, F0): metallic and roughness keep the nearest code, because the glossy chains
// compare roughness with thresholds (`is_mirror`, the reflection reprojection's), and a material
// between two codes would cross one from frame to frame; half a code of roughness moves a lobe's
// width by under 0.2% of its range.
//
// Needs pcg_hash (common/rng.wgsl) and the sRGB transfer function (common/math.wgsl).

// Uniform in [0, 1) per pixel, frame and use.
fn gbuffer_dither_u(pixel: vec2u, frame_index: u32, salt: u32) -> f32 {
    let h = pcg_hash(pixel.x ^ pcg_hash(pixel.y ^ pcg_hash(frame_index ^ pcg_hash(salt))));
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// A linear colour in [0, 1] for an sRGB-encoded 8-bit target: exactly one of the two codes
// around it, decoded (the target's encode gives that code back).
fn dither_srgb8(c: vec3f, u: f32) -> vec3f {
    let e = srgb_encode(clamp(c, vec3f(0.0), vec3f(1.0))) * 255.0;
    let lo = min(floor(e), vec3f(254.0));
    let below = srgb_decode(lo / 255.0);
    let above = srgb_decode((lo + 1.0) / 255.0);
    let t = (c - below) / max(above - below, vec3f(1e-12));
    return select(below, above, vec3f(u) < t);
}

// A linear colour in [0, 1] for a linear 8-bit target: one of the two codes around it.
fn dither_unorm8(c: vec3f, u: f32) -> vec3f {
    let e = clamp(c, vec3f(0.0), vec3f(1.0)) * 255.0;
    let lo = min(floor(e), vec3f(254.0));
    return (lo + select(vec3f(0.0), vec3f(1.0), vec3f(u) < e - lo)) / 255.0;
}

// The base colour (sRGB target; metallic in alpha) and the specular target (F0; roughness in
// alpha) as this frame stores them.
fn dither_material(base: vec4f, specular: vec4f, pixel: vec2u, frame_index: u32) -> array<vec4f, 2> {
    let b = dither_srgb8(base.rgb, gbuffer_dither_u(pixel, frame_index, 0u));
    let f0 = dither_unorm8(specular.rgb, gbuffer_dither_u(pixel, frame_index, 1u));
    return array<vec4f, 2>(vec4f(b, base.a), vec4f(f0, specular.a));
}
