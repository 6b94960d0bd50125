// The upscaler's samples (taa/upscale_common.wgsl), once per render pixel: the composite's light
// less its emission, demodulated, with the linear depth (or -1 off any surface); and where the
// still view keeps the raw mean, the raw sample (the trace's light remodulated) with 1 in alpha
// where the pixel was traced this frame.

var<storage, read> hdr: array<vec4f>;
var out_samples: texture_storage_2d<rgba32float, write>;
var out_raw_samples: texture_storage_2d<rgba32float, write>;

// The composite's sample of render pixel i less its emission, divided by its material's
// demodulation.
fn light_at(i: vec2i) -> vec3f {
    let c = half_safe(hdr[u32(i.y) * frame.size.x + u32(i.x)].rgb);
    if up.materials == 0u {
        return c;
    }
    let hit = textureLoad(gb_object, i, 0).y != NO_SURFACE;
    let a = demodulation(hit, textureLoad(gb_base_color, i, 0), textureLoad(gb_specular, i, 0).rgb);
    return (c - textureLoad(gb_emission, i, 0).rgb) / a;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    textureStore(out_samples, p, vec4f(light_at(p), depth_at(p)));
    var raw = vec4f(0.0);
    if up.bias_sigmas > 0.0 && frame.static_view != 0u && traced_this_frame(gid.xy) {
        raw = vec4f(half_safe(remodulated(gid.xy)), 1.0);
    }
    textureStore(out_raw_samples, p, raw);
}
