// The radiance cache's cells (engine/src/passes/cache.rs): a hash table over surfaces, keyed by
// a grid cell of the position and the normal's dominant axis, in the manner of NVIDIA's SHaRC
// and Bevy Solari's world cache. A cell holds the mean of the matte light (the trace's
// demodulated `tr_matte`: incoming area and indirect light, cos / pi weighted, without the
// material) of the surface points that fell in it.
//
// - The grid's cell size follows the distance to the camera: the power of two nearest above
//   `cell_pixels` pixels' footprint at that distance, so a cell covers a few pixels on screen
//   wherever it is, and a surface keeps its cells while the camera moves by less than half its
//   distance.
// - The normal's dominant axis and its sign are part of the key: the two faces of a thin wall
//   never share a cell (tests/radiance_cache.rs). What can still leak is a cell that straddles a
//   wall along a floor that continues under it, at most one cell wide.
// - A cell also keeps its samples' centroid. A pixel the last frame did not see (the only kind a
//   denoiser restarts from a prior) takes its cell's light only if the centroid is in sight of
//   it (a shadow ray between the two, each end lifted off the surface by a quarter cell): a cell
//   that straddles a wall, filled from the far side, is refused (tests/radiance_cache.rs).
// - Samples are summed in fixed point with 32-bit atomics (WGSL has no float atomics), in units
//   of 1 / 4096 of the display's white (`fixed_scale` = 4096 x exposure), each sample clamped
//   to 64 x white: 2^18 units, so 2^14 samples may land in one cell in one frame.

struct CacheParams {
    // Cells in the table (a power of two).
    capacity: u32,
    // A cell's edge in pixels at its distance (rounded up to a power of two in scene units).
    cell_pixels: f32,
    // The most samples a cell's mean holds: older ones then fade exponentially.
    max_samples: f32,
    // Frames a cell is kept without a sample before its slot is freed.
    max_age: u32,
    // The most frames' worth of samples a pixel's prior stands for.
    prior_frames: f32,
    // One secondary sample per update_tile x update_tile pixels per frame (0: none).
    update_tile: u32,
    // Fixed-point units per unit of radiance, and the clamp of one sample (radiance).
    fixed_scale: f32,
    sample_clamp: f32,
    // The samples a cell must hold before a path may end in it (0: none does;
    // cache/path_end.wgsl).
    path_end_samples: f32,
    // The largest relative standard error of a cell's mean (from its samples' spread and count)
    // at which a path may end in it.
    path_end_error: f32,
    pad1: f32,
    pad2: f32,
}

var<uniform> cache: CacheParams;
var<storage, read_write> cache_keys: array<atomic<u32>>;
// Per cell, CACHE_SUMS words: this frame's fixed-point sums of r, g, b, the number of samples,
// the sums of their positions in the cell (x, y, z in 1/1024 of its edge) weighted by their
// light, the sum of their squared luminances (in 1/1024 of the displayed white squared, each at
// most 16 whites), and the sum of the light weights (light_weight).
var<storage, read_write> cache_sums: array<atomic<u32>>;
// Per cell: the mean (rgb) and the samples it holds (a).
var<storage, read_write> cache_cells: array<vec4f>;
// Per cell: its samples' centroid weighted by their light (light_weight), as a fraction of the
// cell from its lowest corner (xyz): where the light it holds came from, which a cell that
// straddles a wall keeps on its lit side however many dark samples the other side adds; and
// the mean of their squared luminances (w): with the mean's luminance, their spread, which a
// denoiser that estimates variance from moments (SVGF) takes for a restarted pixel's.
var<storage, read_write> cache_centroids: array<vec4f>;
// Per cell: frames since its last sample.
var<storage, read_write> cache_ages: array<u32>;

const CACHE_PROBES: u32 = 8u;
const CACHE_NONE: u32 = 0xffffffffu;
const CACHE_SUMS: u32 = 9u;

struct CellKey {
    // Where its probe sequence starts, and its identity in the table (never 0: empty).
    slot: u32,
    check: u32,
    // The cell: its edge (scene units) and its lowest corner in edges.
    size: f32,
    corner: vec3i,
}

