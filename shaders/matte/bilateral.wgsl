// Stage (7): the final sparse bilateral, with the per-pixel radius of stage (5); it fills
// disocclusions and removes low-frequency noise. The radius is at least min_radius_px (a
// departure from the paper, whose r = (1 - c) R all but vanishes at full confidence): outside
// the history loop the blur does not compound, and the normal and plane weights keep it on
// the surface, so it trades little bias for the residual noise of a history tens of frames
// long (MatteSettings::min_radius_fraction). Taps are also weighed by their luminance
// difference against edge_stop_sigmas standard deviations of the history's noise (SVGF's
// luminance weighting function, Dundr §4.4.3 after Schied et al. 2017, with the variance of the
// n-frame mean estimated from this frame's input): where the history has converged the
// filter keeps the shading detail the plane and normal weights cannot see.
@group(0) @binding(44) var filter_in: texture_2d<f32>;
@group(0) @binding(52) var radius_in: texture_2d<f32>;
@group(0) @binding(51) var reason_in: texture_2d<u32>;
@group(0) @binding(50) var out_matte: texture_storage_2d<rgba16float, write>;

// Standard deviation of the n-frame mean at p: the raw input's spread over 16 taps on p's
// surface within 3 pixels, over sqrt(n).
fn history_noise(p: vec2i, xc: vec3f, nc: vec3f, fc: f32) -> f32 {
    var m1 = luminance(half_safe(matte_input(p)));
    var m2 = m1 * m1;
    var count = 1.0;
    for (var i = 0u; i < 16u; i++) {
        let q = p + vec2i(round(spiral_tap(i, 16u, 3.0, p)));
        if !in_bounds(q) || !has_surface(q) {
            continue;
        }
        if bilateral_weight(xc, nc, fc, position_at(q), oct_decode(textureLoad(gb_normal, q, 0).xy)) < 0.3 {
            continue;
        }
        let s = luminance(half_safe(matte_input(q)));
        m1 += s;
        m2 += s * s;
        count += 1.0;
    }
    m1 /= count;
    let n = max(f32(textureLoad(reason_in, p, 0).x >> 8u), 1.0);
    return sqrt(max(m2 / count - m1 * m1, 0.0) / n);
}

fn final_bilateral(p: vec2i, radius: f32) -> vec3f {
    let c = textureLoad(filter_in, p, 0).rgb;
    if radius < 0.5 || !has_surface(p) {
        return c;
    }
    let xc = position_at(p);
    let nc = oct_decode(textureLoad(gb_normal, p, 0).xy);
    let fc = footprint(xc);
    let sigma_l = dn.edge_stop_sigmas * history_noise(p, xc, nc, fc) + 1e-6;
    let lc = luminance(c);
    var sum = c;
    var wsum = 1.0;
    for (var i = 0u; i < dn.taps; i++) {
        let q = p + vec2i(round(spiral_tap(i, dn.taps, radius, p)));
        if !in_bounds(q) || !has_surface(q) {
            continue;
        }
        let t = textureLoad(filter_in, q, 0).rgb;
        let w = exp(-abs(luminance(t) - lc) / sigma_l) * bilateral_weight(xc, nc, fc, position_at(q), oct_decode(textureLoad(gb_normal, q, 0).xy));
        sum += t * w;
        wsum += w;
    }
    return sum / wsum;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    var v = textureLoad(filter_in, p, 0).rgb;
    if stage_on(STAGE_BILATERAL) {
        v = final_bilateral(p, max(textureLoad(radius_in, p, 0).r, dn.min_radius_px));
    }
    textureStore(out_matte, p, vec4f(half_safe(v), 1.0));
}
