// Mara et al. 2017's chains (the matte chain, §3.4, Figure 2 stages 3-7, and the glossy chain
// beside it): their uniform, the cross-bilateral weight, eq. (11)'s confidence and the sparse tap
// pattern. engine/src/denoise/mara/matte.rs mirrors MatteParams; what the frame's stages share (the
// cameras, the reprojection) is in realtime/reproject.wgsl, read from the frame's uniform.

struct MatteParams {
    // Stage switches, bit per stage (STAGE_* below; MatteSettings::switches).
    stages: u32,
    // Taps of the sparse bilateral filters.
    taps: u32,
    // Largest radius the final bilateral may use, pixels.
    max_radius_px: f32,
    // Eq. (11): hysteresis h.
    hysteresis: f32,
    // History is clamped to mean +- clamp_sigma standard deviations of the 3x3 neighbourhood.
    clamp_sigma: f32,
    // Radius of the history-loop bilateral, pixels (half of 1% of the width by default).
    history_radius_px: f32,
    // R of stage (5), pixels (width / 20 by default), and the multiplier where c < 1/2.
    disocclusion_radius_px: f32,
    low_confidence_multiplier: f32,
    // Bilateral weights: normal power and plane-distance sigma in pixel footprints.
    normal_power: f32,
    plane_sigma_px: f32,
    // A temporal random rotation of the tap pattern, radians.
    rotation: f32,
    // The history bilateral's disk shrinks as 1 / sqrt(n) past this history length (0: never).
    history_full_frames: f32,
    // Smallest radius of the final bilateral, pixels.
    min_radius_px: f32,
    // Its luminance edge-stop, in standard deviations of the history's noise (0: none).
    edge_stop_sigmas: f32,
    // Eq. (11)'s reprojection passes a previous texel only where its normal is within this
    // cosine of the surface's (-2: any normal).
    reprojection_min_cos: f32,
    // A bilinearly resampled history counts as at most this many frames (0: no cap).
    resampled_history_frames: f32,
    // In a still view a history at full confidence weighs the new frame 1 / n down to
    // 1 / this (0: the hysteresis always; MatteSettings::still_frames).
    still_frames: f32,
    // Past this history length stage 7's edge-stop narrows as sqrt(this / n) (0: never).
    edge_stop_full_frames: f32,
    // In a still view, a history longer than edge_stop_full_frames is read only from a previous
    // texel whose normal is within this cosine of the surface's (-2: any normal;
    // MatteSettings::still_normal_degrees).
    still_normal_min_cos: f32,
    // The sparse bilateral's taps weigh by a Gaussian of their distance whose sigma is this
    // fraction of the disk's radius (0: none; MatteSettings::tap_sigma_fraction).
    tap_sigma: f32,
}

var<uniform> mp: MatteParams;

const STAGE_TEMPORAL: u32 = 1u;
const STAGE_HISTORY_BILATERAL: u32 = 2u;
const STAGE_DISOCCLUSION: u32 = 4u;
const STAGE_FIREFLY: u32 = 8u;
const STAGE_BILATERAL: u32 = 16u;

fn stage_on(bit: u32) -> bool {
    return (mp.stages & bit) != 0u;
}

// Cross-bilateral weight of a tap (Mara et al. §3.4: camera-space plane distance and normals).
fn bilateral_weight(xc: vec3f, nc: vec3f, fc: f32, xt: vec3f, nt: vec3f) -> f32 {
    let plane = abs(dot(nc, xt - xc)) / (mp.plane_sigma_px * fc);
    let wn = pow(max(dot(nc, nt), 0.0), mp.normal_power);
    return wn * exp(-plane * plane);
}

// The blur of a filter that runs every frame shrinks as 1 / sqrt(n) past `full_frames` of
// history n, so that its variance times the frames it acts on stays constant (0: never shrinks).
// The matte history bilateral's radius follows it, the glossy bilateral's sigma its square.
fn history_falloff(full_frames: f32, n: f32) -> f32 {
    if full_frames <= 0.0 {
        return 1.0;
    }
    return sqrt(min(1.0, full_frames / max(n, 1.0)));
}

// Eq. (11): c = h smoothstep(d1, d0, distance), distance in footprints (0 without a surface).
fn confidence(h: f32, distance: f32) -> f32 {
    if distance < 0.0 {
        return 0.0;
    }
    return h * (1.0 - smoothstep(frame.d0_px, frame.d1_px, distance));
}

// The new frame's weight in a temporal blend: max(1 - c, 1 / n), eq. (11)'s hysteresis with the
// first frames averaged truly; in a still view at full confidence (`still`), 1 / n down to
// 1 / still_frames, so that the history is the mean of every frame since the view settled.
fn new_frame_weight(c: f32, n: f32, still_frames: f32, still: bool) -> f32 {
    if still {
        return max(1.0 / n, 1.0 / still_frames);
    }
    return max(1.0 - c, 1.0 / n);
}

// Tap i of n in a disk of radius r: a golden-angle spiral (uniform density), rotated per frame
// and per pixel (4x4 interleave) so that over a few frames the taps cover the disk.
fn spiral_tap(i: u32, n: u32, r: f32, p: vec2i) -> vec2f {
    let k = u32(p.x & 3) + 4u * u32(p.y & 3);
    let a = f32(i) * 2.39996323 + mp.rotation + f32(k) * 0.392699;
    let d = r * sqrt((f32(i) + 0.5) / f32(n));
    return d * vec2f(cos(a), sin(a));
}

// Running first and second moments of matte input samples: per channel in xyz, of luminance
// in w (the luminance's variance needs its own square, not the channels').
struct Moments {
    m1: vec4f,
    m2: vec4f,
    count: f32,
}

fn moments_add(m: Moments, s: vec3f) -> Moments {
    let v = vec4f(s, luminance(s));
    return Moments(m.m1 + v, m.m2 + v * v, m.count + 1.0);
}

// Spiral tap i of `taps` within `radius` pixels of p, where it lies on p's surface (bilateral
// weight of at least 0.3); vec2i(-1) where it does not. The neighbourhood statistics of the
// temporal clamp and of stage 7's noise estimate are drawn from these taps.
fn surface_tap(p: vec2i, x: vec3f, nc: vec3f, fc: f32, i: u32, taps: u32, radius: f32) -> vec2i {
    let t = p + vec2i(round(spiral_tap(i, taps, radius, p)));
    if !in_bounds(t) || !has_surface(t) {
        return vec2i(-1);
    }
    if bilateral_weight(x, nc, fc, position_at(t), oct_decode(textureLoad(gb_normal, t, 0).xy)) < 0.3 {
        return vec2i(-1);
    }
    return t;
}

// Adds the matte input at the surface taps (surface_tap) to `m`.
fn surface_moments(m: Moments, p: vec2i, x: vec3f, nc: vec3f, fc: f32, taps: u32, radius: f32) -> Moments {
    var r = m;
    for (var i = 0u; i < taps; i++) {
        let t = surface_tap(p, x, nc, fc, i, taps, radius);
        if t.x >= 0 {
            r = moments_add(r, half_safe(matte_input(t)));
        }
    }
    return r;
}
