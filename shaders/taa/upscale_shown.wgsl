// The upscaler's image shown (taa/upscale_common.wgsl): the denoised light's mean with a little
// of the spatial estimate (fill_weight), times the shown raster's averaged materials, moved towards the raw samples' mean where it is off by more
// than that mean's noise, by the weight taa/converge.wgsl derives (w = b^2 / (b^2 + v), over the
// 3x3 neighbourhood), with the weighted mean's effective sample count (sum w)^2 / sum w^2.

var up_mean: texture_2d<f32>;
var raw: texture_2d<f32>;
var raw_m2: texture_2d<f32>;
var albedo: texture_2d<f32>;
var emission: texture_2d<f32>;
var<storage, read_write> upscaled: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let o = gid.xy;
    if any(o >= up.out_size) {
        return;
    }
    let p = vec2i(o);
    let m = textureLoad(up_mean, p, 0);
    // The spatial estimate only where it still shows (by 1 / 1000 or more).
    var light = m.rgb;
    if up.fill_weight > 1e-3 * m.a {
        light = (m.rgb * m.a + up.fill_weight * spatial_estimate(o)) / (m.a + up.fill_weight);
    }
    var result = light * textureLoad(albedo, p, 0).rgb + textureLoad(emission, p, 0).rgb;
    let own = textureLoad(raw, p, 0);
    let own_m2 = textureLoad(raw_m2, p, 0);
    let own_n = select(0.0, own.a * own.a / own_m2.g, own_m2.g > 0.0);
    if up.bias_sigmas > 0.0 && own_n >= max(up.min_samples, 2.0) {
        var e2 = 0.0;
        var v = 0.0;
        for (var k = 0; k < 9; k++) {
            let q = p + neighbour_3x3(k);
            if any(q < vec2i(0)) || any(q >= vec2i(up.out_size)) {
                continue;
            }
            let a = textureLoad(raw, q, 0);
            let a2 = textureLoad(raw_m2, q, 0);
            let n = select(0.0, a.a * a.a / a2.g, a2.g > 0.0);
            if n < 2.0 {
                continue;
            }
            let s2 = max(a2.r - dot(a.rgb, a.rgb), 0.0) * (n / (n - 1.0));
            v += s2 / n;
            let shown = textureLoad(up_mean, q, 0).rgb * textureLoad(albedo, q, 0).rgb + textureLoad(emission, q, 0).rgb;
            let diff = shown - a.rgb;
            e2 += dot(diff, diff);
        }
        let b2 = max(e2 - up.bias_sigmas * v, 0.0);
        let w = select(0.0, b2 / (b2 + v), b2 + v > 0.0);
        result = mix(result, own.rgb, w);
    }
    upscaled[o.y * up.out_size.x + o.x] = vec4f(half_safe(result), 1.0);
}
