// Dundr §4.2-4.3: the luminance variance m2 - m1^2 of the accumulated samples, blurred by the
// 3x3 kernel over the pixels that have samples (a missing pixel is not filled from its
// neighbours here, §5). Fewer than 4 samples make no estimate: there the luminance weight is
// off (Dundr's first option), by a variance too large to stop anything. Output: dst (rgb,
// variance; -1 where the pixel has no sample).

var integrated: texture_2d<f32>;
var moments: texture_2d<f32>;
// 32-bit: the feedback level writes this light back into the 32-bit history where it does not
// feed it.
var dst: texture_storage_2d<rgba32float, write>;

const UNKNOWN_VARIANCE: f32 = 60000.0;

// The temporal variance of the accumulated light where 4 or more samples make an estimate;
// else the spatial variance of the accumulated luminance over the 3x3 pixels with samples
// (Dundr §4.4.3's second option), or none (no luminance weight) where no neighbour has one.
fn variance_at(q: vec2i) -> f32 {
    let m = textureLoad(moments, q, 0);
    if m.z >= 4.0 {
        return max(m.y - m.x * m.x, 0.0) / m.z;
    }
    var s = vec2f(0.0);
    var n = 0.0;
    for (var k = 0; k < 9; k++) {
        let t = q + neighbour_3x3(k);
        if in_bounds(t) && textureLoad(moments, t, 0).z >= 1.0 {
            let l = luma(textureLoad(integrated, t, 0).rgb);
            s += vec2f(l, l * l);
            n += 1.0;
        }
    }
    if n < 2.0 {
        return UNKNOWN_VARIANCE;
    }
    return max(s.y / n - (s.x / n) * (s.x / n), 0.0);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let c = textureLoad(integrated, p, 0).rgb;
    if textureLoad(moments, p, 0).z < 1.0 {
        textureStore(dst, p, vec4f(0.0, 0.0, 0.0, -1.0));
        return;
    }
    var sum = 0.0;
    var wsum = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = p + vec2i(dx, dy);
            if in_bounds(q) && textureLoad(moments, q, 0).z >= 1.0 {
                let w = select(0.5, 1.0, dx == 0) * select(0.5, 1.0, dy == 0);
                sum += w * variance_at(q);
                wsum += w;
            }
        }
    }
    textureStore(dst, p, vec4f(half_safe(c), min(sum / wsum, UNKNOWN_VARIANCE)));
}
