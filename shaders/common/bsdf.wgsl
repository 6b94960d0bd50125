// The factored BRDF of Mara et al. 2017, eq. (1):
//   f(wi, wo) = m(wi, wo) (1 - F)^2 + g(wi, wo) F
// m is Lambertian: the (1 - metallic) part of the base colour over pi, with its Fresnel factor
// taken at the mirror direction, F(n.wo), as in the matte estimator of eq. (9).
// g is GGX (alpha = roughness^2) with the separable Smith term G1(wi) G1(wo) (as Mitsuba), with
// Schlick's F at the half vector; roughness 0 makes g a delta mirror. F0 = base colour for
// metals, KHR_materials_specular's 0.04 x specular colour x specular factor for dielectrics.
// All directions are in the local shading frame (z = shading normal).
// A transmissive material (KHR_materials_transmission) replaces the reflection and matte lobes
// with common/transmission.wgsl's dielectric (bsdf_eval and bsdf_sample hand it over).

struct Bsdf {
    // (1 - metallic) x base colour.
    albedo: vec3f,
    f0: vec3f,
    f90: vec3f,
    alpha: f32,
    delta: bool,
    // KHR_materials_transmission x (1 - metallic); 0 for an opaque material (with_glass sets
    // these four).
    transmission: f32,
    // Index ratio across the surface, beyond over this side (ior entering, 1 / ior leaving).
    eta: f32,
    // The transmitted light's tint (the base colour).
    tint: vec3f,
    // KHR_materials_volume's thickness 0: light passes straight through.
    thin: bool,
}

// Mitsuba clamps GGX alpha to >= 1e-4; below that Hush uses the delta mirror.
const MIN_ALPHA: f32 = 1e-4;

fn make_bsdf(base: vec3f, metallic: f32, roughness: f32, spec_factor: f32, spec_color: vec3f) -> Bsdf {
    var b: Bsdf;
    b.albedo = base * (1.0 - metallic);
    let f0_d = min(0.04 * spec_color, vec3f(1.0)) * spec_factor;
    b.f0 = mix(f0_d, base, metallic);
    b.f90 = mix(vec3f(spec_factor), vec3f(1.0), metallic);
    b.alpha = roughness * roughness;
    b.delta = b.alpha < MIN_ALPHA;
    b.transmission = 0.0;
    b.eta = 1.0;
    b.tint = vec3f(0.0);
    b.thin = false;
    return b;
}

fn fresnel(b: Bsdf, c: f32) -> vec3f {
    let m = 1.0 - clamp(c, 0.0, 1.0);
    let m2 = m * m;
    return b.f0 + (b.f90 - b.f0) * (m2 * m2 * m);
}

// Mara eq. (1)'s matte weight m (1 - F)^2, with F at the mirror direction.
fn matte_weight(b: Bsdf, cos_o: f32) -> vec3f {
    let one_minus_f = vec3f(1.0) - fresnel(b, cos_o);
    return b.albedo * one_minus_f * one_minus_f;
}

