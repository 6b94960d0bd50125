// The refit tree's surface-area cost relative to its root's area (accel/refit.rs's sah_cost
// as refit_wide counts it): the sum of every node's cost (accel/refit.wgsl) in one workgroup.

struct CostParams {
    nodes: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

var<uniform> cost_params: CostParams;
var<storage, read> node_cost: array<f32>;
var<storage, read> exact: array<vec4f>;
var<storage, read_write> cost_out: array<f32>;

var<workgroup> partial: array<f32, 256>;

@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) li: u32) {
    var sum = 0.0;
    for (var i = li; i < cost_params.nodes; i += 256u) {
        sum += node_cost[i];
    }
    partial[li] = sum;
    workgroupBarrier();
    for (var w = 128u; w > 0u; w >>= 1u) {
        if li < w {
            partial[li] += partial[li + w];
        }
        workgroupBarrier();
    }
    if li == 0u {
        let d = max(exact[1].xyz - exact[0].xyz, vec3f(0.0));
        let area = max(d.x * d.y + d.y * d.z + d.z * d.x, 1.2e-38);
        cost_out[0] = partial[0] / area;
    }
}
