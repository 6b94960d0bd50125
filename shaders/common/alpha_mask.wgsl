// Alpha-masked materials cut their triangles out where base colour alpha < cutoff.
fn alpha_accept(slot: u32, b: vec2f) -> bool {
    let m = material(tri_material(slot));
    if (m.flags & MAT_ALPHA_MASK) == 0u {
        return true;
    }
    var a = m.base_color.a;
    if m.tex.x >= 0 {
        a *= tex_sample(u32(m.tex.x), tri_uv(slot, b)).a;
    }
    return a >= m.alpha_cutoff;
}
