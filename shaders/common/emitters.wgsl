// Emissive triangles: a leaf of the light tree (common/light_tree.wgsl), then a point uniform in
// its triangle's area. A triangle's third vertex's w names its leaf (+ 1; 0: it emits nothing).

// Area density at which sample_emitter from p, n picks a point of triangle `slot`, for the MIS
// weight of a BSDF-sampled hit on it.
fn emitter_pdf_area(slot: u32, p: vec3f, n: vec3f) -> f32 {
    let named = u32(tri_texel(slot * 3u + 2u).w);
    if named == 0u {
        return 0.0;
    }
    let leaf = named - 1u;
    return light_tree_pmf(leaf, p, n) / emitters[leaf].area;
}

// One emitter's point for the surface at p with geometric normal n (zero: none): u.x walks the
// tree, u.yz place the point in the triangle.
fn sample_emitter(p: vec3f, n: vec3f, u: vec3f) -> LightSample {
    let c = light_tree_sample(p, n, u.x);
    if c.pmf <= 0.0 {
        return no_light();
    }
    let leaf = emitters[c.node];
    let slot = leaf.child & ~LIGHT_LEAF;
    // The vertices as texels (at the shutter's close where objects move): one fetch a vertex
    // instead of the storage buffer's per-word reads.
    let v0 = tri_texel(slot * 3u).xyz;
    let e1 = tri_texel(slot * 3u + 1u).xyz - v0;
    let e2 = tri_texel(slot * 3u + 2u).xyz - v0;
    let su = sqrt(u.y);
    let b = vec2f(1.0 - su, u.z * su);
    let q = v0 + b.x * e1 + b.y * e2;
    let ng = normalize(cross(e1, e2));
    let v = q - p;
    let d2 = dot(v, v);
    let dist = sqrt(d2);
    let wi = v / dist;
    // One-sided emitters: only the counter-clockwise face emits.
    let cos_l = -dot(ng, wi);
    let m = material(tri_material(slot));
    if cos_l <= 0.0 || d2 <= 0.0 {
        return no_light();
    }
    var le = m.emission;
    if m.tex.w >= 0 {
        le *= material_texture(m, 3u, tri_tex_coords(slot, b)).rgb;
    }
    let pdf = c.pmf / leaf.area * d2 / cos_l;
    if pdf <= 0.0 {
        return no_light();
    }
    return LightSample(wi, dist, le / pdf, pdf);
}
