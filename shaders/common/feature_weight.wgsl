// Edge-stops on features that carry their own variance: the pre-filter's filtered normal and
// view depth with their dual-buffer variances (Moon et al. 2017 §5, "Variances of pre-filtered
// features"). A feature's distance between the pixel c and a tap t is counted less what the two
// features' noise explains, var_c + min(var_c, var_t), and measured against the larger of the
// distance the surface itself gives and var_c: the feature distance of Rousselle et al. 2013
// (RMZ13 in Moon's references), the form Moon's §5 passes its variances on to. Without
// variance both reduce to SVGF's eq. (3) and (4); out of focus, where a pixel's samples straddle
// two surfaces and its mean features lie between them, they let the light of both be averaged,
// as the lens averages it.

// The depth term's exponent: |z_c - z_t| / s for no variance (s: SVGF's sigma_z |grad z| times
// the tap's offset), the variances in the depth's squared units.
fn depth_distance(dz: f32, s: f32, var_c: f32, var_t: f32) -> f32 {
    let noise = var_c + min(var_c, var_t);
    return sqrt(max(dz * dz - noise, 0.0) / max(s * s, var_c));
}

// The normal term: |n_c - n_t|^2 = 2 (1 - cos), less the normals' noise, back in 1 - cos, and
// SVGF's max(0, cos)^sigma_n of what is left. The variances are the normals' summed over the
// three components (the expected |n - E[n]|^2).
fn normal_weight(cos_ct: f32, sigma_n: f32, var_c: f32, var_t: f32) -> f32 {
    let noise = var_c + min(var_c, var_t);
    let d = max(1.0 - cos_ct - 0.5 * noise, 0.0);
    return pow(max(1.0 - d, 0.0), sigma_n);
}
