// A mesh deforms (a skin or animated morph weights; engine/src/scene/deform.rs): every
// triangle's vertices at the previous frame are stored (tri_prev_texels,
// PreparedScene::tris_prev), and a surface point's previous position is its barycentric mix of
// them, exact for skinned, morphed, rigid and still surfaces alike. A point known only by its
// object (the temporal passes' depth tests) moves with the object's transform, the identity for a
// skinned mesh: where a skinned surface moved, its history fails that test and restarts rather
// than being reprojected by a guess.
var<storage, read> prev_from_current: array<mat4x4f>;
var tri_prev_texels: texture_2d<f32>;

fn previous_position(object: u32, p: vec3f) -> vec3f {
    let q = prev_from_current[object] * vec4f(p, 1.0);
    return q.xyz / q.w;
}

// The point at barycentrics b of triangle slot, at the previous frame.
fn previous_vertex(slot: u32, b: vec2f, object: u32, p: vec3f) -> vec3f {
    let v0 = textureLoad(tri_prev_texels, texel_at(slot * 3u), 0).xyz;
    let v1 = textureLoad(tri_prev_texels, texel_at(slot * 3u + 1u), 0).xyz;
    let v2 = textureLoad(tri_prev_texels, texel_at(slot * 3u + 2u), 0).xyz;
    return v0 + b.x * (v1 - v0) + b.y * (v2 - v0);
}
