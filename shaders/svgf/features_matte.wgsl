// The matte light edge-stops on the primary surface (SVGF §4.2) and is remodulated by the
// composite alone.
var features: texture_2d<f32>;

fn signal_features(p: vec2i) -> Features {
    let f = textureLoad(features, p, 0).xy;
    return Features(f.x, f.y, oct_decode(textureLoad(gb_normal, p, 0).xy));
}

// The features are the primary surface's, whose variances the pre-filter gives.
fn signal_primary_features(p: vec2i) -> bool {
    return true;
}

fn signal_remodulation(p: vec2i) -> vec3f {
    return vec3f(1.0);
}

// The matte light's filter has no spatial bound beyond the kernel's.
fn signal_sigma(p: vec2i) -> f32 {
    return 1e9;
}

// Voorhuis §6's firefly median runs on the matte light of every surface.
fn signal_diffuse(p: vec2i) -> bool {
    return has_surface(p);
}
