// Shared by the glossy chain's stages (Mara et al. 2017 §3.4 stages 8-10, with the reflection
// reprojection and neighbourhood clipping of Voorhuis §4). engine/src/denoise/mara/glossy.rs mirrors
// GlossyParams; the cameras, the reprojection's thresholds and whether history exists are the
// frame's (realtime/reproject.wgsl), the bilateral weight's normal power and plane sigma the
// matte chain's (MatteParams, matte/common.wgsl).

struct GlossyParams {
    // Stage switches (GSTAGE_*).
    stages: u32,
    // Reflection motion vectors: 0 surface (primary), 1 virtual position, 2 diamond search.
    mode: u32,
    // Diamond search: first large-pattern step in pixels, most iterations.
    initial_step: u32,
    max_search_steps: u32,
    roughness_threshold: f32,
    mirror_roughness: f32,
    clip_roughness: f32,
    hysteresis: f32,
    // Eq. (11) for mirrors, in pixel footprints at the reflected distance.
    d0_px: f32,
    d1_px: f32,
    sigma_scale: f32,
    sigma_exponent: f32,
    sigma_epsilon_px: f32,
    omega: f32,
    roughness_sigma: f32,
    // Distance that stands for a reflection that left the scene (a few scene extents).
    far: f32,
    max_sigma_px: f32,
    // 1: the representative hits of glossy surfaces come from traced mirror rays (the reflected-hit
    // test's; the motion search has it as a constant of its program, TRACED_HITS).
    representative_traced: u32,
    // The bilateral's sigma shrinks as 1 / sqrt(history length) beyond this many frames.
    sigma_full_frames: f32,
    // 1 when neither the camera nor an object moved since the previous frame: every reflection
    // then stands still, and the reflection motion is the surface's (zero) in every mode.
    static_view: u32,
    // The surface reprojection's normal test (MatteParams::reprojection_min_cos for the matte chain).
    reprojection_min_cos: f32,
    // A bilinearly resampled history counts as at most this many frames (0: no cap).
    resampled_history_frames: f32,
    // GlossySettings::still_frames, as MatteParams::still_frames for the matte chain.
    still_frames: f32,
}

var<uniform> gp: GlossyParams;

const GSTAGE_TEMPORAL: u32 = 1u;
const GSTAGE_CLIPPING: u32 = 2u;
const GSTAGE_BILATERAL: u32 = 4u;
// The reflected-hit test of glossy (not only mirror) lobes below the roughness threshold.
const GSTAGE_HIT_TEST: u32 = 8u;

const MV_PRIMARY: u32 = 0u;
const MV_VIRTUAL: u32 = 1u;
const MV_DIAMOND: u32 = 2u;

fn gstage_on(bit: u32) -> bool {
    return (gp.stages & bit) != 0u;
}

fn roughness_at(p: vec2i) -> f32 {
    return textureLoad(gb_specular, p, 0).a;
}

fn is_mirror(roughness: f32) -> bool {
    return roughness <= gp.mirror_roughness;
}

fn hit_reflectance(p: vec2i) -> vec3f {
    return unpack4x8unorm(textureLoad(tr_mirror_hit, p, 0).x).rgb;
}

fn hit_normal(p: vec2i) -> vec3f {
    return oct_decode(unpack2x16snorm(textureLoad(tr_mirror_hit, p, 0).y));
}

fn mirror_direction(p: vec2i) -> vec3f {
    return oct_decode(unpack2x16snorm(textureLoad(tr_mirror, p, 0).x));
}

// Behind a mirror the chain filters light divided by the reflected surface's reflectance
// (Voorhuis §4.1), so that the texture seen in the mirror is not blurred; the last stage
// multiplies it back. The floor keeps black reflected surfaces from amplifying noise.
fn demodulation(p: vec2i) -> vec3f {
    if is_mirror(roughness_at(p)) {
        return max(hit_reflectance(p), vec3f(0.02));
    }
    return vec3f(1.0);
}