fn ggx_d(alpha: f32, cos_h: f32) -> f32 {
    let a2 = alpha * alpha;
    let c2 = cos_h * cos_h;
    let d = c2 * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

// Smith G1 for GGX: 2 / (1 + sqrt(1 + alpha^2 tan^2)).
fn smith_g1(alpha: f32, cos_t: f32) -> f32 {
    let c2 = cos_t * cos_t;
    if c2 <= 0.0 {
        return 0.0;
    }
    let tan2 = max(1.0 - c2, 0.0) / c2;
    return 2.0 / (1.0 + sqrt(1.0 + alpha * alpha * tan2));
}

// Probability of picking the glossy lobe: its share of the estimated reflectance.
fn glossy_probability(b: Bsdf, cos_o: f32) -> f32 {
    let g = luminance(fresnel(b, cos_o));
    let m = luminance(matte_weight(b, cos_o));
    if g + m <= 0.0 {
        return 0.0;
    }
    return g / (g + m);
}

// Visible-normal pdf of wi reflected about h ~ D_wo (Heitz 2018): G1(wo) D(h) / (4 cos_o).
fn vndf_pdf(alpha: f32, wo: vec3f, h: vec3f) -> f32 {
    return smith_g1(alpha, wo.z) * ggx_d(alpha, h.z) / (4.0 * wo.z);
}

// f(wi, wo) cos(wi) for the non-delta lobes, and the pdf of sampling wi by bsdf_sample.
struct BsdfEval {
    f_cos: vec3f,
    pdf: f32,
}

// The glossy lobe alone: F(h) D G / (4 cos_o) cos_i, and its visible-normal pdf (the real-time
// trace estimates it separately from the matte lobe, Mara et al. eq. (8)).
fn glossy_eval(b: Bsdf, wo: vec3f, wi: vec3f) -> BsdfEval {
    var r: BsdfEval;
    r.f_cos = vec3f(0.0);
    r.pdf = 0.0;
    if wo.z <= 0.0 || wi.z <= 0.0 || b.delta {
        return r;
    }
    let h = normalize(wi + wo);
    let g = smith_g1(b.alpha, wo.z) * smith_g1(b.alpha, wi.z);
    r.f_cos = fresnel(b, dot(wo, h)) * (ggx_d(b.alpha, h.z) * g / (4.0 * wo.z));
    r.pdf = vndf_pdf(b.alpha, wo, h);
    return r;
}

fn bsdf_eval(b: Bsdf, wo: vec3f, wi: vec3f) -> BsdfEval {
    if b.transmission > 0.0 {
        return glass_eval(b, wo, wi);
    }
    return opaque_eval(b, wo, wi);
}

fn opaque_eval(b: Bsdf, wo: vec3f, wi: vec3f) -> BsdfEval {
    var r: BsdfEval;
    r.f_cos = vec3f(0.0);
    r.pdf = 0.0;
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return r;
    }
    let pg = glossy_probability(b, wo.z);
    r.f_cos = matte_weight(b, wo.z) * (INV_PI * wi.z);
    r.pdf = (1.0 - pg) * wi.z * INV_PI;
    if pg > 0.0 {
        let g = glossy_eval(b, wo, wi);
        r.f_cos += g.f_cos;
        r.pdf += pg * g.pdf;
    }
    return r;
}

struct BsdfSample {
    wi: vec3f,
    // f cos / pdf (the throughput multiplier).
    weight: vec3f,
    // Solid-angle pdf; 0 for a delta direction.
    pdf: f32,
    delta: bool,
}

// Visible GGX normals by spherical caps (Dupuy & Benyoub 2023).
fn sample_vndf(alpha: f32, wo: vec3f, u: vec2f) -> vec3f {
    let wo_std = normalize(vec3f(wo.xy * alpha, wo.z));
    let phi = 2.0 * PI * u.x;
    let z = (1.0 - u.y) * (1.0 + wo_std.z) - wo_std.z;
    let st = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
    let c = vec3f(st * cos(phi), st * sin(phi), z);
    let h_std = c + wo_std;
    return normalize(vec3f(h_std.xy * alpha, max(h_std.z, 1e-7)));
}

fn cosine_hemisphere(u: vec2f) -> vec3f {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    return vec3f(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u.x, 0.0)));
}

// One-sample choice between the lobes, then the full mixture pdf for MIS.
fn bsdf_sample(b: Bsdf, wo: vec3f, u_lobe: f32, u: vec2f) -> BsdfSample {
    if b.transmission > 0.0 {
        return glass_sample(b, wo, u_lobe, u);
    }
    return opaque_sample(b, wo, u_lobe, u);
}

fn opaque_sample(b: Bsdf, wo: vec3f, u_lobe: f32, u: vec2f) -> BsdfSample {
    var s: BsdfSample;
    s.weight = vec3f(0.0);
    s.pdf = 0.0;
    s.delta = false;
    s.wi = vec3f(0.0, 0.0, 1.0);
    if wo.z <= 0.0 {
        return s;
    }
    let pg = glossy_probability(b, wo.z);
    if u_lobe < pg {
        if b.delta {
            s.wi = vec3f(-wo.xy, wo.z);
            s.weight = fresnel(b, wo.z) / pg;
            s.delta = true;
            return s;
        }
        let h = sample_vndf(b.alpha, wo, u);
        s.wi = reflect(-wo, h);
    } else {
        s.wi = cosine_hemisphere(u);
    }
    return evaluated(s, opaque_eval(b, wo, s.wi));
}

// Sample s (its direction chosen, nothing else set) completed by the evaluation of its
// direction: the mixture pdf and f cos / pdf; a direction of pdf 0 carries nothing.
fn evaluated(s: BsdfSample, e: BsdfEval) -> BsdfSample {
    var r = s;
    if e.pdf > 0.0 {
        r.pdf = e.pdf;
        r.weight = e.f_cos / e.pdf;
    }
    return r;
}
