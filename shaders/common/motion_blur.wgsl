// Objects may move while the shutter is open (an animated scene; engine/src/gpu/prepare.rs,
// PreparedScene::expose): each vertex moves linearly from where it is at the shutter's open
// (tri_open_texels) to where it is at its close (tri_texels), and a ray sees the scene at its own
// time in [0, 1] (set_ray_time; 1, the close, is also what the raster, the motion vectors and
// the emitter sampling use). The BVH bounds each triangle at both ends, so it holds it at every
// time between. Linear vertex motion is exact for translations and approximates rotations by
// their chord (the error of a rotation by a over the shutter is (1 - cos(a/2)) of the radius).
var tri_open_texels: texture_2d<f32>;

var<private> ray_time: f32 = 1.0;

fn set_ray_time(t: f32) {
    ray_time = t;
}

// Where in the shutter the ray is: 0 its open, 1 its close (common/instances.wgsl moves an
// instance's transform by it).
fn shutter_time() -> f32 {
    return ray_time;
}

fn tri_vertex(i: u32) -> vec3f {
    let close = tri_texel(i).xyz;
    if ray_time >= 1.0 {
        return close;
    }
    return mix(textureLoad(tri_open_texels, texel_at(i), 0).xyz, close, ray_time);
}

// A shading normal (stored for the close) turned with its triangle to the ray's time: by the
// smallest rotation taking the close-time face normal to the one at the ray's time (exact for a
// triangle's own normal; the shading normal's small tilt from it turns with it).
fn normal_at_ray_time(slot: u32, n: vec3f) -> vec3f {
    if ray_time >= 1.0 {
        return n;
    }
    let c0 = tri_texel(slot * 3u).xyz;
    let a = normalize(cross(tri_texel(slot * 3u + 1u).xyz - c0, tri_texel(slot * 3u + 2u).xyz - c0));
    let v0 = tri_vertex(slot * 3u);
    let b = normalize(cross(tri_vertex(slot * 3u + 1u) - v0, tri_vertex(slot * 3u + 2u) - v0));
    let c = dot(a, b);
    if c <= -0.999 {
        return n;
    }
    // Rodrigues with axis x sin = a x b and cos = a . b.
    let v = cross(a, b);
    return normalize(n * c + cross(v, n) + v * (dot(v, n) / (1.0 + c)));
}

// Moon et al. eq. (2): the world position sample of a hit at the ray's time, carried to the
// shutter's close by the object's motion (the same barycentrics on the close-time triangle, and
// an instance's transform at the close).
fn compensated_position(hit: Hit, p: vec3f) -> vec3f {
    let slot = hit.tri;
    let b = hit.b;
    let v0 = tri_texel(slot * 3u).xyz;
    return inst_close_point(hit.inst, v0 + b.x * (tri_texel(slot * 3u + 1u).xyz - v0) + b.y * (tri_texel(slot * 3u + 2u).xyz - v0));
}
