// Objects that draw a mesh stored once (engine/src/gpu/prepare/instances.rs): a hit on one is in
// the mesh's space (Hit.inst names the object), and these carry it to world space by the
// object's transform at the ray's time, linear between the shutter's open and close as vertices
// move in common/motion_blur.wgsl. Ten texels per object: world-from-mesh rows at the close
// (0-2), mesh-from-world rows at the close (3-5), world-from-mesh rows at the open (6-8), and
// (flags, the mesh tree's root node, 0, 0) as bits; an object stored in world space has flags 0.
var instance_texels: texture_2d<f32>;
// The raster's instances (realtime/gbuffer.wgsl): per instance of a draw, its object, four to a
// texel; NO_INSTANCE for the draws of world-space triangles.
var draw_list_texels: texture_2d<u32>;

const INSTANCE_TEXELS: u32 = 10u;
const INSTANCE_FLAG: u32 = 1u;
// The object's transform mirrors (a negative determinant).
const INSTANCE_MIRRORED: u32 = 2u;

struct Affine {
    r0: vec4f,
    r1: vec4f,
    r2: vec4f,
}

fn inst_row(inst: u32, k: u32) -> vec4f {
    return textureLoad(instance_texels, texel_at(inst * INSTANCE_TEXELS + k), 0);
}

fn affine_point(a: Affine, p: vec3f) -> vec3f {
    return vec3f(dot(a.r0.xyz, p) + a.r0.w, dot(a.r1.xyz, p) + a.r1.w, dot(a.r2.xyz, p) + a.r2.w);
}

fn affine_vector(a: Affine, v: vec3f) -> vec3f {
    return vec3f(dot(a.r0.xyz, v), dot(a.r1.xyz, v), dot(a.r2.xyz, v));
}

// The inverse by the adjugate: its columns are the cross products of the rows over the
// determinant.
fn affine_inverse(a: Affine) -> Affine {
    let c0 = cross(a.r1.xyz, a.r2.xyz);
    let c1 = cross(a.r2.xyz, a.r0.xyz);
    let c2 = cross(a.r0.xyz, a.r1.xyz);
    let inv_det = 1.0 / dot(a.r0.xyz, c0);
    let i0 = vec3f(c0.x, c1.x, c2.x) * inv_det;
    let i1 = vec3f(c0.y, c1.y, c2.y) * inv_det;
    let i2 = vec3f(c0.z, c1.z, c2.z) * inv_det;
    let t = vec3f(a.r0.w, a.r1.w, a.r2.w);
    return Affine(vec4f(i0, -dot(i0, t)), vec4f(i1, -dot(i1, t)), vec4f(i2, -dot(i2, t)));
}

fn world_from_mesh_close(inst: u32) -> Affine {
    return Affine(inst_row(inst, 0u), inst_row(inst, 1u), inst_row(inst, 2u));
}

fn world_from_mesh(inst: u32) -> Affine {
    let close = world_from_mesh_close(inst);
    let t = shutter_time();
    if t >= 1.0 {
        return close;
    }
    return Affine(mix(inst_row(inst, 6u), close.r0, t), mix(inst_row(inst, 7u), close.r1, t), mix(inst_row(inst, 8u), close.r2, t));
}

fn mesh_from_world(inst: u32) -> Affine {
    if shutter_time() >= 1.0 {
        return Affine(inst_row(inst, 3u), inst_row(inst, 4u), inst_row(inst, 5u));
    }
    return affine_inverse(world_from_mesh(inst));
}

fn inst_root(inst: u32) -> u32 {
    return bitcast<u32>(inst_row(inst, 9u).y);
}

fn inst_point(inst: u32, p: vec3f) -> vec3f {
    if inst == NO_INSTANCE {
        return p;
    }
    return affine_point(world_from_mesh(inst), p);
}

fn inst_vector(inst: u32, v: vec3f) -> vec3f {
    if inst == NO_INSTANCE {
        return v;
    }
    return affine_vector(world_from_mesh(inst), v);
}

// A normal of the mesh's space in world space (by the inverse transpose), not normalised: the
// same as the flattened triangle's, whose winding is swapped where the transform mirrors.
fn inst_normal(inst: u32, n: vec3f) -> vec3f {
    if inst == NO_INSTANCE {
        return n;
    }
    let x = mesh_from_world(inst);
    return n.x * x.r0.xyz + n.y * x.r1.xyz + n.z * x.r2.xyz;
}

// A unit shading normal of the mesh's space, in world space.
fn inst_shading_normal(inst: u32, n: vec3f) -> vec3f {
    if inst == NO_INSTANCE {
        return n;
    }
    return normalize(inst_normal(inst, n));
}

fn inst_close_point(inst: u32, p: vec3f) -> vec3f {
    if inst == NO_INSTANCE {
        return p;
    }
    return affine_point(world_from_mesh_close(inst), p);
}

fn inst_mirrored(inst: u32) -> bool {
    return inst != NO_INSTANCE && (bitcast<u32>(inst_row(inst, 9u).x) & INSTANCE_MIRRORED) != 0u;
}

// The instance a G-buffer object id names: the object where it draws a stored mesh.
fn instance_of_object(object: u32) -> u32 {
    if object == NO_HIT || (bitcast<u32>(inst_row(object, 9u).x) & INSTANCE_FLAG) == 0u {
        return NO_INSTANCE;
    }
    return object;
}

fn draw_instance(i: u32) -> u32 {
    return textureLoad(draw_list_texels, texel_at(i / 4u), 0)[i % 4u];
}
