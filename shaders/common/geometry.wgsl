// Triangles in BVH leaf order: three vec4 per triangle, xyz = vertex; v0.w = material index,
// v1.w = index of the triangle in the scene's input order (both as bits).
var<storage, read> tris: array<vec4f>;
// The same records as texel rows (engine/src/gpu/scene.rs, Texels), for the intersection tests:
// lavapipe loads a texel per lane in one read, a storage buffer one word at a time.
var tri_texels: texture_2d<f32>;

// Texel i of a texel-row texture (rows of 1 << TEXEL_ROW_SHIFT texels).
const TEXEL_ROW_SHIFT: u32 = 12u;

fn texel_at(i: u32) -> vec2u {
    return vec2u(i & ((1u << TEXEL_ROW_SHIFT) - 1u), i >> TEXEL_ROW_SHIFT);
}

fn tri_texel(i: u32) -> vec4f {
    return textureLoad(tri_texels, texel_at(i), 0);
}

struct Hit {
    t: f32,
    // GPU triangle slot, or NO_HIT.
    tri: u32,
    // Barycentrics of v1 and v2.
    b: vec2f,
    // The object whose instance of a stored mesh was hit (its triangle in that mesh's space;
    // common/instances.wgsl), or NO_INSTANCE for a triangle stored in world space.
    inst: u32,
}

const NO_HIT: u32 = 0xffffffffu;
const NO_INSTANCE: u32 = 0xffffffffu;

fn miss() -> Hit {
    return Hit(INF, NO_HIT, vec2f(0.0), NO_INSTANCE);
}

fn tri_material(slot: u32) -> u32 {
    return bitcast<u32>(tri_texel(slot * 3u).w);
}

// Möller-Trumbore, both faces (sidedness is decided by the shader that shades the hit).
// Returns (t, b1, b2) with t = INF on a miss.
fn intersect_triangle(o: vec3f, d: vec3f, slot: u32, tmax: f32) -> vec3f {
    let v0 = tri_vertex(slot * 3u);
    let e1 = tri_vertex(slot * 3u + 1u) - v0;
    let e2 = tri_vertex(slot * 3u + 2u) - v0;
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if abs(det) < 1e-30 {
        return vec3f(INF, 0.0, 0.0);
    }
    let inv = 1.0 / det;
    let tv = o - v0;
    let b1 = dot(tv, pv) * inv;
    let qv = cross(tv, e1);
    let b2 = dot(d, qv) * inv;
    let t = dot(e2, qv) * inv;
    if b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 || t <= 0.0 || t >= tmax {
        return vec3f(INF, 0.0, 0.0);
    }
    return vec3f(t, b1, b2);
}

fn safe_inverse(d: vec3f) -> vec3f {
    let tiny = 1e-30;
    return 1.0 / select(d, select(vec3f(tiny), vec3f(-tiny), d < vec3f(0.0)), abs(d) < vec3f(tiny));
}

// Slab test; returns the entry distance or INF.
fn intersect_box(o: vec3f, inv_d: vec3f, lo: vec3f, hi: vec3f, tmax: f32) -> f32 {
    let t0 = (lo - o) * inv_d;
    let t1 = (hi - o) * inv_d;
    let tn = max3(min(t0, t1));
    let tf = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    if tn <= tf && tf >= 0.0 && tn < tmax {
        return max(tn, 0.0);
    }
    return INF;
}

// A binary node holding both children's boxes (engine/src/accel, Bvh2GpuNode): a child with
// a count is a leaf of that many primitives from its index, else the inner node at its index.
// The binary BVH layout (common/bvh2.wgsl) and the instances' top level (common/tlas.wgsl)
// store them, four texels each.
struct Bvh2Node {
    lmin: vec3f,
    l_index: u32,
    lmax: vec3f,
    l_count: u32,
    rmin: vec3f,
    r_index: u32,
    rmax: vec3f,
    r_count: u32,
}

fn bvh2_node_in(t: texture_2d<u32>, i: u32) -> Bvh2Node {
    let a = textureLoad(t, texel_at(i * 4u), 0);
    let b = textureLoad(t, texel_at(i * 4u + 1u), 0);
    let c = textureLoad(t, texel_at(i * 4u + 2u), 0);
    let d = textureLoad(t, texel_at(i * 4u + 3u), 0);
    return Bvh2Node(bitcast<vec3f>(a.xyz), a.w, bitcast<vec3f>(b.xyz), b.w, bitcast<vec3f>(c.xyz), c.w, bitcast<vec3f>(d.xyz), d.w);
}
