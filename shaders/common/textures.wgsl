// All textures in one array of words: four u32 of header per texture (texel offset, width,
// height, flags: bit 0 sRGB, bits 1-2 wrap S, bits 3-4 wrap T with 0 repeat, 1 clamp, 2 mirror,
// bit 5 nearest, bits 6-10 the number of mip levels below the base), then RGBA8 texels, the
// base level's followed by each mip level's (engine/src/gpu/pack.rs). One binding serves any
// number of textures on every backend. The words are read four to a texel of a texel-row
// texture (see tri_texels in geometry.wgsl).
var tex_words: texture_2d<u32>;

fn tex_word(i: u32) -> u32 {
    let t = textureLoad(tex_words, texel_at(i >> 2u), 0);
    let c = i & 3u;
    return select(select(t.x, t.y, c == 1u), select(t.z, t.w, c == 3u), c >= 2u);
}

// A coordinate wrapped into [0, 1] by the sampler mode (0 repeat, 1 clamp, 2 mirror), in float:
// integer remainders are a division per lane on a CPU driver. Mirroring folds the coordinate
// into [0, 1], where the neighbour across an edge is the edge texel itself, as with clamping.
fn wrap_unit(u: f32, mode: u32) -> f32 {
    if mode == 1u {
        return clamp(u, 0.0, 1.0);
    }
    if mode == 2u {
        let m = u - 2.0 * floor(u * 0.5);
        return select(m, 2.0 - m, m > 1.0);
    }
    return u - floor(u);
}

// Texel columns (or rows) i and i + 1 of n: wrapped around for repeat, else held at the edges.
fn wrap_pair(i: i32, n: i32, mode: u32) -> vec2u {
    if mode == 0u {
        return vec2u(u32(select(i, n - 1, i < 0)), u32(select(i + 1, 0, i + 1 >= n)));
    }
    return vec2u(u32(clamp(i, 0, n - 1)), u32(clamp(i + 1, 0, n - 1)));
}

fn texel(off: u32, w: u32, x: u32, y: u32, srgb: bool) -> vec4f {
    let c = unpack4x8unorm(tex_word(off + y * w + x));
    return select(c, vec4f(srgb_decode(c.rgb), c.a), srgb);
}

const HAS_TEXTURES: bool = true;

// Mip level l: its texel offset, width and height (each level half the one above, at least one
// texel a side).
fn tex_level(off: u32, w: u32, h: u32, l: u32) -> vec3u {
    var r = vec3u(off, w, h);
    for (var k = 0u; k < l; k++) {
        r = vec3u(r.x + r.y * r.z, max(r.y >> 1u, 1u), max(r.z >> 1u, 1u));
    }
    return r;
}

// Bilinear (nearest where the sampler says so) in the mip level a footprint calls for. lod:
// log2 of the footprint's side in texture coordinates (TexCoords.lod; very negative at a primary
// hit, whose minification the pixel's samples filter). The level is log2 of the side in texels,
// chosen between the two levels around it with probability by xi, so one bilinear lookup has
// trilinear filtering's mean.
fn tex_sample(index: u32, uv_in: vec2f, lod: f32, xi: f32) -> vec4f {
    let off0 = tex_word(index * 4u);
    let w0 = tex_word(index * 4u + 1u);
    let h0 = tex_word(index * 4u + 2u);
    let flags = tex_word(index * 4u + 3u);
    let texels = lod + 0.5 * log2(f32(w0) * f32(h0));
    var level = 0u;
    if texels > 0.0 {
        let fl = floor(texels);
        level = u32(min(fl + select(0.0, 1.0, xi < texels - fl), f32((flags >> 6u) & 31u)));
    }
    let lv = tex_level(off0, w0, h0, level);
    let off = lv.x;
    let w = lv.y;
    let h = lv.z;
    let srgb = (flags & 1u) != 0u;
    var uv = uv_in;
    if !all(abs(uv) < vec2f(1e6)) {
        uv = vec2f(0.0);
    }
    let ws = (flags >> 1u) & 3u;
    let wt = (flags >> 3u) & 3u;
    let unit = vec2f(wrap_unit(uv.x, ws), wrap_unit(uv.y, wt));
    let size = vec2f(f32(w), f32(h));
    // Nearest: the texel the coordinate falls in (u = 1 exactly: the last one), as a bilinear
    // lookup whose weights are 0; selected rather than branched on, which cost the level's
    // trace 5% on the software driver.
    let nearest = vec2<bool>((flags & 32u) != 0u);
    let f = select(unit * size - 0.5, min(floor(unit * size), size - 1.0), nearest);
    let i = floor(f);
    let t = f - i;
    let x = wrap_pair(i32(i.x), i32(w), ws);
    let y = wrap_pair(i32(i.y), i32(h), wt);
    let a = mix(texel(off, w, x.x, y.x, srgb), texel(off, w, x.y, y.x, srgb), t.x);
    let b = mix(texel(off, w, x.x, y.y, srgb), texel(off, w, x.y, y.y, srgb), t.x);
    return mix(a, b, t.y);
}
