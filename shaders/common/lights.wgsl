// KHR_lights_punctual: directional (irradiance in W/m^2), point and spot (intensity in W/sr).

struct Light {
    pos: vec3f,
    kind: u32,
    // Travel direction (directional) or cone axis (spot).
    dir: vec3f,
    cos_outer: f32,
    intensity: vec3f,
    cos_inner: f32,
}

const LIGHT_DIRECTIONAL: u32 = 0u;
const LIGHT_POINT: u32 = 1u;
const LIGHT_SPOT: u32 = 2u;

var<storage, read> lights: array<Light>;

// A direction towards a light and what arrives along it, divided by the (delta) pdf.
struct LightSample {
    wi: vec3f,
    dist: f32,
    // Radiance over pdf (area and environment lights) or irradiance (punctual lights).
    li: vec3f,
    // Solid-angle pdf; 0 for delta lights.
    pdf: f32,
}

fn no_light() -> LightSample {
    return LightSample(vec3f(0.0, 0.0, 1.0), 0.0, vec3f(0.0), 0.0);
}

fn sample_punctual(i: u32, p: vec3f) -> LightSample {
    let l = lights[i];
    if l.kind == LIGHT_DIRECTIONAL {
        return LightSample(-l.dir, INF, l.intensity, 0.0);
    }
    let v = l.pos - p;
    let d2 = dot(v, v);
    if d2 <= 0.0 {
        return no_light();
    }
    let dist = sqrt(d2);
    let wi = v / dist;
    var e = l.intensity / d2;
    if l.kind == LIGHT_SPOT {
        // glTF's spot falloff: a smooth ramp between the cone angles (KHR_lights_punctual).
        let cd = dot(l.dir, -wi);
        let scale = 1.0 / max(1e-3, l.cos_inner - l.cos_outer);
        let a = clamp((cd - l.cos_outer) * scale, 0.0, 1.0);
        e *= a * a;
    }
    return LightSample(wi, dist, e, 0.0);
}