fn glossy_input(p: vec2i) -> vec3f {
    return half_safe(glossy_light(p) / demodulation(p));
}

// The representative ray's hit distance (the trace traces the mirror ray of glossy surfaces
// under the roughness threshold; mirrors' samples are that ray); an escaped ray stands at `far`.
fn secondary_t(p: vec2i) -> f32 {
    let t = textureLoad(tr_reflection, p, 0).w;
    return select(t, gp.far, t >= 3.0e38);
}

// Eq. (4): the representative ray (primary hit x, mirror direction) extended to its hit: the
// most likely secondary hit. Its distance is the traced mirror ray's (GlossySettings::
// trace_representative_ray) or, as Voorhuis, the sample's; for a mirror they are the same.
fn representative_hit(p: vec2i, x: vec3f) -> vec3f {
    return x + mirror_direction(p) * secondary_t(p);
}

// Eq. (5): the distance from the nearer representative hit to the other representative ray.
fn ray_distance(oa: vec3f, ha: vec3f, ob: vec3f, hb: vec3f) -> f32 {
    let ta = length(ha - oa);
    let tb = length(hb - ob);
    var near = ha;
    var o_far = ob;
    var h_far = hb;
    if ta > tb {
        near = hb;
        o_far = oa;
        h_far = ha;
    }
    let d = h_far - o_far;
    let l = length(d);
    if l <= 0.0 {
        return length(near - o_far);
    }
    return length(cross(d / l, near - o_far));
}

// Mara et al. §3.4: sigma = 7 roughness^0.1 + epsilon pixels; below the roughness threshold
// scaled by Voorhuis eq. (6), exp(-dP / omega), with dP the secondary hit's ray differential in
// pixel footprints of the primary surface. GlossySettings::sigma_px is the same function.
fn glossy_sigma(roughness: f32, footprints: f32) -> f32 {
    let base = gp.sigma_scale * pow(clamp(roughness, 0.0, 1.0), gp.sigma_exponent) + gp.sigma_epsilon_px;
    var scale = 1.0;
    if roughness < gp.roughness_threshold {
        scale = exp(-max(footprints, 0.0) / max(gp.omega, 1e-3));
    }
    return clamp(base * scale, 0.0, gp.max_sigma_px);
}

// Rebased world position to this frame's (unjittered) pixel coordinates, and the previous
// frame's; None-like: w < 0 when behind the camera.
fn to_pixels_of(m: mat4x4f, x: vec3f) -> vec3f {
    let c = m * vec4f(x, 1.0);
    if c.w <= 0.0 {
        return vec3f(0.0, 0.0, -1.0);
    }
    let ndc = c.xy / c.w;
    return vec3f((ndc.x * 0.5 + 0.5) * f32(frame.size.x), (0.5 - ndc.y * 0.5) * f32(frame.size.y), 1.0);
}

// Mara's virtual position (after Zimmer et al. 2015): what the reflection shows seen through
// the mirror lies along the camera ray at the primary distance plus the secondary distance.
// Its motion from this frame to the previous is the reflection's motion vector.
fn virtual_motion(p: vec2i, x: vec3f) -> vec3f {
    let cam = frame.cam_pos.xyz;
    let v = cam + normalize(x - cam) * (length(x - cam) + secondary_t(p));
    let now = to_pixels_of(frame.unjittered_view_proj, x);
    let before = to_pixels_of(frame.prev_view_proj, v);
    if now.z < 0.0 || before.z < 0.0 {
        return vec3f(0.0, 0.0, -1.0);
    }
    return vec3f(before.xy - now.xy, 1.0);
}

