// The current glossy light pre-blurred by a two-pass 7x7 Gaussian (sigma 1.5 px): the
// neighbourhood the glossy temporal clips its history to (Voorhuis §4.2.3). At one sample per
// pixel the raw neighbourhoods of adjacent pixels differ too much to clip against; blurred ones
// agree.

var src: texture_2d<f32>;
var dst: texture_storage_2d<rgba16float, write>;

// exp(-k^2 / (2 x 1.5^2)) for k = 0..3.
const PREFILTER_W = array<f32, 4>(1.0, 0.80074, 0.41111, 0.13534);

fn prefilter(p: vec2i, axis: vec2i, from_trace: bool) -> vec3f {
    var sum = vec3f(0.0);
    var wsum = 0.0;
    for (var k = -3; k <= 3; k++) {
        let q = clamp(p + axis * k, vec2i(0), vec2i(frame.size) - 1);
        var v: vec3f;
        if from_trace {
            v = glossy_input(q);
        } else {
            v = half_safe(textureLoad(src, q, 0).rgb);
        }
        let w = PREFILTER_W[abs(k)];
        sum += v * w;
        wsum += w;
    }
    return sum / wsum;
}

@compute @workgroup_size(8, 8)
fn pre_h(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if in_bounds(p) {
        textureStore(dst, p, vec4f(prefilter(p, vec2i(1, 0), true), 1.0));
    }
}

@compute @workgroup_size(8, 8)
fn pre_v(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if in_bounds(p) {
        textureStore(dst, p, vec4f(prefilter(p, vec2i(0, 1), false), 1.0));
    }
}
