// Stages (9, 10), the separable glossy bilateral (Mara et al. §3.4): a horizontal then a vertical
// Gaussian of sigma = 7 roughness^0.1 + epsilon pixels (glossy_sigma, with Voorhuis eq. (6)'s
// ray-differential reduction below the roughness threshold), each tap weighted by the G-buffer
// normal, plane distance and roughness. Behind mirrors the weights use the reflected surface's
// normal and position instead (Voorhuis §4.1). No firefly filter: glossy highlights are real.
// bilateral_h writes (light, sigma); bilateral_v remodulates and writes the chain's output.
// Sigma shrinks as 1 / history length past GlossySettings::sigma_full_frames (a departure from
// the paper's fixed sigma, measured in settings.rs).

var src: texture_2d<f32>;
var dst: texture_storage_2d<rgba16float, write>;

struct Features {
    // Position and normal the weights compare: the primary surface's, or behind a mirror the
    // reflected surface's.
    x: vec3f,
    n: vec3f,
    roughness: f32,
    // Pixel footprint at x (the centre's only: the weights scale plane distances by it).
    f: f32,
}

fn features(p: vec2i, centre: bool) -> Features {
    let x = position_at(p);
    let r = roughness_at(p);
    var ft = Features(x, oct_decode(textureLoad(gb_normal, p, 0).xy), r, 0.0);
    if centre {
        ft.f = footprint(x);
    }
    if is_mirror(r) {
        if centre {
            ft.f = reflected_footprint(p, x);
        }
        ft.x = x + mirror_direction(p) * secondary_t(p);
        ft.n = hit_normal(p);
    }
    return ft;
}

fn sigma_at(p: vec2i) -> f32 {
    let r = roughness_at(p);
    var dp = 0.0;
    // A reflection of the environment has no secondary hit to differentiate (and is smooth).
    if r < gp.roughness_threshold && secondary_t(p) < gp.far {
        dp = ray_differential(p, position_at(p));
    }
    return glossy_sigma(r, dp);
}

fn bilateral(p: vec2i, axis: vec2i, sigma: f32) -> vec3f {
    let centre = half_safe(textureLoad(src, p, 0).rgb);
    if sigma < 0.25 {
        return centre;
    }
    let c = features(p, true);
    let radius = i32(ceil(2.5 * sigma));
    var sum = vec3f(0.0);
    var wsum = 0.0;
    for (var k = -radius; k <= radius; k++) {
        let q = p + axis * k;
        if !in_bounds(q) || !has_surface(q) {
            continue;
        }
        let t = features(q, false);
        let fk = f32(k) / sigma;
        let dr = (t.roughness - c.roughness) / max(gp.roughness_sigma, 1e-4);
        let w = exp(-0.5 * fk * fk) * bilateral_weight(c.x, c.n, c.f, t.x, t.n) * exp(-dr * dr);
        sum += half_safe(textureLoad(src, q, 0).rgb) * w;
        wsum += w;
    }
    return select(centre, sum / wsum, wsum > 1e-6);
}

@compute @workgroup_size(8, 8)
fn bilateral_h(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    var sigma = 0.0;
    if has_surface(p) && gstage_on(GSTAGE_BILATERAL) {
        sigma = sigma_at(p);
        // The temporal stage's history length n (alpha): sigma falls as 1 / n, so the blur's
        // variance reduction (sigma^2) fades faster than the history's grows, and a converged
        // reflection ends unblurred.
        let falloff = history_falloff(gp.sigma_full_frames, textureLoad(src, p, 0).a);
        sigma *= falloff * falloff;
        // Out of focus the lens averages the light over the circle of confusion anyway
        // (realtime/uncertainty.wgsl), and there a highlight comes as rare bright lens samples
        // that a long history still shows as sparkles: in a still view that reach does not fall
        // with it (cornell_dof, 60 frames: relMSE 0.02240 -> 0.01572). While the camera or
        // anything in view moves it is not taken: the defocused box's highlight then spread past
        // its extent (a slide of 30 frames at 128x128: relMSE 0.04722 -> 0.05416).
        if frame.static_view != 0u {
            sigma = max(sigma, min(defocus_sigma(p), gp.max_sigma_px));
        }
    }
    textureStore(dst, p, vec4f(half_safe(bilateral(p, vec2i(1, 0), sigma)), sigma));
}

@compute @workgroup_size(8, 8)
fn bilateral_v(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let sigma = textureLoad(src, p, 0).a;
    var l = bilateral(p, vec2i(0, 1), sigma);
    if has_surface(p) {
        l *= demodulation(p);
    }
    textureStore(dst, p, vec4f(half_safe(l), sigma));
}
