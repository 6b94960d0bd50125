// What the real-time trace's matte estimate is made of, shared by the trace
// (realtime/trace.wgsl) and the radiance cache's secondary samples (cache/update.wgsl): the
// area lights of its next-event estimate (emissive triangles and the environment; punctual
// lights are evaluated exhaustively into `direct`) and its cosine-sampled matte path.

fn area_groups() -> u32 {
    return select(0u, 1u, HAS_EMITTERS) + select(0u, 1u, HAS_ENV);
}

// One sample of the non-delta lights (emitters or environment, chosen uniformly) for the surface
// at p with geometric normal n.
fn sample_area_light(p: vec3f, n: vec3f, rng: ptr<function, u32>) -> LightSample {
    let u = rand(rng);
    if HAS_EMITTERS && (!HAS_ENV || u < 0.5) {
        return sample_area_light_at(p, n, u, vec3f(rand(rng), rand(rng), rand(rng)));
    }
    return sample_area_light_at(p, n, u, vec3f(rand2(rng), 0.0));
}

// The same, its point on the emitter (or direction of the environment) from the screen's
// strata (common/rng.wgsl), the choice between emitters and environment from rng.
fn sample_area_light_strata(p: vec3f, n: vec3f, st: Strata, rng: ptr<function, u32>) -> LightSample {
    let u = rand(rng);
    if HAS_EMITTERS && (!HAS_ENV || u < 0.5) {
        return sample_area_light_at(p, n, u, strata3(st));
    }
    return sample_area_light_at(p, n, u, vec3f(strata2(st), 0.0));
}

// u_group chooses emitters (below 0.5) or environment; u places the sample (emitters use all
// three numbers: triangle, then its two barycentrics; the environment u.xy).
fn sample_area_light_at(p: vec3f, n: vec3f, u_group: f32, u: vec3f) -> LightSample {
    let groups = f32(area_groups());
    var s: LightSample;
    if HAS_EMITTERS && (!HAS_ENV || u_group < 0.5) {
        s = sample_emitter(p, n, u);
    } else {
        s = sample_env(u.xy);
    }
    s.li *= groups;
    s.pdf /= groups;
    return s;
}

// A matte light sample chosen by resampled importance sampling (Talbot 2005; Bitterli et al.
// 2020, §3 and Alg. 3, the streaming form): `first` and m - 1 more samples of the area lights
// are candidates x_i with source pdf p; each weighs w_i = p^(x_i) / p(x_i), p^ the unshadowed
// matte contribution luminance(L_e) cos θ / π; one is kept with probability w_i / Σw, and
// f(y) W with W = Σw / (m p^(y)) estimates the matte light without bias wherever p^ > 0 where
// L_e cos θ > 0 (the tree gives every emitter that faces the point a pmf > 0). With `glossy`
// the same candidates are resampled a second time for the glossy light, p^ its demodulated
// contribution luminance(L_e f_cos / F(w_s)). `li` is the kept sample's contribution x W before
// its shadow ray; its `dist` and `wi` place that ray. A candidate the tree found no light for
// stays one of the m (its weight 0), as eq. (5) needs.
struct ResampledLight {
    wi: vec3f,
    dist: f32,
    li: vec3f,
}

struct ResampledLights {
    matte: ResampledLight,
    glossy: ResampledLight,
}

// One streaming-RIS reservoir: the kept sample, its weight and the weights' sum.
struct Ris {
    kept: ResampledLight,
    w_kept: f32,
    w_sum: f32,
}

// Streaming RIS's step (Alg. 3): a candidate of weight w joins the sum and replaces the kept
// one with probability w / Σw. A weight that is not finite and positive is no candidate (no
// random number drawn).
fn ris_accept(w_sum: ptr<function, f32>, w: f32, rng: ptr<function, u32>) -> bool {
    if !(w > 0.0) || w > 3.0e38 {
        return false;
    }
    *w_sum += w;
    return rand(rng) * *w_sum < w;
}

