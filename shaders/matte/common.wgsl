// Shared by the matte chain's stages (Mara et al. 2017 §3.4, Figure 2 stages 3-7) and TAA:
// parameters, world positions from depth, the pixel footprint, the cross-bilateral weight and
// the sparse tap pattern. engine/src/passes/matte.rs mirrors DenoiseParams.

struct DenoiseParams {
    // Rebased world from clip, this frame and the previous one (both with their jitter, as the
    // depth buffers were rasterised).
    inv_view_proj: mat4x4f,
    prev_inv_view_proj: mat4x4f,
    // Stage switches, bit per stage (passes/matte.rs: STAGE_*).
    stages: u32,
    // Taps of the sparse bilateral filters.
    taps: u32,
    // Which history texture this frame reads (0 or 1); it writes the other.
    parity: u32,
    // Largest radius the final bilateral may use, pixels.
    max_radius_px: f32,
    // Eq. (11): hysteresis h and the smoothstep's d0, d1 in pixel footprints.
    hysteresis: f32,
    d0_px: f32,
    d1_px: f32,
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
    // TAA: weight of the current frame.
    taa_alpha: f32,
    // A temporal random rotation of the tap pattern, radians.
    rotation: f32,
    // 0 when there is no usable history (first denoised frame, after a resize or a pause of the
    // denoiser): temporal stages then start over.
    history_valid: u32,
    // Tests: replace the input with NaN / +Inf / -Inf on 1 pixel in 7.
    inject_nonfinite: u32,
    // The history bilateral's disk shrinks as 1 / sqrt(n) past this history length (0: never).
    history_full_frames: f32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(40) var<uniform> dn: DenoiseParams;

const STAGE_TEMPORAL: u32 = 1u;
const STAGE_HISTORY_BILATERAL: u32 = 2u;
const STAGE_DISOCCLUSION: u32 = 4u;
const STAGE_FIREFLY: u32 = 8u;
const STAGE_BILATERAL: u32 = 16u;
const STAGE_TAA: u32 = 32u;

// History rejection reasons (the matte/reason debug view).
const REASON_DISOCCLUDED: u32 = 1u;
const REASON_LOW_CONFIDENCE: u32 = 2u;
const REASON_CLAMPED: u32 = 4u;

fn stage_on(bit: u32) -> bool {
    return (dn.stages & bit) != 0u;
}

fn in_bounds(p: vec2i) -> bool {
    return all(p >= vec2i(0)) && all(p < vec2i(frame.size));
}

fn has_surface(p: vec2i) -> bool {
    return textureLoad(gb_object, p, 0).y != NO_SURFACE;
}

// Rebased world position of pixel p's sample, from a depth buffer.
fn world_from_depth(inv: mat4x4f, p: vec2i, depth: f32) -> vec3f {
    let uv = (vec2f(p) + 0.5) / vec2f(frame.size);
    let clip = vec4f(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let w = inv * clip;
    return w.xyz / w.w;
}

fn position_at(p: vec2i) -> vec3f {
    return world_from_depth(dn.inv_view_proj, p, textureLoad(gb_depth, p, 0));
}

// Size of one pixel, in scene units, at the distance of x.
fn footprint(x: vec3f) -> f32 {
    let z = max(dot(x - frame.cam_pos.xyz, frame.cam_fwd.xyz), 1e-6);
    return 2.0 * z * length(frame.cam_up.xyz) / f32(frame.size.y);
}

// Cross-bilateral weight of a tap (Mara et al. §3.4: camera-space plane distance and normals).
fn bilateral_weight(xc: vec3f, nc: vec3f, fc: f32, xt: vec3f, nt: vec3f) -> f32 {
    let plane = abs(dot(nc, xt - xc)) / (dn.plane_sigma_px * fc);
    let wn = pow(max(dot(nc, nt), 0.0), dn.normal_power);
    return wn * exp(-plane * plane);
}

// Tap i of n in a disk of radius r: a golden-angle spiral (uniform density), rotated per frame
// and per pixel (4x4 interleave) so that over a few frames the taps cover the disk.
fn spiral_tap(i: u32, n: u32, r: f32, p: vec2i) -> vec2f {
    let k = u32(p.x & 3) + 4u * u32(p.y & 3);
    let a = f32(i) * 2.39996323 + dn.rotation + f32(k) * 0.392699;
    let d = r * sqrt((f32(i) + 0.5) / f32(n));
    return d * vec2f(cos(a), sin(a));
}


// The matte light entering the chain (with the test's fault injection, when asked for).
fn matte_input(p: vec2i) -> vec3f {
    let v = textureLoad(tr_matte, p, 0).rgb;
    if dn.inject_nonfinite != 0u {
        let k = u32(p.x * 3 + p.y * 5) % 7u;
        let zero = f32(dn.stages & 0u);
        if k == 0u {
            return vec3f(zero / zero);
        }
        if k == 1u {
            return vec3f(1.0 / zero, v.g, -1.0 / zero);
        }
    }
    return v;
}

// YCoCg, where TAA's box and the glossy chain's neighbourhood clip are drawn (Karis 2014).
fn to_ycocg(c: vec3f) -> vec3f {
    return vec3f(
        0.25 * c.r + 0.5 * c.g + 0.25 * c.b,
        0.5 * c.r - 0.5 * c.b,
        -0.25 * c.r + 0.5 * c.g - 0.25 * c.b,
    );
}

fn from_ycocg(c: vec3f) -> vec3f {
    return vec3f(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}
