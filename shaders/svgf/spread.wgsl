// The spike cut's light spread over its surface (SvgfSettings::spike_ratio): each pixel's mean
// of the light the variance stage cut off its neighbours within SPREAD_RADIUS, weighed as the
// regression's taps are (the signal's reach and the depth and normal edge-stops), which the
// regression adds to its fit (svgf/regression.wgsl). Separable: `spread_h` sums each row's
// weighted cut light and weights about each pixel, `spread_v` each column of those sums, so a
// pixel's weight for a tap is the product of its row's and column's (the separable
// approximation of a cross-bilateral, as Mara et al.'s glossy blur is separated): 2 x 33 taps
// where the square would take 1089. Every pixel is a tap, so a rare path's light comes back even,
// not as a lattice of dots. cornell_mirror's frame 60 (256², FLIP against Mitsuba, seeds 0-3):
// 0.0494 / 0.0506 / 0.0504 / 0.0492; every other pixel a tap, half the cost, 0.0497 / 0.0508 at
// seeds 0-1. The alternatives measured are in docs/decisions.md.

var taps: texture_2d<u32>;
var moments: texture_2d<f32>;
// spread_h: the cut light (rgb). spread_v: spread_h's sums (rgb, weight).
var src: texture_2d<f32>;
// spread_h: the row sums (rgb, weight). spread_v: the mean (rgb).
var dst: texture_storage_2d<rgba16float, write>;

const SPREAD_RADIUS: i32 = 16;

// The weighted sum of `src` (its rgb as cut light, weight 1 each, in the horizontal pass; its
// rgb and weight as sums in the vertical one) along `axis` about p, p itself weighing 1.
fn sum_along(p: vec2i, axis: vec2i, sums: bool) -> vec4f {
    let fc = signal_features(p);
    let uncertain = signal_primary_features(p);
    let vc = select(vec2f(0.0), feature_variance(p), uncertain);
    let reach = tap_reach(textureLoad(taps, p, 0));
    var acc = tap_value(p, sums);
    for (var d = -SPREAD_RADIUS; d <= SPREAD_RADIUS; d++) {
        let q = p + d * axis;
        if d == 0 || !in_bounds(q) {
            continue;
        }
        let fq = tap_features(textureLoad(taps, q, 0));
        if fq.dz < 0.0 {
            continue;
        }
        let offset = f32(abs(d));
        let vq = select(vec2f(0.0), feature_variance(q), uncertain);
        let w = exp(-0.5 * offset * offset / (reach * reach)) * feature_weight(fc, fq, offset, vc, vq);
        if w > 1e-3 {
            acc += w * tap_value(q, sums);
        }
    }
    return acc;
}

// The regression adds the spread only where it fits the light: a moving view's short histories
// skip both passes' taps.
fn fitted(p: vec2i) -> bool {
    return regression_fits(p, 1.0 / max(textureLoad(moments, p, 0).w, 1e-6));
}

fn tap_value(q: vec2i, sums: bool) -> vec4f {
    let t = textureLoad(src, q, 0);
    return select(vec4f(t.rgb, 1.0), t, sums);
}

// One pass: the rows' weighted sums (rgb, weight) of the cut light, or the columns' mean of those.
fn spread_pass(p: vec2i, rows: bool) {
    if !in_bounds(p) {
        return;
    }
    var out = vec4f(0.0);
    if fitted(p) {
        let s = sum_along(p, select(vec2i(0, 1), vec2i(1, 0), rows), !rows);
        out = select(vec4f(half_safe(s.rgb / max(s.a, 1e-6)), 1.0), vec4f(half_safe(s.rgb), s.a), rows);
    }
    textureStore(dst, p, out);
}

@compute @workgroup_size(8, 8)
fn spread_h(@builtin(global_invocation_id) gid: vec3u) {
    spread_pass(vec2i(gid.xy), true);
}

@compute @workgroup_size(8, 8)
fn spread_v(@builtin(global_invocation_id) gid: vec3u) {
    spread_pass(vec2i(gid.xy), false);
}
