// Remodulate the light buffers bound as tr_direct, tr_matte and tr_glossy with the material
// (Mara et al. eq. (9) and (10)):
//   L = emission + direct + matte x m (1 - F(w_s))^2 + glossy x F(w_s)
// with m = base colour x (1 - metallic) (the Lambertian rho of eq. (2); the pi of eq. (9) is
// already in the matte light). The composite binds the denoiser's light there
// (realtime/composite.wgsl), the still-view mean the trace's own (taa/converge.wgsl).
// Non-finite results are 0.
fn remodulated(px: vec2u) -> vec3f {
    let p = vec2i(px);
    let g = gbuffer_at(p);
    var l = textureLoad(tr_direct, p, 0).rgb;
    // Emission is added where there is no surface too: traced primaries (a thin lens) store the
    // mean over their k samples, which may hit an emitter where sample 0 missed.
    l += g.emission;
    if g.hit {
        let rd = camera_ray(px);
        let f_s = fresnel_mirror(g, dot(g.n, -rd));
        l += textureLoad(tr_matte, p, 0).rgb * matte_factor(g, f_s);
        l += glossy_light(p) * f_s;
    }
    return select(vec3f(0.0), l, (l == l) & (abs(l) <= vec3f(3.0e38)));
}
