// Reprojection tests on the previous frame's representative hits (glossy/motion.wgsl writes
// them: the reflected point and the pixel's lobe class), shared by the glossy chain's temporal
// stage and SVGF's glossy temporal.

var prev_hit: texture_2d<f32>;

// Eq. (11) on the reflected hit, as `reproject` does it on the surface (matte/common.wgsl): the
// previous frame saw each pixel's reflection at another jitter, so where the pixel under the
// reflection motion vector shows another point, its 3x3 neighbours are tried and the closest
// reflected hit is read (point sampled). Distances are in reflected footprints (`reach`). Testing
// the one pixel alone cut the history of curved mirrors (the hall's metal spheres) short in
// every frame of a still view, and their bilateral then ran at full sigma.
fn reproject_mirror(prev: vec2f, hit: vec3f, reach: f32) -> Reprojection {
    let q = vec2i(floor(prev));
    var best = Reprojection(q, true, -1.0);
    for (var k = 0; k < 9; k++) {
        let t = q + neighbour_3x3(k);
        if !in_bounds(t) {
            continue;
        }
        let ph = textureLoad(prev_hit, t, 0);
        if decode_hit_class(ph.w) != HIT_MIRROR {
            continue;
        }
        let d = length(hit - ph.xyz) / reach;
        if best.distance < 0.0 || d < best.distance {
            best = Reprojection(t, k == 0, d);
        }
        if k == 0 && d <= gp.d0_px {
            break;
        }
    }
    return best;
}

// The taps of a bilinear read whose previous pixel had a glossy lobe (its hit class is set).
fn lobe_taps(b: BilinearTaps) -> vec4<bool> {
    var ok = vec4<bool>(false);
    for (var k = 0; k < 4; k++) {
        let t = bilinear_tap(b, k);
        ok[k] = in_bounds(t) && decode_hit_class(textureLoad(prev_hit, t, 0).w) != HIT_NONE;
    }
    return ok;
}

// The taps of a bilinear read that showed a mirror reflecting `hit`: reproject_mirror's test,
// within d1 reflected footprints.
fn mirror_taps(b: BilinearTaps, hit: vec3f, reach: f32) -> vec4<bool> {
    var ok = vec4<bool>(false);
    for (var k = 0; k < 4; k++) {
        let t = bilinear_tap(b, k);
        if in_bounds(t) {
            let ph = textureLoad(prev_hit, t, 0);
            ok[k] = decode_hit_class(ph.w) == HIT_MIRROR && length(hit - ph.xyz) / reach <= gp.d1_px;
        }
    }
    return ok;
}
