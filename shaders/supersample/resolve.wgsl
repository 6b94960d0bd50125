// Voorhuis §5, after filtering: each extra sample takes its guide's composited radiance, and the
// pixel is the mean of its guide and its extra samples.

var<storage, read_write> hdr: array<vec4f>;
var<storage, read_write> resolved: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.size) {
        return;
    }
    let pixel = gid.y * frame.size.x + gid.x;
    let extra = extra_samples();
    var sum = hdr[pixel].rgb;
    for (var j = 0u; j < extra; j++) {
        sum += hdr[ss_samples[pixel * extra + j].guide].rgb;
    }
    resolved[pixel] = vec4f(sum / f32(extra + 1u), 1.0);
}
