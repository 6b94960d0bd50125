// Display: exposure, the ACES filmic curve (Narkowicz 2015 fit of the ACES RRT+ODT), sRGB
// encoding unless the target does it; or a debug view: any labelled texture of the frame through
// a small map (engine/src/settings/view.rs).

var<storage, read> hdr: array<vec4f>;
var<storage, read> accumulation: array<vec4f>;

struct DisplayOptions {
    encode_srgb: u32,
    // 0: the image; else how the view texture is shown (ViewMap::encode in
    // engine/src/settings/view.rs).
    map: u32,
    // Size of the render target: the frame is scaled to cover it (resolution scale).
    target_size: vec2u,
    // The view's channel and its map's parameter.
    channel: u32,
    param: f32,
    // Size of the image `hdr` holds: the upscaler's (engine/src/passes/upscale.rs) where it ran,
    // else the render size (frame.size), which the accumulation and the debug views have.
    image_size: vec2u,
}

var<uniform> display: DisplayOptions;
// The texture a debug view shows: float formats in view_float, integer ones in view_uint (the
// other holds one zero texel).
var view_float: texture_2d<f32>;
var view_uint: texture_2d<u32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    // One triangle covering the screen.
    let p = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4f(p * 2.0 - 1.0, 0.0, 1.0);
}

fn aces(x: vec3f) -> vec3f {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3f(0.0), vec3f(1.0));
}

fn hash_color(id: u32) -> vec3f {
    let h = pcg_hash(id);
    return vec3f(f32(h & 255u), f32((h >> 8u) & 255u), f32((h >> 16u) & 255u)) / 255.0;
}

// As the surface motion view: hue = direction, brightness = length (1 px = 0.25).
fn motion_colour(mv: vec2f) -> vec3f {
    return vec3f(0.5 + mv.x * 0.125, 0.5 - mv.y * 0.125, 0.5 + length(mv) * 0.25);
}

// A debug view's colour; alpha 1 where it is light (exposed and tone-mapped like the image).
fn debug_view(p: vec2i) -> vec4f {
    let t = textureLoad(view_float, p, 0);
    let u = textureLoad(view_uint, p, 0);
    let c = display.channel;
    switch display.map {
        case 1u: {
            return vec4f(t.rgb, 1.0);
        }
        case 2u: {
            return vec4f(t.rgb, 0.0);
        }
        case 3u: {
            return vec4f(vec3f(t[c] / display.param), 0.0);
        }
        case 4u: {
            return vec4f(motion_colour(vec2f(t[c], t[c + 1u])), 0.0);
        }
        case 5u: {
            let g = gbuffer_at(p);
            return vec4f(select(vec3f(0.0), g.n * 0.5 + 0.5, g.hit), 0.0);
        }
        case 6u: {
            // Reversed Z: near is bright.
            return vec4f(vec3f(pow(textureLoad(gb_depth, p, 0), 0.25)), 0.0);
        }
        case 7u: {
            return vec4f(select(vec3f(0.0), hash_color(u.x), gbuffer_at(p).hit), 0.0);
        }
        case 8u: {
            // Red: disoccluded; yellow: low confidence; blue: history clamped.
            let r = u.x & 255u;
            var f = vec3f(0.0);
            if (r & 1u) != 0u {
                f = vec3f(1.0, 0.0, 0.0);
            } else if (r & 2u) != 0u {
                f = vec3f(1.0, 1.0, 0.0);
            }
            if (r & 4u) != 0u {
                f += vec3f(0.0, 0.3, 1.0);
            }
            return vec4f(f, 0.0);
        }
        case 9u: {
            return vec4f(oct_decode(unpack2x16snorm(u.x)) * 0.5 + 0.5, 0.0);
        }
        case 10u: {
            // Over the scene's extent (2^17 ray offsets); white: escaped.
            let d = t[c];
            return vec4f(vec3f(select(d / (frame.cam_pos.w * 131072.0), 1.0, d >= 65000.0)), 0.0);
        }
        case 11u: {
            return vec4f(select(fract(t.xyz / (frame.cam_pos.w * 131072.0) * 8.0), vec3f(0.0), t.w >= 3.0e38), 0.0);
        }
        default: {
            return vec4f(0.0);
        }
    }
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let q = vec2u(pos.xy * vec2f(frame.size) / vec2f(max(display.target_size, vec2u(1u))));
    let px = min(q, frame.size - 1u);
    let i = px.y * frame.size.x + px.x;
    var c: vec3f;
    if display.map == 0u {
        var l: vec3f;
        if frame.accumulated > 0u {
            l = accumulation[i].rgb / f32(frame.accumulated);
        } else {
            let size = max(display.image_size, vec2u(1u));
            let q_image = min(vec2u(pos.xy * vec2f(size) / vec2f(max(display.target_size, vec2u(1u)))), size - 1u);
            l = hdr[q_image.y * size.x + q_image.x].rgb;
        }
        c = aces(max(l * frame.exposure, vec3f(0.0)));
    } else {
        // The view's texel: its texture's own size (the render size's, or the upscaler's shown
        // size; the unused binding is one texel). Depth is read from the G-buffer's binding.
        var dims = max(textureDimensions(view_float), textureDimensions(view_uint));
        if display.map == 6u {
            dims = frame.size;
        }
        let v = min(vec2u(pos.xy * vec2f(dims) / vec2f(max(display.target_size, vec2u(1u)))), dims - 1u);
        let d = debug_view(vec2i(v));
        c = select(clamp(d.rgb, vec3f(0.0), vec3f(1.0)), aces(max(d.rgb * frame.exposure, vec3f(0.0))), d.a > 0.5);
    }
    if display.encode_srgb != 0u {
        c = srgb_encode(c);
    }
    return vec4f(c, 1.0);
}