// The secondary hit's ray differential in primary pixel footprints: how far the neighbouring
// pixels' mirror rays, carried the same distance, land from this one's (Igehy 1999 with the
// distance held fixed). 1 for a plane mirror at contact, larger where the reflection minifies.
fn ray_differential(p: vec2i, x: vec3f) -> f32 {
    let t = secondary_t(p);
    let h = x + mirror_direction(p) * t;
    var sum = 0.0;
    var count = 0.0;
    for (var k = 0; k < 2; k++) {
        let q = p + select(vec2i(0, 1), vec2i(1, 0), k == 0);
        let qq = select(q, p - (q - p), !in_bounds(q));
        // Only neighbours on the same object: across a silhouette the difference is the edge.
        if in_bounds(qq) && has_surface(qq) && textureLoad(gb_object, qq, 0).x == textureLoad(gb_object, p, 0).x {
            let xq = position_at(qq);
            sum += length(xq + mirror_direction(qq) * t - h);
            count += 1.0;
        }
    }
    return select(1.0, sum / max(count, 1.0) / footprint(x), count > 0.0);
}

// A pixel's size at the reflected hit: at least the footprint at the primary plus secondary
// distance (a plane mirror), more where a curved mirror minifies (the ray differential).
fn reflected_footprint(p: vec2i, x: vec3f) -> f32 {
    let f = footprint(x);
    let plane = f * (1.0 + secondary_t(p) / max(length(x - frame.cam_pos.xyz), 1e-6));
    return max(plane, ray_differential(p, x) * f);
}

// The representative-hit texture's w: which kind of surface the pixel had (a mirror's search
// matches only mirrors, a glossy surface's only glossy ones) and its secondary distance.
const HIT_NONE: u32 = 0u;
const HIT_ROUGH: u32 = 1u;
const HIT_GLOSSY: u32 = 2u;
const HIT_MIRROR: u32 = 3u;

fn hit_class(roughness: f32) -> u32 {
    if roughness >= gp.roughness_threshold {
        return HIT_ROUGH;
    }
    return select(HIT_GLOSSY, HIT_MIRROR, is_mirror(roughness));
}

// none: 0; rough: 1e30; glossy: t + 1; mirror: -(t + 1).
fn encode_hit_w(kind: u32, t: f32) -> f32 {
    switch kind {
        case 1u: {
            return 1e30;
        }
        case 2u: {
            return min(t, 1e29) + 1.0;
        }
        case 3u: {
            return -(min(t, 1e29) + 1.0);
        }
        default: {
            return 0.0;
        }
    }
}

fn decode_hit_class(w: f32) -> u32 {
    if w == 0.0 {
        return HIT_NONE;
    }
    if w < 0.0 {
        return HIT_MIRROR;
    }
    return select(HIT_GLOSSY, HIT_ROUGH, w >= 1e30);
}

// Clip h towards the box centre along the line between them (Karis 2014), in YCoCg.
fn clip_to_box(h: vec3f, lo: vec3f, hi: vec3f) -> vec3f {
    let centre = 0.5 * (lo + hi);
    let extent = max(0.5 * (hi - lo), vec3f(1e-6));
    let d = h - centre;
    let t = max3(abs(d) / extent);
    if t <= 1.0 {
        return h;
    }
    return centre + d / t;
}

// Voorhuis §4.2.3: h clipped to the 5x5 box, in YCoCg, of the pre-blurred current glossy light
// around p (glossy/prefilter.wgsl), the glossy chain's and SVGF's clip alike.
fn clip_to_neighbourhood(neighbourhood: texture_2d<f32>, p: vec2i, h: vec3f) -> vec3f {
    var lo = vec3f(3.0e38);
    var hi = vec3f(-3.0e38);
    for (var dy = -2; dy <= 2; dy++) {
        for (var dx = -2; dx <= 2; dx++) {
            let s = to_ycocg(textureLoad(neighbourhood, clamp(p + vec2i(dx, dy), vec2i(0), vec2i(frame.size) - 1), 0).rgb);
            lo = min(lo, s);
            hi = max(hi, s);
        }
    }
    return from_ycocg(clip_to_box(to_ycocg(h), lo, hi));
}
