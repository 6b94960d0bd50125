// The G-buffer as read by compute and display passes (written by realtime/gbuffer.wgsl).
var gb_depth: texture_depth_2d;
var gb_normal: texture_2d<f32>;
var gb_motion: texture_2d<f32>;
var gb_base_color: texture_2d<f32>;
var gb_specular: texture_2d<f32>;
var gb_emission: texture_2d<f32>;
var gb_object: texture_2d<u32>;
// Trace outputs every scene has.
var tr_matte: texture_2d<f32>;
var tr_direct: texture_2d<f32>;

const NO_SURFACE: u32 = 0xffffffffu;

// The paths the pixel's matte light averages (realtime/uncovered.wgsl: more where a move
// uncovered the surface); 1 where the supersampling mixed it.
fn matte_paths(p: vec2i) -> f32 {
    return clamp(textureLoad(tr_matte, p, 0).a, 1.0, 64.0);
}

struct GSample {
    hit: bool,
    n: vec3f,
    base: vec3f,
    metallic: f32,
    f0: vec3f,
    roughness: f32,
    emission: vec3f,
    f90: f32,
}

fn gbuffer_at(p: vec2i) -> GSample {
    var g: GSample;
    g.hit = textureLoad(gb_object, p, 0).y != NO_SURFACE;
    g.n = oct_decode(textureLoad(gb_normal, p, 0).xy);
    let bc = textureLoad(gb_base_color, p, 0);
    g.base = bc.rgb;
    g.metallic = bc.a;
    let sp = textureLoad(gb_specular, p, 0);
    g.f0 = sp.rgb;
    g.roughness = sp.a;
    let e = textureLoad(gb_emission, p, 0);
    g.emission = e.rgb;
    g.f90 = e.a;
    return g;
}

// Schlick's Fresnel at the mirror direction of the G-buffer's material (realtime/frame.wgsl).
fn fresnel_mirror(g: GSample, cos_o: f32) -> vec3f {
    return schlick_mirror(g.f0, g.f90, cos_o);
}

// What the composite multiplies the matte light by (realtime/frame.wgsl: remodulated_matte).
fn matte_factor(g: GSample, f_s: vec3f) -> vec3f {
    return remodulated_matte(g.base, g.metallic, f_s);
}
