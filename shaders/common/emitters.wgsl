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
    return light_tree_pmf(leaf, p, n) / light_leaf_area(leaf);
}

// A point on emitter triangle `slot` from b2 in [0, 1)^2 (uniform in its area), as seen from p
// (common/path.wgsl `EmitterPoint`; 0 from its back: only the counter-clockwise face emits).
fn emitter_point(slot: u32, b2: vec2f, p: vec3f) -> EmitterPoint {
    // The vertices as texels (at the shutter's close where objects move): one fetch a vertex
    // instead of the storage buffer's per-word reads.
    let v0 = tri_texel(slot * 3u).xyz;
    let e1 = tri_texel(slot * 3u + 1u).xyz - v0;
    let e2 = tri_texel(slot * 3u + 2u).xyz - v0;
    let su = sqrt(b2.x);
    let b = vec2f(1.0 - su, b2.y * su);
    let q = v0 + b.x * e1 + b.y * e2;
    let ng = normalize(cross(e1, e2));
    let v = q - p;
    let d2 = dot(v, v);
    let dist = sqrt(d2);
    let wi = v / dist;
    let cos_l = -dot(ng, wi);
    if cos_l <= 0.0 || d2 <= 0.0 {
        return EmitterPoint(vec3f(0.0, 0.0, 1.0), 0.0, vec3f(0.0), 0.0);
    }
    let m = material(tri_material(slot));
    var le = m.emission;
    if m.tex.w >= 0 {
        le *= material_texture(m, 3u, tri_tex_coords(slot, b)).rgb;
    }
    return EmitterPoint(wi, dist, le, cos_l / d2);
}

fn emitter_leaf_slot(leaf: u32) -> u32 {
    return light_child(leaf) & ~LIGHT_LEAF;
}

// An emitter chosen by the tree for p, n with u.x (slot NO_EMITTER where none can light p), and
// the area density of its point: the tree's pmf over the triangle's area.
fn choose_emitter(p: vec3f, n: vec3f, u: f32) -> EmitterChoice {
    let c = light_tree_sample(p, n, u);
    if c.pmf <= 0.0 {
        return EmitterChoice(NO_EMITTER, 0.0);
    }
    return EmitterChoice(emitter_leaf_slot(c.node), c.pmf / light_leaf_area(c.node));
}

// One emitter's point for the surface at p with geometric normal n (zero: none): u.x walks the
// tree, u.yz place the point in the triangle.
fn sample_emitter(p: vec3f, n: vec3f, u: vec3f) -> LightSample {
    let c = light_tree_sample(p, n, u.x);
    if c.pmf <= 0.0 {
        return no_light();
    }
    let e = emitter_point(emitter_leaf_slot(c.node), u.yz, p);
    if e.g <= 0.0 {
        return no_light();
    }
    let pdf = c.pmf / light_leaf_area(c.node) / e.g;
    if !(pdf > 0.0) {
        return no_light();
    }
    return LightSample(e.wi, e.dist, e.le / pdf, pdf);
}
