// Alpha-masked materials cut their triangles out where base colour alpha < cutoff; blended ones
// (stochastic transparency) are seen with probability alpha: a hit is accepted where a number
// uniform in [0, 1), hashed from the ray (or the raster's pixel and frame) and the triangle, is
// below alpha. Every ray and frame draws anew, so each mean converges to glTF's "over" blend;
// one ray meets a triangle with one draw, so a path and its shadow rays agree with themselves.
fn alpha_accept(slot: u32, b: vec2f, ray: u32) -> bool {
    let m = material(tri_material(slot));
    if (m.flags & (MAT_ALPHA_MASK | MAT_ALPHA_BLEND)) == 0u {
        return true;
    }
    let t = tri_tex_coords(slot, b);
    var a = m.base_color.a * t.color.a;
    if m.tex.x >= 0 {
        a *= material_texture(m, 0u, t).a;
    }
    if (m.flags & MAT_ALPHA_BLEND) != 0u {
        return f32(pcg_hash(ray ^ pcg_hash(slot)) >> 8u) * (1.0 / 16777216.0) < a;
    }
    return a >= m.alpha_cutoff;
}

// A ray's draw: its origin and direction bits hashed (different for every sample and bounce).
fn alpha_ray(o: vec3f, d: vec3f) -> u32 {
    let a = bitcast<vec3u>(o);
    let b = bitcast<vec3u>(d);
    return pcg_hash(a.x ^ pcg_hash(a.y ^ pcg_hash(a.z ^ pcg_hash(b.x ^ pcg_hash(b.y ^ pcg_hash(b.z))))));
}

// The raster's draw for a pixel in a frame.
fn alpha_raster(pixel: vec2u, frame_index: u32) -> u32 {
    return pcg_hash(pixel.x ^ pcg_hash(pixel.y ^ pcg_hash(frame_index)));
}
