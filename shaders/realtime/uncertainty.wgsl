// The G-buffer's feature uncertainty, where the pre-filter ran this frame (a thin lens or an
// open shutter; passes/prefilter.rs writes it as `prefilter/view`): x the filtered view depth's
// relative variance and w the filtered normal's (dual buffers, prefilter/features.wgsl), z the
// spread of the world positions a pixel's primary samples hit (their RMS distance from their
// mean), in pixels at the surface's depth. Those samples see the surface over that spread, so the pixel's value is
// the in-focus light averaged over a disk of about that size (the circle of confusion), and a
// filter of the light may reach as far without blurring what the lens does not (Moon et al.
// 2017 §4.2-4.3 and §5: the per-pixel world-position statistics the pre-filter passes on).

var gb_uncertainty: texture_2d<f32>;

// The spread as a standard deviation per image axis (pixels): an RMS distance d in a plane is
// d / sqrt(2) along each axis.
fn defocus_sigma(p: vec2i) -> f32 {
    return textureLoad(gb_uncertainty, p, 0).z * 0.70710678;
}

// Edge-stops weigh the features against their variances (common/feature_weight.wgsl).
const FEATURE_VARIANCE: bool = true;

// The filtered normal's variance and the view depth's relative variance (times z^2: the depth's).
fn feature_variance(p: vec2i) -> vec2f {
    return textureLoad(gb_uncertainty, p, 0).wx;
}
