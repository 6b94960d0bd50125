// SVGF's output for the composite: the last a-trous level remodulated where the signal was
// demodulated (behind mirrors), and Voorhuis §6's firefly suppression outside the history loop,
// on diffuse light (signal_diffuse: the matte light, the glossy light behind mirrors) that has
// not settled: a pixel brighter than all eight neighbours is brought down to the brightest of
// them, which keeps thin lit lines that the paper's 3x3 median erases (docs/decisions.md).

var src: texture_2d<f32>;
var moments: texture_2d<f32>;
var dst: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    var c = textureLoad(src, p, 0).rgb;
    let m = textureLoad(moments, p, 0);
    let worth = 1.0 / max(m.w, 1e-6);
    // Settled light (SvgfSettings::settled_samples) has averaged its fireflies away.
    let settled = sv.settled_samples > 0.0 && worth >= sv.settled_samples;
    if sv_on(SV_FIREFLY) && signal_diffuse(p) && !settled {
        // A firefly is brighter than all its neighbours: it is brought down to the brightest of
        // them. A thin bright line keeps its neighbours along the line, and its light.
        var brightest = -1.0;
        var value = c;
        for (var k = 1; k < 9; k++) {
            let q = p + neighbour_3x3(k);
            if in_bounds(q) && signal_diffuse(q) {
                let v = textureLoad(src, q, 0).rgb;
                let l = luminance(v);
                if l > brightest {
                    brightest = l;
                    value = v;
                }
            }
        }
        if brightest >= 0.0 && luminance(c) > brightest {
            c = value;
        }
    }
    textureStore(dst, p, vec4f(half_safe(c * signal_remodulation(p)), 1.0));
}
