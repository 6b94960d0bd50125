// The last frame's G-buffer (depth, normal, ids) at the new size (realtime/rescale.wgsl): each
// new texel the nearest old one, so that the reprojection tests of the next frame compare with a
// surface the last frame really saw.

var old_normal: texture_2d<f32>;
var old_ids: texture_2d<u32>;
// The new size (x, y; z and w unused): a render target's size is not a WGSL query.
var<uniform> rescale_target: vec4u;

struct Out {
    @location(0) normal: vec4f,
    @location(1) ids: vec4u,
    @builtin(frag_depth) depth: f32,
}

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    // One triangle covering the target.
    let p = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4f(p * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> Out {
    let new_size = rescale_target.xy;
    let q = vec2i(floor(pos.xy));
    let old_size = textureDimensions(old_ids);
    // rescale_taps' nearest texel.
    let n = clamp(vec2i(floor((vec2f(q) + 0.5) * vec2f(old_size) / vec2f(new_size))), vec2i(0), vec2i(old_size) - 1);
    return Out(textureLoad(old_normal, n, 0), textureLoad(old_ids, n, 0), textureLoad(old_depth, n, 0));
}
