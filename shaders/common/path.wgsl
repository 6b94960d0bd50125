// Path tracing shared by the reference tracer and the real-time trace pass: light selection and
// the path loop. Next-event estimation to one light per vertex (punctual, emissive triangles or
// environment, chosen uniformly among the groups present) combined with BSDF sampling by the
// power heuristic; Russian roulette; path length counted as Mitsuba does (max_depth segments,
// 2 = direct light only).

fn light_groups() -> u32 {
    return params.num_lights + select(0u, 1u, HAS_EMITTERS) + select(0u, 1u, HAS_ENV);
}

// What common/emitters.wgsl (or emitters_none.wgsl) gives of an emissive triangle's point seen
// from p: the direction and distance to it, its radiance towards p and the geometric factor
// cos θ_l / d² that turns its area density into a solid-angle one.
struct EmitterPoint {
    wi: vec3f,
    dist: f32,
    le: vec3f,
    g: f32,
}

// An emitter the light tree chose (slot NO_EMITTER: none) and the area density of its point.
const NO_EMITTER: u32 = 0xffffffffu;

struct EmitterChoice {
    slot: u32,
    pdf_area: f32,
}

// Sample one light group uniformly, then a point on it (emitters by the light tree's importance
// to p and the geometric normal n). li already includes 1/select-probability.
fn sample_light(p: vec3f, n: vec3f, rng: ptr<function, u32>) -> LightSample {
    let groups = light_groups();
    let u = rand(rng);
    let k = min(u32(u * f32(groups)), groups - 1u);
    let fn_ = f32(groups);
    var s: LightSample;
    if k < params.num_lights {
        s = sample_punctual(k, p);
    } else if HAS_EMITTERS && k == params.num_lights {
        s = sample_emitter(p, n, vec3f(rand(rng), rand(rng), rand(rng)));
    } else {
        s = sample_env(rand2(rng));
    }
    s.li *= fn_;
    s.pdf /= fn_;
    return s;
}

// A shadow ray from o along d up to tmax (none where tmax is 0), and the light it brings where
// nothing blocks it.
struct ShadowRay {
    o: vec3f,
    d: vec3f,
    tmax: f32,
    light: vec3f,
}

// What a path vertex adds before the path goes on (`vertex_light`): the light sample's
// light, times the throughput; or, where the path ends there, all of the rest of the path's.
struct VertexLight {
    light: vec3f,
    ended: bool,
}

// Punctual light i at surface s (BSDF b, outgoing direction wo in the frame `basis`) with its
// shadow ray from `origin`; no light where it cannot reach the surface's lobe.
fn punctual_ray(i: u32, s: Surface, b: Bsdf, wo: vec3f, basis: mat3x3f, origin: vec3f) -> ShadowRay {
    let eps = params.cam_pos.w;
    let ls = sample_punctual(i, s.p);
    let wi = to_local(basis, ls.wi);
    let leg = shadow_leg(origin, s.p, ls.wi, ls.dist, eps);
    var r = ShadowRay(origin, leg.dir, leg.tmax, vec3f(0.0));
    if max3(ls.li) > 0.0 && wi.z > 0.0 && dot(ls.wi, s.ng) > 0.0 {
        r.light = bsdf_eval(b, wo, wi).f_cos * ls.li;
    }
    return r;
}

// Every punctual light at surface s, each with its shadow ray: at one sample they carry no
// noise (the real-time trace's `direct`; a path that ends in the radiance cache casts the same
// rays through its own loop, cache/path_end.wgsl).
fn punctual_light(s: Surface, b: Bsdf, wo: vec3f, basis: mat3x3f, origin: vec3f) -> vec3f {
    var l = vec3f(0.0);
    for (var i = 0u; i < params.num_lights; i++) {
        let r = punctual_ray(i, s, b, wo, basis, origin);
        if max3(r.light) > 0.0 && traverse(r.o, r.d, r.tmax, true).tri == NO_HIT {
            l += r.light;
        }
    }
    return l;
}

