// The still-view mean: each pixel's running mean of its own samples (the trace's light
// remodulated, realtime/remodulate.wgsl) since the view settled, with the count in alpha, and
// the mean of their squared length (the sum of the channels' second moments). This is what the
// accumulate mode sums, over TAA's jitter: the box-filtered pixel. A pixel not traced this frame
// (sub-1-spp) keeps its mean.

var mean_history: texture_2d<f32>;
var m2_history: texture_2d<f32>;
var out_mean: texture_storage_2d<rgba32float, write>;
var out_m2: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let px = gid.xy;
    if px.x >= frame.size.x || px.y >= frame.size.y {
        return;
    }
    let p = vec2i(px);
    var mean = vec4f(0.0);
    var m2 = 0.0;
    if cv.continues != 0u {
        mean = textureLoad(mean_history, p, 0);
        m2 = textureLoad(m2_history, p, 0).r;
        let finite = all(mean == mean) && all(abs(mean) <= vec4f(3.0e38)) && m2 == m2 && m2 <= 3.0e38;
        if !finite || mean.a < 0.0 {
            mean = vec4f(0.0);
            m2 = 0.0;
        }
    }
    if traced_this_frame(px) {
        let x = remodulated(px);
        let n = mean.a + 1.0;
        mean = vec4f(mean.rgb + (x - mean.rgb) / n, n);
        m2 += (dot(x, x) - m2) / n;
    }
    textureStore(out_mean, p, mean);
    textureStore(out_m2, p, vec4f(m2, 0.0, 0.0, 0.0));
}
