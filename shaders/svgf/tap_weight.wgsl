// What SVGF's final stages (svgf/regression.wgsl, svgf/spread.wgsl) share: which pixels' light
// the regression fits, and the weight of a tap.

// The regression fits light of at least regression_samples' worth on a surface; the rest shows
// the a-trous output.
fn regression_fits(p: vec2i, samples: f32) -> bool {
    return sv_on(SV_REGRESSION) && has_surface(p) && samples >= sv.regression_samples;
}

// SVGF's depth and normal edge-stops of tap t, with the features' variances where the frame
// has them (vc, vt: the normal's and the depth's relative variance, realtime/uncertainty.wgsl);
// without, edge_weight's terms exactly.
fn feature_weight(c: Features, t: Features, offset: f32, vc: vec2f, vt: vec2f) -> f32 {
    if !FEATURE_VARIANCE {
        return edge_weight(c, t, offset, 0.0, 0.0, 1.0);
    }
    let s = sv.sigma_z * max(c.dz, 1e-6) * offset + 1e-6;
    let z2 = c.z * c.z;
    let wz = depth_distance(c.z - t.z, s, vc.y * z2, vt.y * t.z * t.z);
    return exp(-wz) * normal_weight(dot(c.n, t.n), sv.sigma_n, vc.x, vt.x);
}
