// A mesh deforms (a skin or animated morph weights; engine/src/scene/deform.rs): every
// world-space triangle's vertices at the previous frame are stored (tri_prev_texels,
// PreparedScene::tris_prev), and a surface point's previous position is its barycentric mix of
// them, exact for skinned, morphed, rigid and still surfaces alike. The temporal passes know a
// pixel's triangle by its G-buffer ids and find the point's barycentrics in the triangle's
// current vertices (tri_now_texels, the scene's triangle texels). Self-contained (the passes
// that reproject compose no scene code): its texel addressing is the scene's
// (common/geometry.wgsl, texel_at).
var<storage, read> prev_from_current: array<mat4x4f>;
var tri_now_texels: texture_2d<f32>;
var tri_prev_texels: texture_2d<f32>;

fn motion_texel4(t: texture_2d<f32>, i: u32) -> vec4f {
    return textureLoad(t, vec2u(i & 4095u, i >> 12u), 0);
}

fn motion_texel(t: texture_2d<f32>, i: u32) -> vec3f {
    return motion_texel4(t, i).xyz;
}

fn previous_position(object: u32, p: vec3f) -> vec3f {
    let q = prev_from_current[object] * vec4f(p, 1.0);
    return q.xyz / q.w;
}

// An instanced mesh's triangles are stored once in the mesh's space, and their previous
// vertices' w is 1 (PreparedScene::tris_prev; 0 elsewhere): a point on them moves with its
// instance's transform.
fn instanced_slot(slot: u32) -> bool {
    return motion_texel4(tri_prev_texels, slot * 3u).w > 0.5;
}

// The point at barycentrics b of triangle slot, at the previous frame.
fn previous_vertex(slot: u32, b: vec2f, object: u32, p: vec3f) -> vec3f {
    if instanced_slot(slot) {
        return previous_position(object, p);
    }
    let v0 = motion_texel(tri_prev_texels, slot * 3u);
    let v1 = motion_texel(tri_prev_texels, slot * 3u + 1u);
    let v2 = motion_texel(tri_prev_texels, slot * 3u + 2u);
    return v0 + b.x * (v1 - v0) + b.y * (v2 - v0);
}

// Where the surface point x of the pixel with G-buffer ids (object, triangle slot) was at the
// previous frame: its barycentrics in the triangle now, carried to the triangle then.
fn previous_surface(ids: vec2u, x: vec3f) -> vec3f {
    let slot = ids.y;
    if instanced_slot(slot) {
        return previous_position(ids.x, x);
    }
    let v0 = motion_texel(tri_now_texels, slot * 3u);
    let e1 = motion_texel(tri_now_texels, slot * 3u + 1u) - v0;
    let e2 = motion_texel(tri_now_texels, slot * 3u + 2u) - v0;
    let d = x - v0;
    let d11 = dot(e1, e1);
    let d12 = dot(e1, e2);
    let d22 = dot(e2, e2);
    let den = d11 * d22 - d12 * d12;
    if !(abs(den) > 0.0) {
        return previous_position(ids.x, x);
    }
    let b = vec2f(d22 * dot(d, e1) - d12 * dot(d, e2), d11 * dot(d, e2) - d12 * dot(d, e1)) / den;
    // The part of x off the triangle's plane (depth rounding) moves with it unchanged.
    let on_plane = v0 + b.x * e1 + b.y * e2;
    return previous_vertex(slot, b, ids.x, x) + (x - on_plane);
}
