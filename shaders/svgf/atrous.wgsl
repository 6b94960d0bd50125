// SVGF §4.3: one level of the edge-avoiding a-trous wavelet filter (Dammertz et al. 2010):
// the 5x5 B3-spline kernel h (or a 3x3 one: svgf/kernel_*.wgsl) with taps 2^level pixels apart,
// weighted by eq. (3)-(5) (common.wgsl: edge_weight) with the luminance bandwidth
// sigma_l sqrt(g3x3(var)) of the pixel's variance blurred by a 3x3 Gaussian; Voorhuis eq. (8)
// widens it for young histories.
// The signal may bound the reach with a Gaussian of its own (signal_sigma: the glossy light's).
// Light accumulated from many samples runs only the first levels (SvgfSettings::settled_samples).
// The variance is filtered with the squared weights (eq. (6)) unless Voorhuis §6 turns that off,
// when every level uses the first level's. The first level's output is also next frame's
// history (Schied et al. §4.3: filtered, so the temporal stage accumulates smoother light).

var src: texture_2d<f32>;
var moments: texture_2d<f32>;
// The signal's features as the variance stage packed them (z, dz, oct normal; dz < 0: no
// surface), one record per pixel.
var taps: texture_2d<u32>;
var dst: texture_storage_2d<rgba16float, write>;
var out_history: texture_storage_2d<rgba32float, write>;
var<uniform> level: Level;

// The 3x3 Gaussian of the variance around p (SVGF's prefilter of eq. (5)).
fn blurred_variance(p: vec2i) -> f32 {
    var sum = 0.0;
    var wsum = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2i(dx, dy);
            if in_bounds(q) {
                let w = select(0.25, 0.5, dx == 0) * select(0.25, 0.5, dy == 0);
                sum += w * textureLoad(src, q, 0).a;
                wsum += w;
            }
        }
    }
    return sum / wsum;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let c = textureLoad(src, p, 0);
    var out = c;
    // Settled light (SvgfSettings::settled_samples): the wide levels pass it through.
    let samples = 1.0 / max(textureLoad(moments, p, 0).w, 1e-6);
    let settled = sv.settled_samples > 0.0 && samples >= sv.settled_samples && level.index >= sv.settled_levels;
    if has_surface(p) && !settled {
        // The pixel's own features come unpacked (exact normal); its taps' from the record.
        let fc = signal_features(p);
        let lc = luminance(c.rgb);
        var sigma_l = sv.sigma_l;
        if sv_on(SV_BANDWIDTH_BOOST) {
            // h counts frames; eq. (8) counts successful reprojections, one fewer.
            let reprojections = max(textureLoad(moments, p, 0).z - 1.0, 0.0);
            sigma_l *= 8.0 - min(7.0, reprojections);
        }
        let phi_l = sigma_l * sqrt(max(blurred_variance(p), 0.0));
        // The reach bound as the variance stage packed it (exact: the f32's bits), not
        // signal_sigma at every level: for the glossy light that loads the neighbours' ray
        // differentials, a sixth of the glossy a-trous on lavapipe (docs/decisions.md).
        let sigma = tap_reach(textureLoad(taps, p, 0));
        let k0 = kernel(0);
        var sum = c.rgb * (k0 * k0);
        var sum_var = c.a * (k0 * k0 * k0 * k0);
        var wsum = k0 * k0;
        for (var dy = -KERNEL_RADIUS; dy <= KERNEL_RADIUS; dy++) {
            for (var dx = -KERNEL_RADIUS; dx <= KERNEL_RADIUS; dx++) {
                let q = p + vec2i(dx, dy) * level.step;
                if (dx == 0 && dy == 0) || !in_bounds(q) {
                    continue;
                }
                let fq = tap_features(textureLoad(taps, q, 0));
                if fq.dz < 0.0 {
                    continue;
                }
                let t = textureLoad(src, q, 0);
                let offset = f32(level.step) * length(vec2f(f32(dx), f32(dy)));
                let spatial = exp(-0.5 * offset * offset / (sigma * sigma));
                let w = kernel(abs(dx)) * kernel(abs(dy)) * spatial * edge_weight(fc, fq, offset, lc, luminance(t.rgb), phi_l);
                sum += w * t.rgb;
                sum_var += w * w * t.a;
                wsum += w;
            }
        }
        out = vec4f(sum / wsum, c.a);
        if sv_on(SV_VARIANCE_FILTERING) {
            out.a = sum_var / (wsum * wsum);
        }
    }
    out = vec4f(half_safe(out.rgb), clamp(out.a, 0.0, 65000.0));
    textureStore(dst, p, out);
    if level.write_history != 0u && sv_on(SV_FILTERED_HISTORY) {
        textureStore(out_history, p, vec4f(out.rgb, 1.0));
    }
}
