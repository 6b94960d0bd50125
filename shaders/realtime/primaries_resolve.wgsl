// Writes the traced primaries' features (realtime/primaries.wgsl's pr_features layout) into
// the G-buffer's targets and depth, so that every stage after it reads the G-buffer it always
// reads. One full-screen triangle.
//
// The normal and depth come from `edges` (the pre-filter's, or the raw ones without it): they
// are what the denoisers edge-stop and reproject on (Moon et al. 2017 §3, fig. 2). The material
// (base colour, metallic, F0, roughness) and the emission come from `features`, the raw means:
// the composite and TAA multiply the image by them, so a filtered copy would blur the image's
// own texture and emitters beyond the lens's blur, and TAA would converge to that blur.

var<storage, read> features: array<vec4u>;
var<storage, read> edges: array<vec4u>;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4f {
    let uv = vec2f(f32((vi << 1u) & 2u), f32(vi & 2u));
    return vec4f(uv * 2.0 - 1.0, 0.0, 1.0);
}

struct GBufferOut {
    @location(0) normal: vec2f,
    @location(1) motion: vec2f,
    @location(2) base_color: vec4f,
    @location(3) specular: vec4f,
    @location(4) emission: vec4f,
    @location(5) ids: vec2u,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> GBufferOut {
    let px = vec2u(pos.xy);
    let f = (px.y * frame.size.x + px.x) * 5u;
    let n = bitcast<vec4f>(edges[f]);
    let m = features[f + 4u];
    var o: GBufferOut;
    o.ids = m.zw;
    o.emission = bitcast<vec4f>(features[f + 3u]);
    o.depth = 0.0;
    if m.w == 0xffffffffu {
        return o;
    }
    let len = length(n.xyz);
    o.normal = oct_encode(select(-normalize(frame.cam_fwd.xyz), n.xyz / len, len > 1e-12));
    o.motion = bitcast<vec2f>(m.xy);
    // 8-bit targets: unbiased over the frames (realtime/gbuffer_dither.wgsl).
    let stored = dither_material(bitcast<vec4f>(features[f + 1u]), bitcast<vec4f>(features[f + 2u]), px, frame.index);
    o.base_color = stored[0];
    o.specular = stored[1];
    // Reversed infinite Z of the mean view depth (any point at that depth along the view axis).
    let c = frame.unjittered_view_proj * vec4f(frame.cam_pos.xyz + normalize(frame.cam_fwd.xyz) * max(n.w, 1e-30), 1.0);
    o.depth = clamp(c.z / c.w, 0.0, 1.0);
    return o;
}
