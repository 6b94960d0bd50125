// The sparse cross-bilateral filter of stages (4) and (7): `mp.taps` taps in a disk, weighted by
// plane distance and normals, and with edge_k > 0 also by luminance (stage 7's edge-stop, see
// matte/bilateral.wgsl). Where the program's uncertainty module gives the features' variances
// (stage 7 with the pre-filter) the plane and normal weights count them (common/
// feature_weight.wgsl). Reads `filter_in`, the caller's input (for the edge-stop, its alpha
// holds the guide's luminance), and for the edge-stop `reason_in`, the history length.

// Standard deviation of the n-frame mean at p: the root mean square of the raw input minus the
// history's mean (filter_in) over p and up to 16 taps on p's surface within 3 pixels, over
// sqrt(n). The residual holds the noise without the shading's own variation: the input's
// spread around its local mean counted a contact shadow's contrast as noise, and the edge-stop
// then blurred the shadow it was there to keep.
fn history_noise(p: vec2i, xc: vec3f, nc: vec3f, fc: f32, n: f32) -> f32 {
    var sum = residual_square(p);
    var count = 1.0;
    for (var i = 0u; i < 16u; i++) {
        let t = surface_tap(p, xc, nc, fc, i, 16u, 3.0);
        if t.x >= 0 {
            sum += residual_square(t);
            count += 1.0;
        }
    }
    return sqrt(sum / count / n);
}

fn residual_square(p: vec2i) -> f32 {
    let d = luminance(half_safe(matte_input(p))) - luminance(textureLoad(filter_in, p, 0).rgb);
    return d * d;
}

fn sparse_bilateral(p: vec2i, radius: f32, edge_k: f32) -> vec3f {
    let centre = textureLoad(filter_in, p, 0);
    let c = centre.rgb;
    if radius < 0.5 || !has_surface(p) {
        return c;
    }
    let xc = position_at(p);
    let nc = oct_decode(textureLoad(gb_normal, p, 0).xy);
    let fc = footprint(xc);
    var sigma_l = 0.0;
    if edge_k > 0.0 {
        // The guide averages up to 9 samples: a third of the mean's noise. Past
        // edge_stop_full_frames the stop narrows faster than the noise, so that what it lets
        // through falls faster than the history's own error and a still view ends at its mean.
        let n = max(f32(textureLoad(reason_in, p, 0).x >> 8u), 1.0);
        var k = edge_k;
        if mp.edge_stop_full_frames > 0.0 {
            k *= sqrt(min(1.0, mp.edge_stop_full_frames / n));
        }
        sigma_l = k * history_noise(p, xc, nc, fc, n) / 3.0 + 1e-6;
    }
    let lc = centre.a;
    let vc = feature_variance(p);
    var sum = c;
    var wsum = 1.0;
    // Mara et al. §3.2's Gaussian over the disk, where it is on.
    let sigma = mp.tap_sigma * radius;
    let inv_two_sigma2 = select(0.0, 1.0 / (2.0 * sigma * sigma), sigma > 0.0);
    for (var i = 0u; i < mp.taps; i++) {
        let off = spiral_tap(i, mp.taps, radius, p);
        let q = p + vec2i(round(off));
        if !in_bounds(q) || !has_surface(q) {
            continue;
        }
        let tap = textureLoad(filter_in, q, 0);
        let t = tap.rgb;
        let xt = position_at(q);
        let nt = oct_decode(textureLoad(gb_normal, q, 0).xy);
        var w: f32;
        if FEATURE_VARIANCE {
            w = uncertain_bilateral_weight(xc, nc, fc, vc, xt, nt, feature_variance(q));
        } else {
            w = bilateral_weight(xc, nc, fc, xt, nt);
        }
        if sigma_l > 0.0 {
            w *= exp(-abs(tap.a - lc) / sigma_l);
        }
        w *= exp(-dot(off, off) * inv_two_sigma2);
        sum += t * w;
        wsum += w;
    }
    return sum / wsum;
}

// bilateral_weight with the features' variances (vc, vt: the normal's and the view depth's
// relative variance). The plane distance's variance is taken as the depth's: a defocused pixel's
// samples scatter along the view ray about as far as its mean depth is uncertain.
fn uncertain_bilateral_weight(xc: vec3f, nc: vec3f, fc: f32, vc: vec2f, xt: vec3f, nt: vec3f, vt: vec2f) -> f32 {
    let zc = dot(xc - frame.cam_pos.xyz, frame.cam_fwd.xyz);
    let zt = dot(xt - frame.cam_pos.xyz, frame.cam_fwd.xyz);
    let plane = depth_distance(dot(nc, xt - xc), mp.plane_sigma_px * fc, vc.y * zc * zc, vt.y * zt * zt);
    return normal_weight(dot(nc, nt), mp.normal_power, vc.x, vt.x) * exp(-plane * plane);
}
