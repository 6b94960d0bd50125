// Alpha-masked materials cut their triangles out where base colour alpha < cutoff.
fn alpha_accept(slot: u32, b: vec2f) -> bool {
    let m = material(tri_material(slot));
    if (m.flags & MAT_ALPHA_MASK) == 0u {
        return true;
    }
    let t = tri_tex_coords(slot, b);
    var a = m.base_color.a * t.color.a;
    if m.tex.x >= 0 {
        a *= material_texture(m, 0u, t).a;
    }
    return a >= m.alpha_cutoff;
}
