// Bilinear reads spelled out (the histories are 32-bit floats, which WebGPU does not filter
// without an optional feature, and their taps are tested one by one).

// The four texels a bilinear read at `at` blends, base + (0,0), (1,0), (0,1), (1,1), and their
// weights in that order.
struct BilinearTaps {
    base: vec2i,
    w: vec4f,
}

fn bilinear_taps(at: vec2f) -> BilinearTaps {
    let f = at - 0.5;
    let t = f - floor(f);
    let s = 1.0 - t;
    return BilinearTaps(vec2i(floor(f)), vec4f(s.x * s.y, t.x * s.y, s.x * t.y, t.x * t.y));
}

fn bilinear_tap(b: BilinearTaps, k: i32) -> vec2i {
    return b.base + vec2i(k & 1, k >> 1);
}
