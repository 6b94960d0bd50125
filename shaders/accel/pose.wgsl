// Posing deforming meshes on the GPU, one invocation a vertex and shutter end: glTF 2.0's
// morph targets first, in the mesh's space (§3.7.2.2: p + sum of w_k x delta_k), then linear
// blend skinning (§3.7.3.3: sum of w_i x joint matrix_i), the joint matrices already carrying
// the object's transform and the scene's origin (an object that moves rigidly has one "joint",
// its transform). Normals by the weighted sum of the joints' inverse transposes, tangents by
// their linear parts, as the CPU's pose (scene/deform.rs) does.

struct PoseParams {
    vertex_count: u32,
    // 1, or 2 while the shutter is open (end 1: its open).
    ends: u32,
    // Matrices and morph weights of one end; end e's follow at e x these.
    matrices: u32,
    weights: u32,
}

var<uniform> pose_params: PoseParams;
// Per vertex: position (w: its object's record, bits), normal, tangent (w: handedness).
var<storage, read> rest: array<vec4f>;
// Per vertex: joints 0-3, joints 4-7 (global matrix indices), then weights 0-3, 4-7 as bits.
var<storage, read> influences: array<vec4u>;
// Per object: (first delta record, morph targets, first weight, first vertex).
var<storage, read> pose_objects: array<vec4u>;
// Per object, target and vertex: position, normal and tangent displacements.
var<storage, read> deltas: array<vec4f>;
// Per matrix: its four columns, then the three of its normal matrix.
var<storage, read> joint_mats: array<vec4f>;
var<storage, read> morph_weights: array<f32>;
// Per end and vertex: position, normal, tangent.
var<storage, read_write> posed: array<vec4f>;

// Whether every component is finite (bit tests: a NaN compare may be folded away).
fn finite3(v: vec3f) -> bool {
    let e = bitcast<vec3u>(v) & vec3u(0x7f800000u);
    return all(e != vec3u(0x7f800000u));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let i = gid.x + gid.y * 65535u * 64u;
    let n = pose_params.vertex_count;
    if i >= n * pose_params.ends {
        return;
    }
    let end = i / n;
    let v = i - end * n;
    let r = rest[v * 3u];
    var p = r.xyz;
    var nrm = rest[v * 3u + 1u].xyz;
    let t = rest[v * 3u + 2u];
    var tan = t.xyz;
    let o = pose_objects[bitcast<u32>(r.w) * 2u];
    let count = pose_objects[bitcast<u32>(r.w) * 2u + 1u].x;
    for (var k = 0u; k < o.y; k++) {
        let w = morph_weights[end * pose_params.weights + o.z + k];
        if w != 0.0 {
            let d = (o.x + k * count + (v - o.w)) * 3u;
            p += w * deltas[d].xyz;
            nrm += w * deltas[d + 1u].xyz;
            tan += w * deltas[d + 2u].xyz;
        }
    }
    let js = array<vec4u, 2>(influences[v * 4u], influences[v * 4u + 1u]);
    let ws = array<vec4f, 2>(bitcast<vec4f>(influences[v * 4u + 2u]), bitcast<vec4f>(influences[v * 4u + 3u]));
    var m = mat4x4f(vec4f(0.0), vec4f(0.0), vec4f(0.0), vec4f(0.0));
    var nm = mat3x3f(vec3f(0.0), vec3f(0.0), vec3f(0.0));
    for (var h = 0u; h < 2u; h++) {
        for (var c = 0u; c < 4u; c++) {
            let w = ws[h][c];
            if w > 0.0 {
                let j = (end * pose_params.matrices + js[h][c]) * 7u;
                m += w * mat4x4f(joint_mats[j], joint_mats[j + 1u], joint_mats[j + 2u], joint_mats[j + 3u]);
                nm += w * mat3x3f(joint_mats[j + 4u].xyz, joint_mats[j + 5u].xyz, joint_mats[j + 6u].xyz);
            }
        }
    }
    // What does not stay finite keeps its rest value: NaN and Inf never reach the trace.
    let pp = (m * vec4f(p, 1.0)).xyz;
    if finite3(pp) {
        p = pp;
    }
    let nn = nm * nrm;
    let nl = length(nn);
    nrm = select(vec3f(0.0, 0.0, 1.0), nn / nl, nl > 0.0 && finite3(nn / nl));
    let tt = (m * vec4f(tan, 0.0)).xyz;
    let tl = length(tt);
    tan = select(vec3f(1.0, 0.0, 0.0), tt / tl, tl > 0.0 && finite3(tt / tl));
    let at = (end * n + v) * 3u;
    posed[at] = vec4f(p, 0.0);
    posed[at + 1u] = vec4f(nrm, 0.0);
    posed[at + 2u] = vec4f(tan, t.w);
}
