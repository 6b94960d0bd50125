// Shared constants and small helpers.

const PI: f32 = 3.14159265358979;
const INV_PI: f32 = 0.318309886183791;
const INF: f32 = 3.0e38;

fn luminance(c: vec3f) -> f32 {
    return dot(c, vec3f(0.2126, 0.7152, 0.0722));
}

// The sRGB transfer function (IEC 61966-2-1), linear to encoded and back, for values in [0, 1].
fn srgb_encode(c: vec3f) -> vec3f {
    return select(1.055 * pow(c, vec3f(1.0 / 2.4)) - 0.055, c * 12.92, c <= vec3f(0.0031308));
}

fn srgb_decode(c: vec3f) -> vec3f {
    return select(pow((c + 0.055) / 1.055, vec3f(2.4)), c / 12.92, c <= vec3f(0.04045));
}

fn max3(v: vec3f) -> f32 {
    return max(v.x, max(v.y, v.z));
}

fn is_finite3(v: vec3f) -> bool {
    // NaN fails every comparison; Inf fails the bound.
    return all(abs(v) <= vec3f(3.0e38));
}

// Orthonormal basis around n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
fn onb(n: vec3f) -> mat3x3f {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3f(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = vec3f(b, s + n.y * n.y * a, -n.y);
    return mat3x3f(t, bt, n);
}

fn to_local(f: mat3x3f, v: vec3f) -> vec3f {
    return vec3f(dot(v, f[0]), dot(v, f[1]), dot(v, f[2]));
}

// Move a ray origin off a surface along its geometric normal (n on the side the ray leaves to).
// The offset scales with the scene (eps = scene extent x 2^-17, Params.cam_pos.w) and with the
// magnitude of p (2^-18 |p|, about 32 ulps), so it neither leaks light in a millimetre-sized scene
// nor re-hits the surface in a kilometre-sized one. The GPU scene is rebased around its centre,
// which keeps |p| small for scenes far from the world origin.
fn offset_ray(p: vec3f, n: vec3f, eps: f32) -> vec3f {
    let m = max3(abs(p));
    return p + n * (eps + m * 3.8e-6);
}

// A shadow ray's direction and length from `origin` (p lifted off its surface by offset_ray) to
// the light point p + wi x dist, stopping short of it (dist INF: a direction, kept as it is).
// Aimed from the lifted origin: a line along wi from there runs beside the true one and, where
// an emitter lies low over the surface, crosses the emitter's plane before its end, so that
// the emitter's own triangle would shadow its sample (tests/area_light.rs).
struct ShadowLeg {
    dir: vec3f,
    tmax: f32,
}

fn shadow_leg(origin: vec3f, p: vec3f, wi: vec3f, dist: f32, eps: f32) -> ShadowLeg {
    if !(dist < INF) {
        return ShadowLeg(wi, INF);
    }
    let v = p + wi * dist - origin;
    let len = length(v);
    if !(len > 0.0) {
        return ShadowLeg(wi, 0.0);
    }
    return ShadowLeg(v / len, len * (1.0 - 1e-4) - eps);
}

fn power_heuristic(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    let b2 = b * b;
    if a2 + b2 <= 0.0 || a2 > 3.0e38 {
        return 1.0;
    }
    return a2 / (a2 + b2);
}
