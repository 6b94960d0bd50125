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

// Screen-space strata for a sample's leading dimensions (the aim of Heitz & Belcher 2019,
// "Distributing Monte Carlo errors as a blue noise in screen space", reached with a randomized
// lattice rather than their optimized tables). The pixels of an aligned 16x16 tile take 256
// consecutive points of the R_d sequence (Roberts 2018), in the order of the pixel's Morton
// code, so every aligned 2^k x 2^k block of the tile holds 4^k consecutive points, which cover
// the unit square or cube evenly. A random XOR of the code and a random toroidal shift
// (Cranley-Patterson rotation), drawn per tile, per frame (`sample_index`: the real-time trace
// passes one index for the frames that share a lattice) and per use, keep each pixel's point
// uniform and independent from frame to frame: a pixel's estimate is as unbiased and as noisy
// as with `rand`, while a block's mean lies closer to the integral. The error left is at the
// scale of a pixel, which the denoisers' spatial filters remove, instead of at the scale of
// their windows, which they cannot.
// The lattice is summed in 32-bit fixed point, wrapping, so that the point is exact to 2^-24:
// in floating point, code * g carries the error of a number near 200 (2^-16), which skews the
// choice among emitters whose share of the power is that small.
struct Strata {
    code: u32,
    shift: vec3u,
}

fn morton_16x16(p: vec2u) -> u32 {
    var m = 0u;
    for (var b = 0u; b < 4u; b++) {
        m |= ((p.x >> b) & 1u) << (2u * b);
        m |= ((p.y >> b) & 1u) << (2u * b + 1u);
    }
    return m;
}

fn strata_init(px: vec2u, sample_index: u32, seed: u32) -> Strata {
    let tile = px >> vec2u(4u);
    let h0 = pcg_hash(tile.x ^ pcg_hash(tile.y ^ pcg_hash(sample_index ^ pcg_hash(seed))));
    let h1 = pcg_hash(h0);
    let h2 = pcg_hash(h1);
    return Strata(morton_16x16(px & vec2u(15u)) ^ (h0 & 255u), vec3u(h1, h2, pcg_hash(h2)));
}

fn unit_24(x: vec3u) -> vec3f {
    return vec3f(x >> vec3u(8u)) * (1.0 / 16777216.0);
}

// R_2's generator (1 / phi_2, 1 / phi_2^2, phi_2 the plastic number, x^3 = x + 1) times 2^32.
fn strata2(s: Strata) -> vec2f {
    return unit_24(s.shift + s.code * vec3u(0xc13fa9a9u, 0x91e10da6u, 0u)).xy;
}

// R_3's generator (1 / phi_3^k, phi_3 the real root of x^4 = x + 1) times 2^32.
fn strata3(s: Strata) -> vec3f {
    return unit_24(s.shift + s.code * vec3u(0xd1b54a33u, 0xabc98389u, 0x8cb92ba7u));
}
