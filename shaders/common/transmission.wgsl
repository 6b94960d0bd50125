// Glass: KHR_materials_transmission, KHR_materials_ior and KHR_materials_volume. Where the
// transmission is 1 this is Mitsuba's dielectric (roughness 0) and roughdielectric (GGX,
// alpha = roughness^2, visible-normal sampling; Walter et al. 2007, eq. (20) and (21)):
//   reflection  F(wo.h) D G / (4 cos_o) cos_i, with the exact dielectric Fresnel F, untinted;
//   refraction  t tint (1 - F(wo.h)) D G |wi.h| |wo.h| / (cos_o (wo.h + eta wi.h)^2), for
//               radiance: Walter's eta^2 in the numerator cancels against the 1 / eta^2 of
//               non-symmetric refraction (Veach 1997, §5.2), as in Mitsuba's radiance mode;
//   matte       the opaque BRDF's matte lobe with (1 - t) of its albedo (glTF: transmission
//               takes the place of the diffuse base).
// Thin-walled glass (thickness 0) passes light straight through with t tint (1 - F) beside the
// opaque BRDF's reflection and matte lobes.
// The glass table (engine/src/gpu/prepare.rs, pack_glass): two texels per material,
// (transmission, ior, 1 if thin-walled, 0) and (absorption per metre rgb, 0).
var glass_texels: texture_2d<f32>;

fn glass_row(m: Material, k: u32) -> vec4f {
    return textureLoad(glass_texels, texel_at((m.flags >> MAT_INDEX_SHIFT) * 2u + k), 0);
}

// The BSDF of material m at a hit on its front (ray from outside) or back side.
fn with_glass(b: Bsdf, m: Material, ms: MaterialSample, front: bool) -> Bsdf {
    let row = glass_row(m, 0u);
    let t = row.x * (1.0 - clamp(ms.metallic, 0.0, 1.0));
    var r = b;
    if t <= 0.0 {
        return r;
    }
    r.transmission = t;
    r.tint = ms.base.rgb;
    r.albedo = b.albedo * (1.0 - t);
    r.thin = row.z > 0.5;
    // A thin wall has air on both sides: no total internal reflection from either.
    r.eta = select(1.0 / row.y, row.y, front || r.thin);
    return r;
}

// Beer-Lambert over a segment of length t that ended on the inside of material m's volume.
fn glass_absorption(m: Material, front: bool, t: f32) -> vec3f {
    if front {
        return vec3f(1.0);
    }
    return exp(-glass_row(m, 1u).rgb * t);
}

// Unpolarised reflectance of a smooth dielectric interface, eta = beyond / this side, cos_i > 0.
fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

// Thin wall: probability of the straight-through lobe against the opaque lobes.
fn thin_probability(b: Bsdf, cos_o: f32) -> f32 {
    let t = b.transmission * luminance(b.tint) * (1.0 - fresnel_dielectric(cos_o, b.eta));
    let o = luminance(fresnel(b, cos_o)) + luminance(matte_weight(b, cos_o));
    return select(0.0, t / (t + o), t + o > 0.0);
}

// Thick glass: probability of the matte lobe against the dielectric's (reflection + refraction).
fn glass_matte_probability(b: Bsdf, cos_o: f32) -> f32 {
    let m = luminance(matte_weight(b, cos_o));
    let f = fresnel_dielectric(cos_o, b.eta);
    let d = f + b.transmission * luminance(b.tint) * (1.0 - f);
    return select(0.0, m / (m + d), m + d > 0.0);
}

// Probability of reflecting (rather than refracting) at a microfacet with reflectance f.
fn reflect_probability(b: Bsdf, f: f32) -> f32 {
    let t = b.transmission * luminance(b.tint) * (1.0 - f);
    return select(1.0, f / (f + t), f + t > 0.0);
}

