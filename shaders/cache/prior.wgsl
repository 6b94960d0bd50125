// The radiance cache's prior for a pixel whose matte history restarts (engine/src/passes/cache.rs):
// rgb, its cell's mean matte light; a, the frames' worth of samples it stands for (0: none); and
// the mean squared luminance of those samples.

var cache_prior: texture_2d<f32>;

fn cache_prior_at(p: vec2i) -> vec4f {
    let v = textureLoad(cache_prior, p, 0);
    return select(vec4f(0.0), v, is_finite3(v.rgb) && v.a > 0.0);
}

// The mean squared luminance of the samples behind the prior.
var cache_prior_m2: texture_2d<f32>;

fn cache_prior_m2_at(p: vec2i) -> f32 {
    let v = textureLoad(cache_prior_m2, p, 0).r;
    return select(0.0, v, v >= 0.0 && v < 3.0e38);
}
