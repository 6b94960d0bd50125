// Emissive triangles, picked in proportion to area x luminance of the material's emission and
// then uniformly in area. Entries: (cumulative probability as bits, triangle slot).
var<storage, read> emitters: array<vec2u>;

// Area density of a point on an emissive triangle: luminance(L) / sum(area x luminance(L)).
// It does not depend on the triangle's area, so a BSDF-sampled hit can compute it from its
// material alone (for MIS).
fn emitter_pdf_area(emission: vec3f) -> f32 {
    return luminance(emission) * params.emit.x;
}

fn sample_emitter(p: vec3f, u: vec3f) -> LightSample {
    // Binary search for the first entry whose cumulative probability exceeds u.x.
    var lo = 0u;
    var hi = params.num_emitters - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if bitcast<f32>(emitters[mid].x) > u.x {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    let slot = emitters[lo].y;
    // The vertices as texels (at the shutter's close where objects move): one fetch a vertex
    // instead of the storage buffer's per-word reads.
    let v0 = tri_texel(slot * 3u).xyz;
    let e1 = tri_texel(slot * 3u + 1u).xyz - v0;
    let e2 = tri_texel(slot * 3u + 2u).xyz - v0;
    let su = sqrt(u.y);
    let b = vec2f(1.0 - su, u.z * su);
    let q = v0 + b.x * e1 + b.y * e2;
    let n = normalize(cross(e1, e2));
    let v = q - p;
    let d2 = dot(v, v);
    let dist = sqrt(d2);
    let wi = v / dist;
    // One-sided emitters: only the counter-clockwise face emits.
    let cos_l = -dot(n, wi);
    let m = material(tri_material(slot));
    if cos_l <= 0.0 || d2 <= 0.0 {
        return no_light();
    }
    var le = m.emission;
    if m.tex.w >= 0 {
        le *= material_texture(m, 3u, tri_tex_coords(slot, b)).rgb;
    }
    let pdf = emitter_pdf_area(m.emission) * d2 / cos_l;
    if pdf <= 0.0 {
        return no_light();
    }
    return LightSample(wi, dist, le / pdf, pdf);
}