fn glass_eval(b: Bsdf, wo: vec3f, wi: vec3f) -> BsdfEval {
    var r = BsdfEval(vec3f(0.0), 0.0);
    if wo.z <= 0.0 {
        return r;
    }
    if b.thin {
        let e = opaque_eval(b, wo, wi);
        return BsdfEval(e.f_cos, e.pdf * (1.0 - thin_probability(b, wo.z)));
    }
    let pm = glass_matte_probability(b, wo.z);
    if wi.z > 0.0 {
        r.f_cos = matte_weight(b, wo.z) * (INV_PI * wi.z);
        r.pdf = pm * wi.z * INV_PI;
    }
    if b.delta {
        return r;
    }
    let g1_o = smith_g1(b.alpha, wo.z);
    if wi.z > 0.0 {
        let h = normalize(wi + wo);
        let co = dot(wo, h);
        if co <= 0.0 {
            return r;
        }
        let f = fresnel_dielectric(co, b.eta);
        let d = ggx_d(b.alpha, h.z);
        r.f_cos += vec3f(f * d * g1_o * smith_g1(b.alpha, wi.z) / (4.0 * wo.z));
        r.pdf += (1.0 - pm) * vndf_pdf(b.alpha, wo, h) * reflect_probability(b, f);
    } else if wi.z < 0.0 {
        // The microfacet that refracts wo into wi (Walter eq. (16)), turned to the outside.
        var h = normalize(wo + b.eta * wi);
        h = select(h, -h, h.z < 0.0);
        let co = dot(wo, h);
        let ci = dot(wi, h);
        let denom = co + b.eta * ci;
        if co <= 0.0 || ci >= 0.0 || denom * denom < 1e-12 {
            return r;
        }
        let f = fresnel_dielectric(co, b.eta);
        let d = ggx_d(b.alpha, h.z);
        let g = g1_o * smith_g1(b.alpha, wi.z);
        r.f_cos += b.tint * (b.transmission * (1.0 - f) * d * g * co * (-ci) / (wo.z * denom * denom));
        // Visible-normal pdf of h, times the choice to refract, times dh/dwi (Walter eq. (17)).
        let pdf_h = g1_o * co * d / wo.z;
        r.pdf += (1.0 - pm) * pdf_h * (1.0 - reflect_probability(b, f)) * b.eta * b.eta * (-ci) / (denom * denom);
    }
    return r;
}

fn glass_sample(b: Bsdf, wo: vec3f, u_lobe: f32, u: vec2f) -> BsdfSample {
    var s = BsdfSample(vec3f(0.0, 0.0, 1.0), vec3f(0.0), 0.0, false);
    if wo.z <= 0.0 {
        return s;
    }
    if b.thin {
        let pt = thin_probability(b, wo.z);
        if u_lobe < pt {
            let f = fresnel_dielectric(wo.z, b.eta);
            return BsdfSample(-wo, b.tint * (b.transmission * (1.0 - f) / pt), 0.0, true);
        }
        var o = opaque_sample(b, wo, (u_lobe - pt) / (1.0 - pt), u);
        o.weight /= 1.0 - pt;
        o.pdf *= 1.0 - pt;
        return o;
    }
    let pm = glass_matte_probability(b, wo.z);
    if u_lobe < pm {
        s.wi = cosine_hemisphere(u);
    } else {
        var h = vec3f(0.0, 0.0, 1.0);
        if !b.delta {
            h = sample_vndf(b.alpha, wo, u);
        }
        let co = dot(wo, h);
        if co <= 0.0 {
            return s;
        }
        let f = fresnel_dielectric(co, b.eta);
        let pr = reflect_probability(b, f);
        // The lobe choice reuses what is left of u_lobe.
        if (u_lobe - pm) / (1.0 - pm) < pr {
            s.wi = reflect(-wo, h);
            if b.delta {
                return BsdfSample(s.wi, vec3f(f / (pr * (1.0 - pm))), 0.0, true);
            }
        } else {
            s.wi = refract(-wo, h, 1.0 / b.eta);
            if dot(s.wi, s.wi) == 0.0 {
                return s;
            }
            if b.delta {
                let w = b.transmission * (1.0 - f) / (b.eta * b.eta * (1.0 - pr) * (1.0 - pm));
                return BsdfSample(s.wi, b.tint * w, 0.0, true);
            }
        }
    }
    return evaluated(s, glass_eval(b, wo, s.wi));
}
