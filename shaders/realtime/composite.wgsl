// Composite: the denoiser's light remodulated with the material (realtime/remodulate.wgsl).
// Writes linear HDR radiance; in accumulate mode also adds it to the running sum (converging
// to the reference image while the camera is still).

var<storage, read_write> hdr: array<vec4f>;
var<storage, read_write> accumulation: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let px = gid.xy;
    if px.x >= frame.size.x || px.y >= frame.size.y {
        return;
    }
    let l = remodulated(px);
    let i = px.y * frame.size.x + px.x;
    hdr[i] = vec4f(l, 1.0);
    if frame.accumulated > 0u {
        let a = select(vec4f(0.0), accumulation[i], frame.accumulated > 1u);
        accumulation[i] = vec4f(a.rgb + l, 0.0);
    }
}
