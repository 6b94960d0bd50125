// The radiance cache's resolve (engine/src/passes/cache.rs), one thread per slot, after the
// frame's samples are in: each cell's mean takes this frame's samples in as a running mean of
// up to max_samples samples (then an exponential one, so that a change of light fades in), and
// the samples' light-weighted centroid as the running mean of the light; a cell with no sample
// for max_age frames frees its slot.

@compute @workgroup_size(256)
fn resolve(@builtin(global_invocation_id) gid: vec3u) {
    let s = gid.x;
    if s >= cache.capacity || atomicLoad(&cache_keys[s]) == 0u {
        return;
    }
    let i = CACHE_SUMS * s;
    let count = atomicLoad(&cache_sums[i + 3u]);
    if count == 0u {
        let age = cache_ages[s] + 1u;
        cache_ages[s] = age;
        if age > cache.max_age {
            atomicStore(&cache_keys[s], 0u);
            cache_cells[s] = vec4f(0.0);
            cache_centroids[s] = vec4f(0.0);
        }
        return;
    }
    let sum = vec3f(
        f32(atomicLoad(&cache_sums[i])),
        f32(atomicLoad(&cache_sums[i + 1u])),
        f32(atomicLoad(&cache_sums[i + 2u])),
    );
    // Every sample weighs at least 1 (cells.wgsl's light_weight).
    let weights = f32(max(atomicLoad(&cache_sums[i + 8u]), 1u));
    let at = vec3f(
        f32(atomicLoad(&cache_sums[i + 4u])),
        f32(atomicLoad(&cache_sums[i + 5u])),
        f32(atomicLoad(&cache_sums[i + 6u])),
    ) / (1024.0 * weights);
    // The mean squared luminance, back in radiance squared.
    let to_radiance = 4096.0 / cache.fixed_scale;
    let l2 = f32(atomicLoad(&cache_sums[i + 7u])) / (1024.0 * f32(count)) * to_radiance * to_radiance;
    let mean = sum / (cache.fixed_scale * f32(count));
    let old = cache_cells[s];
    let n = min(old.a + f32(count), max(cache.max_samples, 1.0));
    let w = min(f32(count) / n, 1.0);
    cache_cells[s] = vec4f(mix(old.rgb, mean, w), n);
    // The centroid of the old samples and this frame's, each weighed by its light: the old ones'
    // mean weight a sample is taken from their mean's luminance.
    // (to_radiance is a displayed white in radiance.)
    let w_old = (1.0 - w) * f32(select(light_weight(luminance(old.rgb) / to_radiance), 0u, old.a <= 0.0));
    let w_new = w * weights / f32(count);
    let c = cache_centroids[s];
    cache_centroids[s] = vec4f(mix(c.xyz, at, w_new / max(w_old + w_new, 1e-30)), mix(c.w, l2, w));
    cache_ages[s] = 0u;
    for (var k = 0u; k < CACHE_SUMS; k++) {
        atomicStore(&cache_sums[i + k], 0u);
    }
}
