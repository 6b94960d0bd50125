// Dundr §4.4 and §5: one level of the edge-avoiding a-trous filter with the 3x3 kernel
// (1/4, 1/2, 1/4 per axis), taps `step` pixels apart, large scale first. Taps without a sample
// (variance < 0) are skipped; a pixel without one takes its neighbours' weighted mean (without
// a luminance weight) and so has a sample for the next level. The variance follows the weights
// (Dundr's var_{L+1} = w^2 var_L, normalised as the variance of the weighted mean:
// sum w^2 var / (sum w)^2). The direct light's levels only fill missing pixels. In a still view
// a level of step s passes on light of more than reach_samples x (16 / s)^2 samples unfiltered
// (Hush's; Dundr runs every level at every pixel).
// The feedback level (step 1, run first; ProgressiveSettings::feedback_samples) also writes its
// output as the history of each pixel traced this frame whose history is young (§4.4, §5).

var src: texture_2d<f32>;
// The light's moments (m1, m2, age): the age sets the luminance weight's epsilon and the reach.
var moments: texture_2d<f32>;
var dst: texture_storage_2d<rgba16float, write>;
// The temporal stage's output, next frame's history (the feedback level only).
var out_history: texture_storage_2d<rgba32float, write>;
var<uniform> level: Level;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let c = textureLoad(src, p, 0);
    let missing = c.a < 0.0;
    let f = textureLoad(features, p, 0);
    let fc = f.xy;
    if fc.x < 0.0 || (level.fill_only != 0u && !missing) {
        textureStore(dst, p, c);
        return;
    }
    let age = textureLoad(moments, p, 0).z;
    // The filter's reach falls as the samples grow (ProgressiveSettings::reach_samples): a
    // level of step s filters only light of at most reach_samples x (16 / s)^2 samples, so its
    // area times the light's samples stays bounded. The feedback level passes such light on
    // at its end, after writing the history. A pixel without samples (age 0) is filled by
    // every level.
    let s16 = 16.0 / f32(level.step);
    let reach_ended = frame.static_view != 0u && pp.reach_samples > 0.0 && age > pp.reach_samples * s16 * s16;
    if reach_ended && level.feedback == 0u {
        textureStore(dst, p, c);
        return;
    }
    let nc = oct_decode(f.zw);
    let lc = select(luma(c.rgb), -1.0, missing);
    // The luminance weight in displayed light (the light times the exposure, its variance times
    // the exposure squared), here in the light's own units: epsilon is an amount of light on
    // the screen, so a scene lit far below the display's white, shown brighter, is not blurred
    // across its gradients the more for its dimness.
    let k = frame.exposure;
    let epsilon = luminance_epsilon(age) / k;
    let variance = max(c.a, 0.0) * k;
    var sum = vec3f(0.0);
    var sum_var = 0.0;
    var wsum = 0.0;
    if !missing {
        sum = c.rgb * 0.25;
        sum_var = c.a * 0.0625;
        wsum = 0.25;
    }
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2i(dx, dy) * level.step;
            if (dx == 0 && dy == 0) || !in_bounds(q) {
                continue;
            }
            let t = textureLoad(src, q, 0);
            let g = textureLoad(features, q, 0);
            let fq = g.xy;
            if t.a < 0.0 || fq.x < 0.0 {
                continue;
            }
            let nq = oct_decode(g.zw);
            let h = 0.25 * select(0.5, 1.0, dx == 0) * select(0.5, 1.0, dy == 0);
            let offset = f32(level.step) * length(vec2f(f32(dx), f32(dy)));
            // w_L with the larger of the two variances, not the centre's alone (Dundr's): the
            // weight is then symmetric, so a pixel holding a rare bright sample (a large
            // variance) gives its light to the neighbours whose light it takes. With the
            // centre's, they refused it while it took theirs, and the filter lost 5% of the
            // level's light at four samples (ProgressiveSettings::symmetric_luminance). The
            // tap's variance counts up to variance_cap x the centre's, so that one bright path
            // is not spread over a patch (ProgressiveSettings::variance_cap).
            let tv = t.a * k;
            let capped = select(tv, min(tv, pp.variance_cap * variance), pp.variance_cap > 0.0);
            let v = select(variance, max(variance, capped), pp.symmetric_luminance != 0u);
            let w = h * dundr_weight(fc, nc, lc, v, epsilon, fq, nq, luma(t.rgb), offset);
            sum += w * t.rgb;
            sum_var += w * w * t.a;
            wsum += w;
        }
    }
    if wsum <= 0.0 {
        textureStore(dst, p, c);
        return;
    }
    let filtered = half_safe(sum / wsum);
    let out = select(vec4f(filtered, clamp(sum_var / (wsum * wsum), 0.0, 60000.0)), c, reach_ended);
    textureStore(dst, p, out);
    // A pixel whose history took a sample this frame (§5: once per sample, not every frame)
    // takes the filtered light; the others get back the light they had (the variance stage's
    // output is 32-bit for that). The store is under a uniform branch: lavapipe (Mesa 22.3)
    // crashes on a storage store under a branch that diverges on a float comparison.
    if level.feedback != 0u {
        let feed = !missing && traced_this_frame(vec2u(p)) && age < pp.feedback_samples;
        textureStore(out_history, p, vec4f(select(c.rgb, filtered, feed), 1.0));
    }
}