// Next-event estimation at surface s (BSDF b, outgoing direction wo in the frame `basis`): one
// light sample with its shadow ray from `origin` (from the far side where it goes through a
// transmitting surface), weighed by the power heuristic against BSDF sampling, times the
// throughput beta. Skipped when the glossy lobe is a pure mirror and there is no matte lobe:
// no light sample can land in a delta lobe.
fn next_event(s: Surface, b: Bsdf, wo: vec3f, basis: mat3x3f, origin: vec3f, beta: vec3f, rng: ptr<function, u32>) -> vec3f {
    let eps = params.cam_pos.w;
    let matte_present = max3(b.albedo) > 0.0;
    if light_groups() == 0u || (!matte_present && b.delta) {
        return vec3f(0.0);
    }
    let ls = sample_light(s.p, s.ng, rng);
    let wi_l = to_local(basis, ls.wi);
    let through = b.transmission > 0.0 && wi_l.z < 0.0 && dot(ls.wi, s.ng) < 0.0;
    if max3(ls.li) > 0.0 && ((wi_l.z > 0.0 && dot(ls.wi, s.ng) > 0.0) || through) {
        let e = bsdf_eval(b, wo, wi_l);
        if max3(e.f_cos) > 0.0 {
            let start = select(origin, offset_ray(s.p, -s.ng, eps), through);
            let leg = shadow_leg(start, s.p, ls.wi, ls.dist, eps);
            let blocked = traverse(start, leg.dir, leg.tmax, true).tri != NO_HIT;
            if !blocked {
                var w = 1.0;
                if ls.pdf > 0.0 {
                    w = power_heuristic(ls.pdf, e.pdf);
                }
                return beta * e.f_cos * ls.li * w;
            }
        }
    }
    return vec3f(0.0);
}

// next_event's light sample as a ray for a caller that casts it among others
// (cache/path_end.wgsl), its light without the throughput. next_event keeps its own code,
// which leaves before setting up the ray where the sample brings no light, for every frame
// without the cache.
fn light_sample_ray(s: Surface, b: Bsdf, wo: vec3f, basis: mat3x3f, origin: vec3f, rng: ptr<function, u32>) -> ShadowRay {
    let eps = params.cam_pos.w;
    let ls = sample_light(s.p, s.ng, rng);
    let wi = to_local(basis, ls.wi);
    let through = b.transmission > 0.0 && wi.z < 0.0 && dot(ls.wi, s.ng) < 0.0;
    let start = select(origin, offset_ray(s.p, -s.ng, eps), through);
    let leg = shadow_leg(start, s.p, ls.wi, ls.dist, eps);
    var r = ShadowRay(start, leg.dir, leg.tmax, vec3f(0.0));
    if max3(ls.li) > 0.0 && ((wi.z > 0.0 && dot(ls.wi, s.ng) > 0.0) || through) {
        let e = bsdf_eval(b, wo, wi);
        var w = 1.0;
        if ls.pdf > 0.0 {
            w = power_heuristic(ls.pdf, e.pdf);
        }
        r.light = e.f_cos * ls.li * w;
    }
    return r;
}

fn depth_ok(segments: i32) -> bool {
    return params.max_depth < 0 || segments <= params.max_depth;
}

// Where a path continues from: the ray about to be traced, the throughput so far, the segment
// count including this ray, and the pdf of the technique that chose rd (for MIS against NEE).
struct PathStart {
    ro: vec3f,
    rd: vec3f,
    beta: vec3f,
    segments: i32,
    prev_pdf: f32,
    prev_delta: bool,
    // Probability with which the vertex that chose rd picked the light group its own next-event
    // estimate sampled, and the point and geometric normal that estimate chose its emitter for
    // (the MIS weight of an emitter hit by rd needs them).
    nee_select: f32,
    nee_p: vec3f,
    nee_n: vec3f,
    // The ray cone (common/scene.wgsl, cone_lod): its width at ro and its spread angle.
    cone: vec2f,
}

// The angle between neighbouring pixels' rays at the image centre: a camera ray's cone spread
// (Akenine-Moller et al. 2019, eq. (20.30)).
fn pixel_spread() -> f32 {
    return 2.0 * length(params.cam_up.xyz) / (length(params.cam_fwd.xyz) * f32(params.height));
}

