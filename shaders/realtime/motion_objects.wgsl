// Animated scene: per object, the rebased transform from where a point is now to where it was
// in the previous frame (PreparedScene::prev_from_current).
var<storage, read> prev_from_current: array<mat4x4f>;

fn previous_position(object: u32, p: vec3f) -> vec3f {
    let q = prev_from_current[object] * vec4f(p, 1.0);
    return q.xyz / q.w;
}

// A point on triangle slot at barycentrics b: it moves with its object.
fn previous_vertex(slot: u32, b: vec2f, object: u32, p: vec3f) -> vec3f {
    return previous_position(object, p);
}

// The surface point x of the pixel with G-buffer ids (object, triangle slot): it moves with
// its object.
fn previous_surface(ids: vec2u, x: vec3f) -> vec3f {
    return previous_position(ids.x, x);
}
