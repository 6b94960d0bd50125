// Independent uniform random numbers: a PCG state per pixel and sample (O'Neill 2014; Jarzynski &
// Olano 2020, "Hash Functions for GPU Rendering"), so every sample is reproducible from
// (pixel, sample index, seed).

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn rng_init(pixel: u32, sample_index: u32, seed: u32) -> u32 {
    return pcg_hash(pixel ^ pcg_hash(sample_index ^ pcg_hash(seed)));
}

// Uniform in [0, 1).
fn rand(state: ptr<function, u32>) -> f32 {
    let s = *state * 747796405u + 2891336453u;
    *state = s;
    let word = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return f32(((word >> 22u) ^ word) >> 8u) * (1.0 / 16777216.0);
}

fn rand2(state: ptr<function, u32>) -> vec2f {
    let a = rand(state);
    let b = rand(state);
    return vec2f(a, b);
}