// A camera ray: nothing to weigh against.
fn camera_path(ro: vec3f, rd: vec3f) -> PathStart {
    return PathStart(ro, rd, vec3f(1.0), 1, 0.0, true, 1.0, ro, vec3f(0.0), vec2f(0.0, pixel_spread()));
}

// What a path contributes and where its first segment ended (INF for a miss).
struct PathResult {
    radiance: vec3f,
    first_t: f32,
    // The first hit's reflectance (matte albedo + F0) and shading normal: the features of the
    // first non-specular hit that the glossy chain uses behind a mirror (Voorhuis §4.1). A miss
    // reports reflectance 1 and the normal facing back along the ray.
    first_reflectance: vec3f,
    first_normal: vec3f,
}

// A path in flight: where it continues from and what it has gathered. `path_step` traces one
// segment, so that a loop may advance a path and, when it ends, start another one in the same
// iterations (the reference tracer's samples, the real-time trace's matte then glossy path):
// on SIMD lanes a loop of whole paths waits for the longest path of every round.
struct PathState {
    ro: vec3f,
    rd: vec3f,
    beta: vec3f,
    // Segments so far, counting the one about to be traced.
    segments: i32,
    prev_pdf: f32,
    prev_delta: bool,
    prev_select: f32,
    // Where the last vertex's light sample chose its emitter (PathStart::nee_p, nee_n).
    prev_p: vec3f,
    prev_n: vec3f,
    radiance: vec3f,
    first_t: f32,
    first_reflectance: vec3f,
    first_normal: vec3f,
    done: bool,
    // The ray cone at ro (PathStart::cone).
    cone: vec2f,
    // The square of the index ratios crossed so far (Mitsuba's eta^2): Russian roulette weighs
    // the throughput by it, so that refraction's radiance scaling 1 / eta^2 does not end paths
    // inside glass that will regain it on the way out.
    eta2: f32,
    // The segment count from which a vertex may end the path with the light the radiance cache
    // holds for it (`path_end`; NEVER_CACHED: no vertex does).
    cache_from: i32,
}

const NEVER_CACHED: i32 = 0x7fffffff;

fn path_begin(start: PathStart) -> PathState {
    return PathState(start.ro, start.rd, start.beta, start.segments, start.prev_pdf, start.prev_delta, start.nee_select, start.nee_p, start.nee_n, vec3f(0.0), -1.0, vec3f(1.0), -start.rd, false, start.cone, 1.0, NEVER_CACHED);
}

fn path_result(st: PathState) -> PathResult {
    return PathResult(st.radiance, select(st.first_t, INF, st.first_t < 0.0), st.first_reflectance, st.first_normal);
}

fn trace_path(start: PathStart, rng: ptr<function, u32>) -> PathResult {
    var st = path_begin(start);
    loop {
        if st.done {
            break;
        }
        path_step(&st, rng);
    }
    return path_result(st);
}