fn ris_add(r: ptr<function, Ris>, ls: LightSample, li: vec3f, w: f32, rng: ptr<function, u32>) {
    // A pointer argument names a whole variable (WGSL without unrestricted pointer parameters).
    var w_sum = (*r).w_sum;
    if ris_accept(&w_sum, w, rng) {
        (*r).kept = ResampledLight(ls.wi, ls.dist, li);
        (*r).w_kept = w;
    }
    (*r).w_sum = w_sum;
}

// f(y) W = f(y) Σw / (m p^(y)), and p^(y) / p(y) = w_y.
fn ris_result(r: Ris, m: u32) -> ResampledLight {
    var kept = r.kept;
    if r.w_kept > 0.0 {
        kept.li *= r.w_sum / (f32(m) * r.w_kept);
    } else {
        kept.li = vec3f(0.0);
    }
    return kept;
}

fn resample_area_light(p: vec3f, ng: vec3f, basis: mat3x3f, b: Bsdf, wo: vec3f, f_s: vec3f, first: LightSample, m: u32, glossy: bool, rng: ptr<function, u32>) -> ResampledLights {
    let none = ResampledLight(first.wi, first.dist, vec3f(0.0));
    var rm = Ris(none, 0.0, 0.0);
    var rg = Ris(none, 0.0, 0.0);
    for (var i = 0u; i < m; i++) {
        var ls = first;
        if i > 0u {
            ls = sample_area_light(p, ng, rng);
        }
        let wl = to_local(basis, ls.wi);
        if !(max3(ls.li) > 0.0) || wl.z <= 0.0 || dot(ls.wi, ng) <= 0.0 {
            continue;
        }
        // li is L_e / p, so w_i = luminance(li x the contribution's factor).
        let matte = ls.li * (wl.z * INV_PI);
        ris_add(&rm, ls, matte, luminance(matte), rng);
        if glossy {
            let g = ls.li * glossy_eval(b, wo, wl).f_cos / f_s;
            ris_add(&rg, ls, g, luminance(g), rng);
        }
    }
    return ResampledLights(ris_result(rm, m), ris_result(rg, m));
}

// A light sample resampled at its vertex has no pdf a BSDF-sampled hit could be weighed
// against: passed as that vertex's light-group probability (PathStart::nee_select), it makes
// every light the next segment hits weigh 0 in the power heuristic (the product stays finite,
// so no 0 x inf), and the resampled sample carries that light alone.
const NEE_RESAMPLED: f32 = 1.0e18;

// One cosine-sampled matte path (Mara et al. 2017, eq. (6)) from `origin` on a surface with
// shading frame `basis` and geometric normal ng; 0 where the direction falls below the
// geometric surface. Cosine sampling cancels eq. (7)'s cos / pi: the throughput starts at 1.
// u_dir places the first direction; the path's later vertices draw from rng. p: the surface
// point the caller's light sample was chosen for.
fn matte_path(basis: mat3x3f, p: vec3f, origin: vec3f, ng: vec3f, cone_width: f32, nee_select: f32, u_dir: vec2f, rng: ptr<function, u32>) -> vec3f {
    let wl = cosine_hemisphere(u_dir);
    let wi = basis * wl;
    if dot(wi, ng) <= 0.0 {
        return vec3f(0.0);
    }
    let cone = vec2f(cone_width, cone_spread_after(pixel_spread(), wl.z * INV_PI));
    var st = path_begin(PathStart(origin, normalize(wi), vec3f(1.0), 2, wl.z * INV_PI, false, nee_select, p, ng, cone));
    // Where the frame keeps a radiance cache, the path may end at any of its vertices with the
    // vertex's cell's light (cache/path_end.wgsl): the matte light integrates over the vertices,
    // which hides the cells' blocks. The glossy path never does: a mirror would show them.
    st.cache_from = 2;
    loop {
        if st.done {
            break;
        }
        path_step(&st, rng);
    }
    return st.radiance;
}
