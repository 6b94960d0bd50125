// The glossy light edge-stops on the glossy surface's own features (Voorhuis §4.2.2): its
// reflections are blurry, and two neighbours on one surface reflect similar distributions.
// Behind a mirror (§4.1) it edge-stops on what the mirror shows: the reflected surface's normal
// and the distance along the reflection (primary depth plus secondary distance, its gradient
// scaled to the reflected footprint), and the light, demodulated by the reflected surface's
// reflectance in the temporal stage, is multiplied back here. The filter's reach is bounded by
// a Gaussian (§4.2.2 eq. (6); glossy/common.wgsl: glossy_sigma): Mara's 7 roughness^0.1 pixels,
// shrunk by the secondary hit's ray differential below the roughness threshold, so that a
// sharp reflection seen from afar is not blurred across the surface. Out of focus it reaches
// at least the circle of confusion (realtime/uncertainty.wgsl: defocus_sigma), over which the
// lens averages the light anyway: a defocused glossy surface's highlights come as rare bright
// lens samples, and the roughness alone would keep them as sparkles.
var features: texture_2d<f32>;

fn signal_features(p: vec2i) -> Features {
    let f = textureLoad(features, p, 0).xy;
    var r = Features(f.x, f.y, oct_decode(textureLoad(gb_normal, p, 0).xy));
    if sv_on(SV_MIRROR_FEATURES) && f.x > 0.0 && is_mirror(roughness_at(p)) {
        let t = min(secondary_t(p), gp.far);
        r = Features(f.x + t, f.y * (1.0 + t / f.x), hit_normal(p));
    }
    return r;
}

// Behind a mirror the features are the reflected surface's, which the pre-filter did not see.
fn signal_primary_features(p: vec2i) -> bool {
    return !(sv_on(SV_MIRROR_FEATURES) && is_mirror(roughness_at(p)));
}

fn signal_remodulation(p: vec2i) -> vec3f {
    return demodulation(p);
}

fn signal_sigma(p: vec2i) -> f32 {
    let x = position_at(p);
    let defocus = min(defocus_sigma(p), gp.max_sigma_px);
    return max(max(glossy_sigma(roughness_at(p), ray_differential(p, x)), defocus), 0.5);
}

// Behind a mirror the glossy light is what a diffuse surface reflects (§4.1: the first non-
// specular hit), so Voorhuis §6's firefly median runs there too, among mirror pixels; on glossy
// surfaces it would cut their highlights.
fn signal_diffuse(p: vec2i) -> bool {
    return has_surface(p) && sv_on(SV_MIRROR_FEATURES) && is_mirror(roughness_at(p));
}
