// Stage (6): 3x3 median per channel, outside the history loop (fireflies still feed the running
// average, so the image is not darkened, but never reach the screen). The pass also writes, on
// or off, the guide of stage 7's edge-stop into the alpha.
var filter_in: texture_2d<f32>;
var out_median: texture_storage_2d<rgba16float, write>;

fn median9(v: array<f32, 9>) -> f32 {
    var a = v;
    // Partial selection sort up to the middle element.
    for (var i = 0; i < 5; i++) {
        var k = i;
        for (var j = i + 1; j < 9; j++) {
            if a[j] < a[k] {
                k = j;
            }
        }
        let t = a[i];
        a[i] = a[k];
        a[k] = t;
    }
    return a[4];
}

// The guide of stage 7's luminance edge-stop (matte/bilateral.wgsl), written to the alpha: the
// luminance of the 3x3 neighbourhood's mean on p's surface (cross-bilateral weights).
fn edge_guide(p: vec2i) -> f32 {
    let xc = position_at(p);
    let nc = oct_decode(textureLoad(gb_normal, p, 0).xy);
    let fc = footprint(xc);
    var sum = luminance(textureLoad(filter_in, p, 0).rgb);
    var wsum = 1.0;
    for (var k = 1; k < 9; k++) {
        let q = p + neighbour_3x3(k);
        if !in_bounds(q) || !has_surface(q) {
            continue;
        }
        let w = bilateral_weight(xc, nc, fc, position_at(q), oct_decode(textureLoad(gb_normal, q, 0).xy));
        sum += w * luminance(textureLoad(filter_in, q, 0).rgb);
        wsum += w;
    }
    return sum / wsum;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let centre = textureLoad(filter_in, p, 0);
    if !has_surface(p) {
        textureStore(out_median, p, vec4f(centre.rgb, luminance(centre.rgb)));
        return;
    }
    // Only stage 7's edge-stop reads the guide.
    var guide = luminance(centre.rgb);
    if stage_on(STAGE_BILATERAL) && mp.edge_stop_sigmas > 0.0 {
        guide = edge_guide(p);
    }
    if !stage_on(STAGE_FIREFLY) {
        textureStore(out_median, p, vec4f(centre.rgb, guide));
        return;
    }
    var r: array<f32, 9>;
    var g: array<f32, 9>;
    var b: array<f32, 9>;
    var k = 0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let s = textureLoad(filter_in, clamp(p + vec2i(dx, dy), vec2i(0), vec2i(frame.size) - 1), 0).rgb;
            r[k] = s.r;
            g[k] = s.g;
            b[k] = s.b;
            k++;
        }
    }
    textureStore(out_median, p, vec4f(median9(r), median9(g), median9(b), guide));
}
