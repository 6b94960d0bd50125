// Tangents (xyz, w = handedness), three vec4 per triangle, for tangent-space normal maps.
var<storage, read> tangents: array<vec4f>;

fn apply_normal_map(slot: u32, b: vec2f, ns: vec3f, tc: TexCoords, m: Material) -> vec3f {
    if m.tex.z < 0 {
        return ns;
    }
    let w = vec3f(1.0 - b.x - b.y, b.x, b.y);
    let t4 = w.x * tangents[slot * 3u] + w.y * tangents[slot * 3u + 1u] + w.z * tangents[slot * 3u + 2u];
    // Gram-Schmidt against the (possibly flipped) shading normal.
    let t = t4.xyz - ns * dot(ns, t4.xyz);
    if dot(t, t) < 1e-20 {
        return ns;
    }
    let tn = normalize(t);
    let bn = cross(ns, tn) * select(1.0, -1.0, t4.w < 0.0);
    var c = material_texture(m, 2u, tc).xyz * 2.0 - 1.0;
    // Under KHR_texture_transform the map's x and y run along the transformed coordinates.
    c = vec3f(texture_frame(m, 2u, c.xy * m.normal_scale), c.z);
    let n = tn * c.x + bn * c.y + ns * c.z;
    let len = length(n);
    return select(ns, n / len, len > 1e-12 && len < 1e30);
}
