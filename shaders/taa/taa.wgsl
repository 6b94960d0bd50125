// Temporal anti-aliasing of the composited image (the raster is jittered over a Halton(2, 3)
// sequence). History is fetched bilinearly at pixel + motion and clamped to the min/max box of
// the current 3x3 neighbourhood in YCoCg (Karis 2014), which bounds ghosting to colours present
// now (not in a static view, where nothing can ghost); then blended with weight taa_params.alpha for
// the current frame. Without a history (first frame, off screen, no surface) the current
// colour is used as is. Nor is there where a pixel that moved finds its surface at none of the
// bilinear taps' previous depths (eq. (11) of Mara et al., as the denoisers' temporal stages
// test theirs) and lies off any silhouette: a surface the move uncovered (a window's
// reveal after a step sideways) otherwise took 90% of its first frame from the wall that hid it,
// clamped into a 3x3 box whose noisy light spans both.
//
// The history's alpha carries n, its length in frames, and the current frame weighs 2 / (n + 1):
// the exponential blend whose samples are as old on average as an n-frame mean's, so that the
// first frames (denoised from little history) fade faster than in a plain mean. A still pixel
// (zero motion: its history texel is read exactly, not resampled) whose history the clamp left
// alone lets the weight fall to 1 / taa_params.still_frames: a long blend over whole Halton cycles
// converges to the box-filtered pixel, where taa_params.alpha weighs the latest offsets most and keeps
// an edge pixel off by a fraction of the edge's contrast. Moving or clamped, the weight is held
// at taa_params.alpha: bilinear resampling blurs a long history, and a clamp means the history no
// longer matches what the pixel shows. Such a history is stored with a negative length, and
// when the pixel stands still again its length restarts at taa_params.resampled_frames: held at
// taa_params.alpha, the blur that resampling left in it would otherwise outlast the stop by tens of
// frames.
//
// The image shown is the history, except at a settled pixel, where it is the last image shown
// blended towards the history by taa_params.display_ratio x 2 / (n + 1) (at most 1): a second
// low-pass that damps the flicker of a sub-pixel edge sampled at a new Halton offset every
// frame (the history moves by 2 / (n + 1) of the edge's contrast each frame) and passes the
// slower convergence of the denoised light. The history itself is not smoothed; the last image
// shown is read back from final_image, which nothing else writes.
//
// A settled pixel's history averages composites whose matte and glossy light were themselves
// running means, so it weighs old, little-converged light most. TAA also averages, with the same
// weights, the matte factor m (1 - F)^2, the glossy factor F(w_s) x the mirror demodulation, and
// the residual: the composite less those factors times the two chains' temporal outputs. Where a
// chain's history continues last frame's (this pixel's own texel, at least as long as TAA's), TAA
// follows that chain: its term becomes avg(factor) x current light, mixed in by
// taa_params.current_light (matte) or taa_params.current_glossy: the same image while the light stands still,
// and no lag while it converges. The residual's alpha holds which chains it leaves out (bit 0
// matte, bit 1 glossy), as they were followed last frame; a chain followed from last frame on
// needs its term left out of the residual then. Where the glossy chain stops continuing, its
// term goes back into the residual (last frame's light is its temporal output there, still in
// its history); where the matte chain does, or the pixel is not settled, TAA keeps its own
// average and re-sets the residual so that the two agree.
//
// A pixel that moves takes the glossy term out of its history and this frame's in
// (TaaSettings::moving_glossy): the history moved with the surface, the reflection on it moves
// its own way, and the denoiser's glossy light followed the reflection. The term each texel was
// last blended with is kept beside the history; both are read bilinearly, so where the texels
// were written while moving the difference is exactly the history of the rest of the composite
// (after a still frame it is off by TAA's average of the glossy term less the last frame's).

