// All textures in one buffer: four u32 of header per texture (texel offset, width, height,
// flags: bit 0 sRGB, bits 1-2 wrap S, bits 3-4 wrap T with 0 repeat, 1 clamp, 2 mirror), then
// RGBA8 texels. One binding serves any number of textures on every backend.
var<storage, read> tex_data: array<u32>;

fn srgb_decode(c: vec3f) -> vec3f {
    return select(pow((c + 0.055) / 1.055, vec3f(2.4)), c / 12.92, c <= vec3f(0.04045));
}

fn wrap_coord(i: i32, n: i32, mode: u32) -> u32 {
    if mode == 1u {
        return u32(clamp(i, 0, n - 1));
    }
    if mode == 2u {
        let p = ((i % (2 * n)) + 2 * n) % (2 * n);
        return u32(select(p, 2 * n - 1 - p, p >= n));
    }
    return u32(((i % n) + n) % n);
}

fn texel(off: u32, w: u32, x: u32, y: u32, srgb: bool) -> vec4f {
    let c = unpack4x8unorm(tex_data[off + y * w + x]);
    return select(c, vec4f(srgb_decode(c.rgb), c.a), srgb);
}

// Bilinear, without mip-maps: the reference tracer's many samples per pixel filter minification.
fn tex_sample(index: u32, uv_in: vec2f) -> vec4f {
    let off = tex_data[index * 4u];
    let w = tex_data[index * 4u + 1u];
    let h = tex_data[index * 4u + 2u];
    let flags = tex_data[index * 4u + 3u];
    let srgb = (flags & 1u) != 0u;
    var uv = uv_in;
    if !all(abs(uv) < vec2f(1e6)) {
        uv = vec2f(0.0);
    }
    let f = uv * vec2f(f32(w), f32(h)) - 0.5;
    let i = floor(f);
    let t = f - i;
    let x0 = i32(i.x);
    let y0 = i32(i.y);
    let ws = (flags >> 1u) & 3u;
    let wt = (flags >> 3u) & 3u;
    let xa = wrap_coord(x0, i32(w), ws);
    let xb = wrap_coord(x0 + 1, i32(w), ws);
    let ya = wrap_coord(y0, i32(h), wt);
    let yb = wrap_coord(y0 + 1, i32(h), wt);
    let a = mix(texel(off, w, xa, ya, srgb), texel(off, w, xb, ya, srgb), t.x);
    let b = mix(texel(off, w, xa, yb, srgb), texel(off, w, xb, yb, srgb), t.x);
    return mix(a, b, t.y);
}