// The cell of a surface point p with normal n, its grid sized for a camera at `eye` whose pixels
// subtend `spread` radians.
fn cell_key(p: vec3f, n: vec3f, eye: vec3f, spread: f32) -> CellKey {
    let footprint = max(distance(p, eye) * spread * cache.cell_pixels, 1e-30);
    let level = clamp(i32(ceil(log2(footprint))), -40, 40);
    let q = vec3i(floor(p * exp2(-f32(level))));
    let a = abs(n);
    var axis = 0u;
    var along = n.x;
    if a.y >= a.x && a.y >= a.z {
        axis = 1u;
        along = n.y;
    } else if a.z >= a.x && a.z >= a.y {
        axis = 2u;
        along = n.z;
    }
    let face = axis * 2u + select(0u, 1u, along < 0.0);
    let tag = u32(level + 64) | (face << 8u);
    var h = pcg_hash(0x9e3779b9u ^ tag);
    var c = pcg_hash(0x85ebca6bu ^ (tag * 0x27d4eb2fu));
    for (var i = 0u; i < 3u; i++) {
        let v = bitcast<u32>(q[i]);
        h = pcg_hash(h ^ v);
        c = pcg_hash(c ^ (v * 0x165667b1u + i));
    }
    return CellKey(h, max(c, 1u), exp2(f32(level)), q);
}

// The slot holding key k, or CACHE_NONE.
fn cache_find(k: CellKey) -> u32 {
    let mask = cache.capacity - 1u;
    for (var i = 0u; i < CACHE_PROBES; i++) {
        let s = (k.slot + i) & mask;
        if atomicLoad(&cache_keys[s]) == k.check {
            return s;
        }
    }
    return CACHE_NONE;
}

// The slot of key k, claimed if it has none (CACHE_NONE when its probes are all taken: the
// sample is then lost, and the table's fill is reported by cache/resolve's slots in use).
fn cache_claim(k: CellKey) -> u32 {
    let found = cache_find(k);
    if found != CACHE_NONE {
        return found;
    }
    let mask = cache.capacity - 1u;
    for (var i = 0u; i < CACHE_PROBES; i++) {
        let s = (k.slot + i) & mask;
        // A weak exchange may fail while the slot is still empty: try again then.
        for (var t = 0u; t < 4u; t++) {
            let r = atomicCompareExchangeWeak(&cache_keys[s], 0u, k.check);
            if r.exchanged || r.old_value == k.check {
                return s;
            }
            if r.old_value != 0u {
                break;
            }
        }
    }
    return CACHE_NONE;
}

// Where p lies in cell k, from 0 to 1 along each axis.
fn cell_fraction(k: CellKey, p: vec3f) -> vec3f {
    return clamp(p / k.size - vec3f(k.corner), vec3f(0.0), vec3f(1.0));
}

// Add one sample v at p to slot s (cell k); `u` in [0, 1)^3 rounds stochastically, so that the
// mean of values under one fixed-point unit is kept.
fn cache_add(s: u32, k: CellKey, p: vec3f, v: vec3f, u: vec3f) {
    if s == CACHE_NONE || !is_finite3(v) {
        return;
    }
    let c = clamp(v, vec3f(0.0), vec3f(cache.sample_clamp));
    let q = vec3u(c * cache.fixed_scale + u);
    let at = vec3u(cell_fraction(k, p) * 1024.0 + 0.5);
    // Luminance in displayed whites (fixed_scale = 4096 x exposure), at most 16, squared, in
    // 1/1024 units: 2^18 a sample, as the light's.
    let white = min(luminance(c) * cache.fixed_scale / 4096.0, 16.0);
    let l2 = u32(white * white * 1024.0 + fract(u.x + u.y));
    let w = light_weight(white);
    let i = CACHE_SUMS * s;
    atomicAdd(&cache_sums[i], q.x);
    atomicAdd(&cache_sums[i + 1u], q.y);
    atomicAdd(&cache_sums[i + 2u], q.z);
    atomicAdd(&cache_sums[i + 3u], 1u);
    atomicAdd(&cache_sums[i + 4u], at.x * w);
    atomicAdd(&cache_sums[i + 5u], at.y * w);
    atomicAdd(&cache_sums[i + 6u], at.z * w);
    atomicAdd(&cache_sums[i + 7u], l2);
    atomicAdd(&cache_sums[i + 8u], w);
}

// A sample's weight in its cell's centroid, from its luminance in displayed whites (at most
// 16): 1 for a black sample, 257 at 16 whites, so that the centroid follows the light (at most
// 2^18 units of position a sample, as the light's sums).
fn light_weight(white: f32) -> u32 {
    return 1u + u32(clamp(white, 0.0, 16.0) * 16.0);
}
