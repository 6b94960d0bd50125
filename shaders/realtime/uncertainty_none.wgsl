// No feature uncertainty this frame (a pinhole camera, or the pre-filter off): every pixel's
// primary sample is exact, and its light is the surface's at that point
// (realtime/uncertainty.wgsl where the pre-filter ran).

fn defocus_sigma(p: vec2i) -> f32 {
    return 0.0;
}

const FEATURE_VARIANCE: bool = false;

fn feature_variance(p: vec2i) -> vec2f {
    return vec2f(0.0);
}
