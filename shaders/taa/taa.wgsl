// Temporal anti-aliasing of the composited image (the raster is jittered over a Halton(2, 3)
// sequence). History is fetched bilinearly at pixel + motion and clamped to the min/max box of
// the current 3x3 neighbourhood in YCoCg (Karis 2014), which bounds ghosting to colours present
// now; then blended with weight taa_alpha for the current frame. Without a history (first frame,
// off screen, no surface) the current colour is used as is.

@group(0) @binding(32) var<storage, read> hdr: array<vec4f>;
@group(0) @binding(42) var history: texture_2d<f32>;
@group(0) @binding(43) var linear_clamp: sampler;
@group(0) @binding(50) var out_history: texture_storage_2d<rgba16float, write>;
@group(0) @binding(54) var<storage, read_write> final_image: array<vec4f>;

fn hdr_at(p: vec2i) -> vec3f {
    let q = clamp(p, vec2i(0), vec2i(frame.size) - 1);
    return half_safe(hdr[u32(q.y) * frame.size.x + u32(q.x)].rgb);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let current = hdr_at(p);
    var result = current;
    let prev = vec2f(p) + 0.5 + textureLoad(gb_motion, p, 0).xy;
    let on_screen = all(prev >= vec2f(0.0)) && all(prev < vec2f(frame.size));
    if stage_on(STAGE_TAA) && on_screen && dn.history_valid != 0u {
        var lo = vec3f(3.0e38);
        var hi = vec3f(-3.0e38);
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let s = to_ycocg(hdr_at(p + vec2i(dx, dy)));
                lo = min(lo, s);
                hi = max(hi, s);
            }
        }
        let hist = half_safe(textureSampleLevel(history, linear_clamp, prev / vec2f(frame.size), 0.0).rgb);
        let clamped = from_ycocg(clamp(to_ycocg(hist), lo, hi));
        result = mix(clamped, current, dn.taa_alpha);
    }
    result = half_safe(result);
    textureStore(out_history, p, vec4f(result, 1.0));
    final_image[u32(p.y) * frame.size.x + u32(p.x)] = vec4f(result, 1.0);
}
