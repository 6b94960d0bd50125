// Shows the reference tracer's running mean in the viewer: mean = sum / samples, ACES filmic
// curve (Narkowicz 2015 fit), then sRGB encoding unless the surface format does it.

struct DisplayParams {
    width: u32,
    height: u32,
    samples: u32,
    encode_srgb: u32,
}

@group(0) @binding(0) var<uniform> display: DisplayParams;
@group(0) @binding(1) var<storage, read> accum_in: array<vec4f>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    // One triangle covering the screen.
    let p = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4f(p * 2.0 - 1.0, 0.0, 1.0);
}

fn aces(x: vec3f) -> vec3f {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3f(0.0), vec3f(1.0));
}

fn srgb_encode(c: vec3f) -> vec3f {
    return select(1.055 * pow(c, vec3f(1.0 / 2.4)) - 0.055, c * 12.92, c <= vec3f(0.0031308));
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let x = min(u32(pos.x), display.width - 1u);
    let y = min(u32(pos.y), display.height - 1u);
    let s = accum_in[(y * display.width + x) * 2u].rgb / f32(max(display.samples, 1u));
    var c = aces(max(s, vec3f(0.0)));
    if display.encode_srgb != 0u {
        c = srgb_encode(c);
    }
    return vec4f(c, 1.0);
}
