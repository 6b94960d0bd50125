// The image shown in a still view: TAA's image D moved towards the plain mean A of the pixel's
// samples (taa/converge_mean.wgsl) by the weight that minimises the expected squared error of
// their convex combination (A unbiased with variance v, D's error taken as bias b):
//   w = b^2 / (b^2 + v),   b^2 = max(E[(D - A)^2] - bias_sigmas x v, 0),
// both estimated over the 3x3 neighbourhood (the mean's variance from its samples' variance
// over n). Where D is right within A's noise, w stays near 0 and the filtered image is shown;
// where D keeps a bias the samples have outgrown (a pixel whose jittered samples fall on two
// surfaces: TAA shows the product of the averaged material and light there, and the mean the
// average of the products), w grows as v falls, so the image ends at the mean of every sample.
// D's error counts as bias even where it is noise: D is the smoother estimate there, and its
// squared error still adds to the difference.

var mean: texture_2d<f32>;
var m2: texture_2d<f32>;
var<storage, read> taa_image: array<vec4f>;
var<storage, read_write> shown: array<vec4f>;

fn taa_at(q: vec2i) -> vec3f {
    return taa_image[u32(q.y) * frame.size.x + u32(q.x)].rgb;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let px = gid.xy;
    if px.x >= frame.size.x || px.y >= frame.size.y {
        return;
    }
    let p = vec2i(px);
    let i = px.y * frame.size.x + px.x;
    let d = taa_image[i].rgb;
    let own = textureLoad(mean, p, 0);
    var result = d;
    if cv.bias_sigmas > 0.0 && own.a >= max(cv.min_samples, 2.0) {
        var e2 = 0.0;
        var v = 0.0;
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let q = p + vec2i(dx, dy);
                if any(q < vec2i(0)) || any(q >= vec2i(frame.size)) {
                    continue;
                }
                let a = textureLoad(mean, q, 0);
                if a.a < 2.0 {
                    continue;
                }
                // The samples' variance summed over the channels (unbiased), over n: the
                // mean's.
                let s2 = max(textureLoad(m2, q, 0).r - dot(a.rgb, a.rgb), 0.0) * (a.a / (a.a - 1.0));
                v += s2 / a.a;
                let diff = taa_at(q) - a.rgb;
                e2 += dot(diff, diff);
            }
        }
        let b2 = max(e2 - cv.bias_sigmas * v, 0.0);
        let w = select(0.0, b2 / (b2 + v), b2 + v > 0.0);
        result = mix(d, own.rgb, w);
    }
    shown[i] = vec4f(half_safe(result), 1.0);
}
