// The posed vertices (accel/pose.wgsl) into the moving part's triangle slots, one invocation a
// slot: positions into the scene's `tris`, normals into the slots' shading records and tangent
// directions into `tangents`, the shutter's open ends into `posed_open`. What a slot holds
// beside them (material, input index, UVs, object, handedness) stays as the last CPU
// flattening wrote it.

struct SlotParams {
    slots: u32,
    // The moving part's first slot among the scene's.
    slot_base: u32,
    ends: u32,
    vertex_count: u32,
}

var<uniform> slot_params: SlotParams;
// Per moving slot: its three vertices among the posed ones (in the winding the slot keeps).
var<storage, read> slot_verts: array<vec4u>;
var<storage, read> posed: array<vec4f>;
var<storage, read_write> tris: array<vec4f>;
// Per moving slot four shading texels and the three vertices at the shutter's open; per scene
// slot three tangents (a scene without normal maps binds a stand-in too short to hold any).
var<storage, read_write> posed_shading: array<vec4f>;
var<storage, read_write> posed_tangents: array<vec4f>;
var<storage, read_write> posed_open: array<vec4f>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let s = gid.x + gid.y * 65535u * 64u;
    if s >= slot_params.slots {
        return;
    }
    let vs = slot_verts[s];
    let g = (slot_params.slot_base + s) * 3u;
    let open = slot_params.ends - 1u;
    let tangents = arrayLength(&posed_tangents) >= g + 3u;
    for (var k = 0u; k < 3u; k++) {
        let v = vs[k] * 3u;
        tris[g + k] = vec4f(posed[v].xyz, tris[g + k].w);
        posed_shading[s * 4u + k] = vec4f(posed[v + 1u].xyz, posed_shading[s * 4u + k].w);
        if tangents {
            posed_tangents[g + k] = vec4f(posed[v + 2u].xyz, posed_tangents[g + k].w);
        }
        let o = (open * slot_params.vertex_count * 3u) + v;
        posed_open[s * 3u + k] = vec4f(posed[o].xyz, 0.0);
    }
}
