// Display: exposure, the ACES filmic curve (Narkowicz 2015 fit of the ACES RRT+ODT), sRGB
// encoding unless the target does it; or one of the debug views (engine/src/frame/views.rs).

var<storage, read> hdr: array<vec4f>;
var<storage, read> accumulation: array<vec4f>;

struct DisplayOptions {
    encode_srgb: u32,
    _pad: u32,
    // Size of the render target: the frame is scaled to cover it (resolution scale).
    target_size: vec2u,
}

var<uniform> display: DisplayOptions;

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

fn hash_color(id: u32) -> vec3f {
    let h = pcg_hash(id);
    return vec3f(f32(h & 255u), f32((h >> 8u) & 255u), f32((h >> 16u) & 255u)) / 255.0;
}

// Light buffers are shown exposed and tone-mapped like the image, G-buffer channels as data.
fn debug_view(view: u32, p: vec2i) -> vec4f {
    let g = gbuffer_at(p);
    switch view {
        case 1u: {
            // Reversed Z: near is bright.
            return vec4f(vec3f(pow(textureLoad(gb_depth, p, 0), 0.25)), 0.0);
        }
        case 2u: {
            return vec4f(select(vec3f(0.0), g.n * 0.5 + 0.5, g.hit), 0.0);
        }
        case 3u: {
            return vec4f(g.base, 0.0);
        }
        case 4u: {
            return vec4f(vec3f(g.metallic), 0.0);
        }
        case 5u: {
            return vec4f(vec3f(g.roughness), 0.0);
        }
        case 6u: {
            return vec4f(g.f0, 0.0);
        }
        case 7u: {
            return vec4f(g.emission, 1.0);
        }
        case 8u: {
            let id = textureLoad(gb_object, p, 0).x;
            return vec4f(select(vec3f(0.0), hash_color(id), g.hit), 0.0);
        }
        case 9u: {
            // Motion in pixels: hue = direction, brightness = length (1 px = 0.25).
            let mv = textureLoad(gb_motion, p, 0).xy;
            return vec4f(vec3f(0.5 + mv.x * 0.125, 0.5 - mv.y * 0.125, 0.5 + length(mv) * 0.25), 0.0);
        }
        case 10u: {
            return vec4f(textureLoad(tr_matte, p, 0).rgb, 1.0);
        }
        case 11u: {
            return vec4f(textureLoad(tr_direct, p, 0).rgb, 1.0);
        }
        case 12u: {
            return vec4f(glossy_view(view, p), 1.0);
        }
        case 13u, 14u, 15u: {
            return vec4f(glossy_view(view, p), 0.0);
        }
        default: {
            return denoise_view(view, p);
        }
    }
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let q = vec2u(pos.xy * vec2f(frame.size) / vec2f(max(display.target_size, vec2u(1u))));
    let px = min(q, frame.size - 1u);
    let i = px.y * frame.size.x + px.x;
    var c: vec3f;
    if frame.view == 0u {
        var l = hdr[i].rgb;
        if frame.accumulated > 0u {
            l = accumulation[i].rgb / f32(frame.accumulated);
        }
        c = aces(max(l * frame.exposure, vec3f(0.0)));
    } else {
        let d = debug_view(frame.view, vec2i(px));
        c = select(clamp(d.rgb, vec3f(0.0), vec3f(1.0)), aces(max(d.rgb * frame.exposure, vec3f(0.0))), d.a > 0.5);
    }
    if display.encode_srgb != 0u {
        c = srgb_encode(c);
    }
    return vec4f(c, 1.0);
}
