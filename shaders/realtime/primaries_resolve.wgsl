// Writes the traced primaries' features (realtime/primaries.wgsl's pr_features layout: raw, or
// the pre-filter's) into the G-buffer's targets and depth, so that every stage after it reads
// the G-buffer it always reads. One full-screen triangle.

var<storage, read> features: array<vec4u>;

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
    let n = bitcast<vec4f>(features[f]);
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
    o.base_color = bitcast<vec4f>(features[f + 1u]);
    o.specular = bitcast<vec4f>(features[f + 2u]);
    // Reversed infinite Z of the mean view depth (any point at that depth along the view axis).
    let c = frame.unjittered_view_proj * vec4f(frame.cam_pos.xyz + normalize(frame.cam_fwd.xyz) * max(n.w, 1e-30), 1.0);
    o.depth = clamp(c.z / c.w, 0.0, 1.0);
    return o;
}
