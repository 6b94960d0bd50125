// SVGF's output for the composite: the last a-trous level remodulated where the signal was
// demodulated (behind mirrors), and where the signal is diffuse light (signal_diffuse: the matte
// light, the glossy light behind mirrors) Voorhuis §6's firefly suppression: the 3x3 neighbour of
// median luminance among the neighbours where it is too, outside the history loop (the next
// frame's history is untouched).

var src: texture_2d<f32>;
var dst: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    var c = textureLoad(src, p, 0).rgb;
    if sv_on(SV_FIREFLY) && signal_diffuse(p) {
        var values: array<vec3f, 9>;
        var lum: array<f32, 9>;
        var n = 0;
        for (var k = 0; k < 9; k++) {
            let q = p + neighbour_3x3(k);
            if in_bounds(q) && signal_diffuse(q) {
                values[n] = textureLoad(src, q, 0).rgb;
                lum[n] = luminance(values[n]);
                n++;
            }
        }
        // The element of rank n / 2 by luminance: the one with as many darker as brighter.
        for (var i = 0; i < n; i++) {
            var below = 0;
            var equal = 0;
            for (var j = 0; j < n; j++) {
                below += select(0, 1, lum[j] < lum[i]);
                equal += select(0, 1, lum[j] == lum[i]);
            }
            if below <= n / 2 && n / 2 < below + equal {
                c = values[i];
                break;
            }
        }
    }
    textureStore(dst, p, vec4f(half_safe(c * signal_remodulation(p)), 1.0));
}