// One segment of the path: trace it, add what it finds, and choose the next (or end the path).
fn path_step(st: ptr<function, PathState>, rng: ptr<function, u32>) {
    let eps = params.cam_pos.w;
    let select_p = 1.0 / f32(max(light_groups(), 1u));
    let segments = (*st).segments;
    let ro = (*st).ro;
    let rd = (*st).rd;
    let prev_delta = (*st).prev_delta;
    let prev_pdf = (*st).prev_pdf;
    let prev_select = (*st).prev_select;
    (*st).done = true;
    if !depth_ok(segments) {
        return;
    }
    let hit = traverse(ro, rd, INF, false);
    // The path's first segment (first_t is negative until then).
    let first = (*st).first_t < 0.0;
    if first {
        (*st).first_t = hit.t;
    }
    if hit.tri == NO_HIT {
        if HAS_ENV {
            let le = env_radiance(rd);
            var w = 1.0;
            if !prev_delta {
                w = power_heuristic(prev_pdf, prev_select * env_pdf(rd));
            }
            (*st).radiance += (*st).beta * le * w;
        }
        return;
    }
    var s = surface_at(hit, rd);
    let m = material(s.material);
    // The back of a single-sided surface is a black absorber, as in Mitsuba.
    if !s.front && (m.flags & MAT_DOUBLE_SIDED) == 0u {
        return;
    }
    // The cone's width where it meets the surface; after the primary hit its footprint picks
    // the mip level of every texture read.
    let cone_width = (*st).cone.x + (*st).cone.y * hit.t;
    if HAS_TEXTURES && segments > 1 && params.switches.x > 0.0 && any(m.tex >= vec4i(0)) {
        s.tc.lod = cone_lod(hit, cone_width, dot(s.ng, rd));
        s.tc.xi = f32(pcg_hash(bitcast<u32>(hit.b.x) ^ pcg_hash(bitcast<u32>(hit.t)))) * (1.0 / 4294967296.0);
    }
    // A segment that ends on the inside of glass crossed its volume.
    let beta = (*st).beta * glass_absorption(m, s.front, hit.t);
    let ms = material_at(m, s.tc);
    let emission = ms.emission;
    let bsdf = with_glass(material_bsdf(m, ms), m, ms, s.front);
    if first {
        (*st).first_reflectance = min(bsdf.albedo + bsdf.f0, vec3f(1.0));
        (*st).first_normal = s.ns;
    }
    if s.front && max3(emission) > 0.0 {
        var w = 1.0;
        if !prev_delta {
            let cos_l = abs(dot(s.ng, rd));
            let d2 = dot(s.p - ro, s.p - ro);
            let area_pdf = emitter_pdf_area(hit.tri, (*st).prev_p, (*st).prev_n);
            let light_pdf = prev_select * area_pdf * d2 / max(cos_l, 1e-12);
            w = power_heuristic(prev_pdf, light_pdf);
        }
        (*st).radiance += beta * emission * w;
    }
    if !depth_ok(segments + 1) {
        return;
    }
    let frame = onb(s.ns);
    let wo = to_local(frame, -rd);
    let origin = offset_ray(s.p, s.ng, eps);
    // The light sample, or where the path may end in the radiance cache here, the rest of the
    // path from the cache (common/path_end_none.wgsl never ends one; cache/path_end.wgsl).
    let v = vertex_light(s, bsdf, wo, frame, origin, beta, segments >= (*st).cache_from && wo.z > 0.0, hit.t, rng);
    (*st).radiance += v.light;
    if v.ended {
        return;
    }
    // Rays that go through (glass) start on the surface's far side.
    let origin_through = offset_ray(s.p, -s.ng, eps);
    let transmits = bsdf.transmission > 0.0;

    // Continue the path by sampling the BSDF.
    let u_lobe = rand(rng);
    let bs = bsdf_sample(bsdf, wo, u_lobe, rand2(rng));
    if max3(bs.weight) <= 0.0 {
        return;
    }
    let wi = frame * bs.wi;
    // A direction below the geometric surface would start inside the object, unless the BSDF
    // chose to go through (and then it must leave by the far side).
    let through = transmits && bs.wi.z < 0.0;
    if select(dot(wi, s.ng) <= 0.0, dot(wi, s.ng) >= 0.0, through) {
        return;
    }
    var next_beta = beta * bs.weight;
    if through && !bsdf.thin {
        (*st).eta2 *= bsdf.eta * bsdf.eta;
    }
    // Russian roulette from the fifth segment on, as Mitsuba (unbiased).
    if segments + 1 > params.rr_depth {
        let q = min(max3(next_beta) * (*st).eta2, 0.95);
        if rand(rng) >= q {
            return;
        }
        next_beta /= q;
    }
    (*st).beta = next_beta;
    (*st).prev_pdf = bs.pdf;
    (*st).prev_delta = bs.delta;
    (*st).prev_select = select_p;
    (*st).prev_p = s.p;
    (*st).prev_n = s.ng;
    (*st).ro = select(origin, origin_through, through);
    (*st).rd = normalize(wi);
    (*st).cone = vec2f(cone_width, cone_spread_after((*st).cone.y, bs.pdf));
    (*st).segments = segments + 1;
    (*st).done = false;
}