// TAA's own parameters (engine/src/passes/taa.rs: TaaParams; TaaSettings).
struct TaaParams {
    // 0: TAA is off and the composite passes through.
    enabled: u32,
    // The current frame's weight.
    alpha: f32,
    // In a still view the current frame's weight falls to 1 / this.
    still_frames: f32,
    // A pixel that stands still again restarts its history length here (0: carries on).
    resampled_frames: f32,
    // The shown image follows a settled pixel's history with this many times the history's own
    // weight (0: the history is shown as is).
    display_ratio: f32,
    // Share of a settled pixel's matte-light lag taken out (TaaSettings::current_light).
    current_light: f32,
    // The same for the glossy light (TaaSettings::current_glossy).
    current_glossy: f32,
    // Where a pixel moves, the history's glossy term is replaced by this frame's
    // (TaaSettings::moving_glossy).
    moving_glossy: u32,
}

var<uniform> taa_params: TaaParams;
var<storage, read> hdr: array<vec4f>;
var history: texture_2d<f32>;
var out_history: texture_storage_2d<rgba32float, write>;
var<storage, read_write> final_image: array<vec4f>;
// Averages, over TAA's history, of the matte factor m (1 - F)^2 and of the composite less that
// factor times the matte temporal's output (TaaSettings::current_light).
var material_history: texture_2d<f32>;
var out_material: texture_storage_2d<rgba32float, write>;
var residual_history: texture_2d<f32>;
var out_residual: texture_storage_2d<rgba32float, write>;
// Average of the glossy factor F(w_s) x the mirror demodulation (TaaSettings::current_glossy).
var glossy_factor_history: texture_2d<f32>;
var out_glossy_factor: texture_storage_2d<rgba16float, write>;
// The glossy term of the composite each history texel was last blended with
// (TaaSettings::moving_glossy): rgb per pixel, row-major.
var<storage, read> glossy_term_history: array<f32>;
var<storage, read_write> out_glossy_term: array<f32>;

// What TAA follows of the denoiser's matte light: taa/matte.wgsl where the denoiser offers it
// (the matte temporal's output and its reason flags and history length), taa/matte_none.wgsl
// where it does not. This pixel's glossy term as TAA follows it: taa/glossy.wgsl, or
// taa/glossy_none.wgsl where the denoiser offers none to follow; taa/glossy_term.wgsl gives the
// composite's glossy term either way (TaaSettings::moving_glossy).
struct TaaGlossy {
    // What the composite multiplies the glossy chain's light by: F(w_s) x the demodulation.
    factor: vec3f,
    // The glossy temporal's output: the light divided by the demodulation.
    light: vec3f,
    // The temporal's history is this pixel's own texel, read exactly.
    own: bool,
    // Its length in frames.
    n: f32,
}

// The residual's alpha: which chains' terms it leaves out.
const FOLLOW_MATTE: u32 = 1u;
const FOLLOW_GLOSSY: u32 = 2u;

// The terms of the chains in `chains` (FOLLOW_* bits): factor x light.
fn followed_terms(chains: u32, matte: vec3f, light: vec3f, glossy: vec3f, glossy_light: vec3f) -> vec3f {
    var sum = vec3f(0.0);
    if (chains & FOLLOW_MATTE) != 0u {
        sum += matte * light;
    }
    if (chains & FOLLOW_GLOSSY) != 0u {
        sum += glossy * glossy_light;
    }
    return sum;
}

// The composite's F(w_s) and matte factor at this pixel (0 off the surface).
fn pixel_factors(px: vec2u) -> array<vec3f, 2> {
    let g = gbuffer_at(vec2i(px));
    if !g.hit {
        return array<vec3f, 2>(vec3f(0.0), vec3f(0.0));
    }
    let f_s = fresnel_mirror(g, dot(g.n, -camera_ray(px)));
    return array<vec3f, 2>(f_s, matte_factor(g, f_s));
}

// The history's glossy term read at the taps `b` with their weights, edges clamped (as
// load_taps reads the history).
fn glossy_term_taps(b: BilinearTaps) -> vec3f {
    let hi = vec2i(frame.size) - 1;
    var sum = vec3f(0.0);
    for (var k = 0; k < 4; k++) {
        let q = clamp(bilinear_tap(b, k), vec2i(0), hi);
        let j = 3u * (u32(q.y) * frame.size.x + u32(q.x));
        sum += b.w[k] * vec3f(glossy_term_history[j], glossy_term_history[j + 1u], glossy_term_history[j + 2u]);
    }
    return sum;
}

