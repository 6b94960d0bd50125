// Reprojection tests on the previous frame's representative hits (glossy/motion.wgsl writes
// them: the reflected point and the pixel's lobe class), shared by the glossy chain's temporal
// stage and SVGF's glossy temporal.

var prev_hit: texture_2d<f32>;

// Eq. (11) on the reflected hit, as `reproject` does it on the surface (matte/common.wgsl): the
// previous frame saw each pixel's reflection at another jitter, so where the pixel under the
// reflection motion vector shows another point, its 3x3 neighbours are tried and the closest
// reflected hit is read (point sampled). Distances are in reflected footprints (`reach`). Testing
// the one pixel alone cut the history of curved mirrors (the hall's metal spheres) short in
// every frame of a still view, and their bilateral then ran at full sigma. `lobe_class`: the lobe
// class the previous pixel must have had (HIT_MIRROR, HIT_GLOSSY).
fn reproject_hit(prev: vec2f, hit: vec3f, reach: f32, lobe_class: u32) -> Reprojection {
    let q = vec2i(floor(prev));
    var best = Reprojection(q, true, -1.0);
    for (var k = 0; k < 9; k++) {
        let t = q + neighbour_3x3(k);
        if !in_bounds(t) {
            continue;
        }
        let ph = textureLoad(prev_hit, t, 0);
        if decode_hit_class(ph.w) != lobe_class {
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

// The taps of a bilinear read whose lobe `lobe_class` reflected `hit`: reproject_hit's test, within
// d1 reaches.
fn hit_taps(b: BilinearTaps, hit: vec3f, reach: f32, lobe_class: u32) -> vec4<bool> {
    var ok = vec4<bool>(false);
    for (var k = 0; k < 4; k++) {
        let t = bilinear_tap(b, k);
        if in_bounds(t) {
            let ph = textureLoad(prev_hit, t, 0);
            ok[k] = decode_hit_class(ph.w) == lobe_class && length(hit - ph.xyz) / reach <= gp.d1_px;
        }
    }
    return ok;
}

// The distance unit of the reflected-hit test: a pixel's footprint at the reflected hit, and on
// a glossy lobe (GGX alpha = roughness^2) the lobe's spread over the secondary distance, within
// which a moved representative hit still reflects much the same light.
fn hit_reach(p: vec2i, x: vec3f, roughness: f32) -> f32 {
    let lobe = select(roughness * roughness * secondary_t(p), 0.0, is_mirror(roughness));
    return reflected_footprint(p, x) + lobe;
}

// The lobe class whose reflected hit is tested where the history follows reflection motion:
// mirrors always; glossy lobes where their representative hits are traced mirror rays (a
// sampled depth jumps between near and far geometry) and `test_glossy`. HIT_NONE: no test.
fn tested_class(roughness: f32, test_glossy: bool) -> u32 {
    if is_mirror(roughness) {
        return HIT_MIRROR;
    }
    if test_glossy && gp.representative_traced != 0u {
        return HIT_GLOSSY;
    }
    return HIT_NONE;
}
