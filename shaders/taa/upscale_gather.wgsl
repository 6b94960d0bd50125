// Where the upscaler's shown pixels find their samples (taa/upscale_common.wgsl), written once
// per render pixel by taa/upscale_samples.wgsl.

var up_samples: texture_2d<f32>;

// Render pixel i's demodulated light.
fn light_at(i: vec2i) -> vec3f {
    return textureLoad(up_samples, i, 0).rgb;
}

// Render pixels per shown pixel (at most 1 on each axis).
fn to_render() -> vec2f {
    return vec2f(frame.size) / vec2f(up.out_size);
}

// The render pixel whose sample lies nearest shown pixel o's centre; the nine around it hold
// every sample within a render pixel of it.
fn centre_sample(o: vec2u) -> vec2i {
    return vec2i(floor((vec2f(o) + 0.5) * to_render() - frame.jitter + 0.5));
}

// Offset, in shown pixels, from o's centre to the sample of render pixel i.
fn sample_offset(o: vec2u, i: vec2i) -> vec2f {
    return (vec2f(i) + frame.jitter) / to_render() - (vec2f(o) + 0.5);
}

// The nine samples' light around o filtered with a Gaussian of half a render pixel: the image where
// the history has no weight yet.
fn spatial_estimate(o: vec2u) -> vec3f {
    let centre = centre_sample(o);
    var sum_w = 0.0;
    var sum_c = vec3f(0.0);
    for (var k = 0; k < 9; k++) {
        let i = centre + neighbour_3x3(k);
        if !in_bounds(i) {
            continue;
        }
        let dr = sample_offset(o, i) * to_render();
        let w = exp(-2.0 * dot(dr, dr));
        sum_w += w;
        sum_c += w * light_at(i);
    }
    return sum_c / max(sum_w, 1e-20);
}