fn hdr_at(p: vec2i) -> vec3f {
    let q = clamp(p, vec2i(0), vec2i(frame.size) - 1);
    return half_safe(hdr[u32(q.y) * frame.size.x + u32(q.x)].rgb);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let current = hdr_at(p);
    let factors = pixel_factors(gid.xy);
    let m_k = factors[1];
    let light_k = half_safe(taa_matte_light(p));
    let gl = taa_glossy(p, factors[0]);
    let glossy_term = taa_glossy_term(p, factors[0]);
    let matte_reason_k = taa_matte_state(p);
    // The matte light of this pixel continues last frame's: a surface whose history is this
    // pixel's own texel.
    let own_light = has_surface(p) && (matte_reason_k & (REASON_DISOCCLUDED | REASON_LOW_CONFIDENCE | REASON_NEIGHBOUR)) == 0u;
    let matte_n = f32(matte_reason_k >> 8u);
    var material = m_k;
    var glossy = gl.factor;
    // The chains TAA follows from this frame on.
    var chains = select(0u, FOLLOW_MATTE, own_light && taa_params.current_light > 0.0) | select(0u, FOLLOW_GLOSSY, gl.own && taa_params.current_glossy > 0.0);
    var result = current;
    var n = 1.0;
    var shown_weight = 1.0;
    let prev = vec2f(p) + 0.5 + textureLoad(gb_motion, p, 0).xy;
    let on_screen = all(prev >= vec2f(0.0)) && all(prev < vec2f(frame.size));
    let still = dot(prev - vec2f(p) - 0.5, prev - vec2f(p) - 0.5) < 1e-4;
    var taps = BilinearTaps(vec2i(0), vec4f(0.0));
    if taa_params.enabled != 0u && on_screen && frame.history_valid != 0u {
        taps = history_taps(p, prev, still);
    }
    if any(taps.w != vec4f(0.0)) {
        var lo = vec3f(3.0e38);
        var hi = vec3f(-3.0e38);
        for (var dy = -1; dy <= 1; dy++) {
            for (var dx = -1; dx <= 1; dx++) {
                let s = to_ycocg(hdr_at(p + vec2i(dx, dy)));
                lo = min(lo, s);
                hi = max(hi, s);
            }
        }
        let texel = load_taps(history, taps, taps.w);
        var hist = half_safe(texel.rgb);
        // After a change of size the history was resampled but the terms were not.
        if taa_params.moving_glossy != 0u && !still && frame.rescaled_frames <= 0.0 {
            // The history's glossy term moved with the surface; the reflection moves its own way,
            // and the denoiser's glossy light followed it there.
            hist = half_safe(hist - glossy_term_taps(taps) + glossy_term);
        }
        let y = to_ycocg(hist);
        // In a static view (no camera or object motion) the history shows what the pixel shows,
        // and the clamp can only take from it: a feature thinner than a pixel (a highlight on a
        // stair nosing, a lantern's lit glass) lies between the jittered samples of most frames,
        // the current 3x3 box then misses it, and the clamp darkened it every such frame.
        var yc = y;
        if frame.static_view == 0u || !still {
            yc = clamp(y, lo, hi);
        }
        let clamped = from_ycocg(yc);
        // A clamp by more than half-precision rounding.
        let held = any(abs(yc - y) > vec3f(1e-3 * max(abs(y.x), 1e-2)));
        // Read exactly and left alone: the history may grow past 1 / taa_params.alpha.
        let settled = still && !held;
        let weight_floor = select(taa_params.alpha, min(taa_params.alpha, 1.0 / max(taa_params.still_frames, 1.0)), settled);
        // A negative length marks a history last resampled or clamped.
        var n_prev = select(texel.a, 1.0, texel.a != texel.a);
        // After a change of size every history was resampled (realtime/rescale.wgsl): TAA's
        // counts as one resampled between texels.
        if frame.rescaled_frames > 0.0 {
            n_prev = -abs(n_prev);
        }
        if n_prev < 0.0 {
            n_prev = -n_prev;
            if settled && taa_params.resampled_frames > 0.0 {
                n_prev = min(n_prev, taa_params.resampled_frames);
            }
        }
        n = clamp(n_prev + 1.0, 1.0, 2.0 / weight_floor - 1.0);
        let w = 2.0 / (n + 1.0);
        result = mix(clamped, current, w);
        let material_prev = half_safe(load_taps(material_history, taps, taps.w).rgb);
        let glossy_prev = half_safe(load_taps(glossy_factor_history, taps, taps.w).rgb);
        material = mix(material_prev, m_k, w);
        glossy = mix(glossy_prev, gl.factor, w);
        if !settled {
            chains = 0u;
            n = -n;
        } else {
            // A chain is followed where its history continues last frame's and is at least as
            // long as TAA's.
            chains &= select(0u, FOLLOW_MATTE, matte_n >= n) | select(0u, FOLLOW_GLOSSY, gl.n >= n);
            let r_prev = load_bilinear(residual_history, prev);
            var r = half_safe(r_prev.rgb);
            var left_out = u32(clamp(r_prev.a, 0.0, 3.0));
            // The glossy chain stopped continuing: its term of last frame goes back in.
            if (left_out & FOLLOW_GLOSSY) != 0u && (chains & FOLLOW_GLOSSY) == 0u {
                r += glossy_prev * taa_glossy_previous(p);
                left_out &= ~FOLLOW_GLOSSY;
            }
            // Follow the chains left out of the residual, if all of them still continue.
            if left_out != 0u && (left_out & ~chains) == 0u {
                let rest_k = current - followed_terms(left_out, m_k, light_k, gl.factor, gl.light);
                let averaged = mix(r, rest_k, w);
                let followed = followed_terms(left_out, material, light_k, glossy, gl.light) + averaged;
                // Negative where the pixel's material and light changed together (a sub-pixel
                // edge between a lit and an unlit surface): the product of the averages is not
                // the average of the products there.
                if all(followed >= vec3f(0.0)) {
                    // One share for every chain followed: TAA keeps no average of each chain's
                    // term apart, so the larger of the two applies (TaaSettings::current_glossy).
                    let share = max(select(0.0, taa_params.current_light, (left_out & FOLLOW_MATTE) != 0u), select(0.0, taa_params.current_glossy, (left_out & FOLLOW_GLOSSY) != 0u));
                    result = mix(result, followed, share);
                }
            }
            if taa_params.display_ratio > 0.0 {
                // taa_params.display_ratio times the history's own weight: a fresh history is shown as
                // is.
                shown_weight = min(taa_params.display_ratio * 2.0 / (n + 1.0), 1.0);
            }
        }
    }
    result = half_safe(result);
    material = half_safe(material);
    glossy = half_safe(glossy);
    // What the composite adds beside the terms of the chains followed from here on.
    let residual = half_safe(result - followed_terms(chains, material, light_k, glossy, gl.light));
    textureStore(out_history, p, vec4f(result, n));
    textureStore(out_material, p, vec4f(material, 0.0));
    textureStore(out_glossy_factor, p, vec4f(glossy, 0.0));
    textureStore(out_residual, p, vec4f(residual, f32(chains)));
    let i = u32(p.y) * frame.size.x + u32(p.x);
    out_glossy_term[3u * i] = glossy_term.x;
    out_glossy_term[3u * i + 1u] = glossy_term.y;
    out_glossy_term[3u * i + 2u] = glossy_term.z;
    var shown = result;
    if shown_weight < 1.0 {
        shown = half_safe(mix(half_safe(final_image[i].rgb), result, shown_weight));
    }
    final_image[i] = vec4f(shown, 1.0);
}
