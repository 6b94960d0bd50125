// The upscaler's accumulation (taa/upscale_common.wgsl says what it keeps and why).

var up_raw_samples: texture_2d<f32>;
var up_history: texture_2d<f32>;
var out_up_history: texture_storage_2d<rgba32float, write>;
// The raw samples' kernel-weighted mean (rgb) and weight (a); their weighted mean squared
// length (r) and sum of squared weights (g), for the mean's variance.
var raw_history: texture_2d<f32>;
var raw_m2_history: texture_2d<f32>;
var out_raw: texture_storage_2d<rgba32float, write>;
var out_raw_m2: texture_storage_2d<rg32float, write>;
// The shown raster's demodulation averaged over its jitter (rgb) and its count (a), and its
// emission's average.
var albedo_history: texture_2d<f32>;
var out_albedo: texture_storage_2d<rgba16float, write>;
var emission_history: texture_2d<f32>;
var out_emission: texture_storage_2d<rgba16float, write>;
// The raster's materials at the shown size (realtime/gbuffer.wgsl).
var shown_base_color: texture_2d<f32>;
var shown_specular: texture_2d<f32>;
var shown_ids: texture_2d<u32>;
var shown_emission: texture_2d<f32>;

fn shown_albedo(o: vec2i) -> vec3f {
    if up.materials == 0u {
        return vec3f(1.0);
    }
    let hit = textureLoad(shown_ids, o, 0).y != NO_SURFACE;
    return demodulation(hit, textureLoad(shown_base_color, o, 0), textureLoad(shown_specular, o, 0).rgb);
}

// Bilinear read of the history at shown-pixel coordinates `at` (texel centres at +0.5).
fn history_bilinear(at: vec2f) -> vec4f {
    let b = bilinear_taps(at);
    let hi = vec2i(up.out_size) - 1;
    var sum = vec4f(0.0);
    for (var k = 0; k < 4; k++) {
        sum += b.w[k] * textureLoad(up_history, clamp(bilinear_tap(b, k), vec2i(0), hi), 0);
    }
    return sum;
}

// While anything moves the materials' mean is this short: point-sampled through the motion a
// longer one smears the shown raster's texels (tests/upscale.rs's strafe, FLIP against the
// frames traced at the shown size: 0.1495 with none, 0.1450 at 2 frames, 0.1679 at 10).
const MOVING_MATERIAL_FRAMES: f32 = 2.0;

