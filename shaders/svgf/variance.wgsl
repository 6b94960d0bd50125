// SVGF §4.2: the luminance variance that steers the a-trous filter. Where the history holds at
// least 4 frames it is the temporal moments' m2 - m1^2; where fewer, a 7x7 estimate across the
// surface (depth and normal weights): of this frame's luminance (Schied et al.), or of the
// neighbours' accumulated moments (Voorhuis §6), and the light is averaged with the same
// weights. As Falcor's SVGFPass, the young variance is raised by 4 / h, since it is drawn from
// few samples and underestimates. Output: dst (rgb, variance), and the signal's features packed
// into one 16-byte texel per pixel for the a-trous levels and the regression (out_taps: z, dz,
// oct normal, the signal's reach bound signal_sigma; dz < 0 where there is no surface), so that
// each of their taps loads the light and one record instead of four to seven texels. The record
// is an Rgba32Uint texture, not a storage buffer: a texel load is one 16-byte load per lane on a
// CPU driver, a storage-buffer read at per-lane addresses a loop over the lanes (docs/decisions.md).
// It also writes the light the regression's spike cut takes off the pixel (out_excess; below).

var integrated: texture_2d<f32>;
var moments: texture_2d<f32>;
var dst: texture_storage_2d<rgba16float, write>;
var out_taps: texture_storage_2d<rgba32uint, write>;
var out_excess: texture_storage_2d<rgba16float, write>;

// A pixel's samples' mean square over this many times their mean's square: one rare path makes
// most of their spread. Monte Carlo noise of a diffuse surface stays near 1 + cv^2 (about 3 in
// cornell_diffuse), one path among n of a pixel's samples that carries its light gives about n.
// A small highlight that every frame sees (a lamp in a mirror) stays near 1 and is not cut.
const SPIKE_SPREAD: f32 = 8.0;

// The spike cut (SvgfSettings::spike_ratio): the light over spike_ratio times the second
// brightest of the pixel's eight neighbours on its surface, where one rare path makes most of its
// samples' spread (a caustic's path through a mirror to the light). The second brightest, not
// the brightest or the mean: along a lit line or an edge's lit side a pixel has at least two
// neighbours as bright, so only a lone pixel is cut. The regression fits what is left and spreads
// the cut light over a window (svgf/regression.wgsl), so it is moved, not lost.
fn spike_excess(p: vec2i, fc: Features, c: vec3f, m: vec4f) -> vec3f {
    if sv.spike_ratio <= 0.0 || !sv_on(SV_REGRESSION) || m.y <= SPIKE_SPREAD * m.x * m.x {
        return vec3f(0.0);
    }
    var first = 0.0;
    var second = 0.0;
    var count = 0;
    for (var k = 1; k < 9; k++) {
        let q = p + neighbour_3x3(k);
        if !in_bounds(q) || !has_surface(q) || edge_weight(fc, signal_features(q), 1.0, 0.0, 0.0, 1.0) < 0.05 {
            continue;
        }
        let l = luminance(textureLoad(integrated, q, 0).rgb);
        second = max(second, min(first, l));
        first = max(first, l);
        count++;
    }
    let l = luminance(c);
    if count < 3 || l <= sv.spike_ratio * second {
        return vec3f(0.0);
    }
    return c * (1.0 - sv.spike_ratio * second / l);
}

fn pack_taps(f: Features, reach: f32) -> vec4u {
    return vec4u(bitcast<u32>(f.z), bitcast<u32>(f.dz), pack2x16snorm(oct_encode(f.n)), bitcast<u32>(reach));
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let c = textureLoad(integrated, p, 0);
    let m = textureLoad(moments, p, 0);
    let h = m.z;
    if !has_surface(p) {
        textureStore(dst, p, vec4f(c.rgb, 0.0));
        textureStore(out_excess, p, vec4f(0.0));
        textureStore(out_taps, p, pack_taps(Features(0.0, -1.0, vec3f(0.0, 0.0, 1.0)), 0.0));
        return;
    }
    let fc = signal_features(p);
    textureStore(out_taps, p, pack_taps(fc, signal_sigma(p)));
    if h >= 4.0 || !sv_on(SV_SPATIAL_VARIANCE) {
        textureStore(dst, p, vec4f(c.rgb, steering_variance(m.y - m.x * m.x, m)));
        textureStore(out_excess, p, vec4f(half_safe(spike_excess(p, fc, c.rgb, m)), 0.0));
        return;
    }
    var sum_w = 0.0;
    var sum_light = vec3f(0.0);
    var sum_m = vec2f(0.0);
    for (var dy = -3; dy <= 3; dy++) {
        for (var dx = -3; dx <= 3; dx++) {
            let q = p + vec2i(dx, dy);
            if !in_bounds(q) || !has_surface(q) {
                continue;
            }
            let t = textureLoad(integrated, q, 0);
            var w = 1.0;
            if dx != 0 || dy != 0 {
                w = edge_weight(fc, signal_features(q), length(vec2f(f32(dx), f32(dy))), 0.0, 0.0, 1.0);
            }
            var mq = vec2f(t.a, t.a * t.a);
            if sv_on(SV_ACCUMULATED_MOMENTS) {
                mq = textureLoad(moments, q, 0).xy;
            }
            sum_w += w;
            sum_light += w * t.rgb;
            sum_m += w * mq;
        }
    }
    let mean = sum_m / sum_w;
    let variance = max(mean.y - mean.x * mean.x, 0.0) * 4.0 / max(h, 1.0);
    textureStore(dst, p, vec4f(half_safe(sum_light / sum_w), steering_variance(variance, m)));
    // Too few frames to tell a rare path from noise, and too few for the regression.
    textureStore(out_excess, p, vec4f(0.0));
}