fn finite4(v: vec4f) -> bool {
    return all(v == v) && all(abs(v) <= vec4f(3.0e38));
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let o = gid.xy;
    if any(o >= up.out_size) {
        return;
    }
    let centre = centre_sample(o);
    let inv_2s2 = 1.0 / (2.0 * up.sigma * up.sigma);
    // The raw mean is kept only in a still view; in a moving one the nearest depth picks the
    // motion (a still view's motion is zero everywhere).
    let static_view = frame.static_view != 0u;
    let raw_on = up.bias_sigmas > 0.0 && static_view;
    var sum_w = 0.0;
    var sum_c = vec3f(0.0);
    var raw_w = 0.0;
    var raw_w2 = 0.0;
    var raw_c = vec3f(0.0);
    var raw_c2 = 0.0;
    var lo = vec3f(3.0e38);
    var hi = vec3f(-3.0e38);
    var nearest = clamp(centre, vec2i(0), vec2i(frame.size) - 1);
    var nearest_z = 3.0e38;
    for (var k = 0; k < 9; k++) {
        let i = centre + neighbour_3x3(k);
        if !in_bounds(i) {
            continue;
        }
        let sample = textureLoad(up_samples, i, 0);
        let c = sample.rgb;
        let d = sample_offset(o, i);
        let w = exp(-dot(d, d) * inv_2s2);
        sum_w += w;
        sum_c += w * c;
        // The kernel cut at 1% of its peak (3 sigma): remodulating a sample costs more than all
        // the rest of its use here.
        let raw_sample = select(vec4f(0.0), textureLoad(up_raw_samples, i, 0), raw_on && w >= 0.01);
        if raw_sample.a > 0.0 {
            let x = raw_sample.rgb;
            raw_w += w;
            raw_w2 += w * w;
            raw_c += w * x;
            raw_c2 += w * dot(x, x);
        }
        let y = to_ycocg(c);
        lo = min(lo, y);
        hi = max(hi, y);
        let z = select(sample.a, -1.0, static_view);
        if z >= 0.0 && z < nearest_z {
            nearest = i;
            nearest_z = z;
        }
    }
    let mv = textureLoad(gb_motion, nearest, 0).xy;
    let still = dot(mv, mv) < 1e-4;
    let settled = still && frame.static_view != 0u;
    var hist = vec4f(0.0);
    var albedo = vec4f(0.0);
    var emission = vec3f(0.0);
    let prev = vec2f(o) + 0.5 + mv / to_render();
    let on_screen = all(prev >= vec2f(0.0)) && all(prev < vec2f(up.out_size));
    if up.continues != 0u && on_screen {
        // The previous depth buffer is the render size's; without one the clamp alone decides.
        var shown = true;
        if frame.history_valid != 0u {
            let taps = history_taps(nearest, vec2f(nearest) + 0.5 + mv, still);
            shown = any(taps.w != vec4f(0.0));
        }
        if shown {
            hist = select(history_bilinear(prev), textureLoad(up_history, vec2i(o), 0), still);
            let t = vec2i(prev);
            albedo = select(textureLoad(albedo_history, t, 0), textureLoad(albedo_history, vec2i(o), 0), still);
            emission = select(textureLoad(emission_history, t, 0).rgb, textureLoad(emission_history, vec2i(o), 0).rgb, still);
        }
        if !finite4(albedo) || albedo.a <= 0.0 || !finite4(vec4f(emission, 0.0)) {
            albedo = vec4f(0.0);
            emission = vec3f(0.0);
        }
        if !finite4(hist) || hist.a <= 0.0 {
            hist = vec4f(0.0);
        }
    }
    if !settled && hist.a > 0.0 {
        hist = vec4f(from_ycocg(clamp(to_ycocg(hist.rgb), lo, hi)), min(hist.a, up.moving_weight));
    }
    let weight = hist.a + sum_w;
    var mean: vec3f;
    if weight > 1e-20 {
        mean = (hist.rgb * hist.a + sum_c) / weight;
    } else {
        mean = spatial_estimate(o);
    }
    textureStore(out_up_history, vec2i(o), vec4f(mean, weight));
    // The materials' mean over the shown raster's jitter: a plain mean in a still view, at
    // most upscale_moving_frames long while anything moves.
    var n = albedo.a;
    if !settled {
        n = min(n, MOVING_MATERIAL_FRAMES);
    }
    let a_now = shown_albedo(vec2i(o));
    textureStore(out_albedo, vec2i(o), vec4f(albedo.rgb + (a_now - albedo.rgb) / (n + 1.0), n + 1.0));
    var e_now = vec3f(0.0);
    if up.materials != 0u {
        e_now = half_safe(textureLoad(shown_emission, vec2i(o), 0).rgb);
    }
    textureStore(out_emission, vec2i(o), vec4f(emission + (e_now - emission) / (n + 1.0), 0.0));

    // The raw mean continues only while the view stands still (its own texel, unclamped).
    var raw = vec4f(0.0);
    var raw_m2 = vec4f(0.0);
    if up.raw_continues != 0u && settled {
        raw = textureLoad(raw_history, vec2i(o), 0);
        raw_m2 = textureLoad(raw_m2_history, vec2i(o), 0);
        if !finite4(raw) || !finite4(raw_m2) || raw.a <= 0.0 {
            raw = vec4f(0.0);
            raw_m2 = vec4f(0.0);
        }
    }
    let raw_weight = raw.a + raw_w;
    if raw_weight > 1e-20 {
        raw = vec4f((raw.rgb * raw.a + raw_c) / raw_weight, raw_weight);
        raw_m2 = vec4f((raw_m2.r * (raw_weight - raw_w) + raw_c2) / raw_weight, raw_m2.g + raw_w2, 0.0, 0.0);
    }
    textureStore(out_raw, vec2i(o), raw);
    textureStore(out_raw_m2, vec2i(o), raw_m2);
}
