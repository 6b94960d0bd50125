// Path tracing shared by the reference tracer and the real-time trace pass: light selection and
// the path loop. Next-event estimation to one light per vertex (punctual, emissive triangles or
// environment, chosen uniformly among the groups present) combined with BSDF sampling by the
// power heuristic; Russian roulette; path length counted as Mitsuba does (max_depth segments,
// 2 = direct light only).

fn light_groups() -> u32 {
    return params.num_lights + select(0u, 1u, HAS_EMITTERS) + select(0u, 1u, HAS_ENV);
}

// Sample one light group uniformly, then a point on it. li already includes 1/select-probability.
fn sample_light(p: vec3f, rng: ptr<function, u32>) -> LightSample {
    let n = light_groups();
    let u = rand(rng);
    let k = min(u32(u * f32(n)), n - 1u);
    let fn_ = f32(n);
    var s: LightSample;
    if k < params.num_lights {
        s = sample_punctual(k, p);
    } else if HAS_EMITTERS && k == params.num_lights {
        s = sample_emitter(p, vec3f(rand(rng), rand(rng), rand(rng)));
    } else {
        s = sample_env(rand2(rng));
    }
    s.li *= fn_;
    s.pdf /= fn_;
    return s;
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
    // estimate sampled (the MIS weight of an emitter hit by rd needs it).
    nee_select: f32,
}

// A camera ray: nothing to weigh against.
fn camera_path(ro: vec3f, rd: vec3f) -> PathStart {
    return PathStart(ro, rd, vec3f(1.0), 1, 0.0, true, 1.0);
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

fn trace_path(start: PathStart, rng: ptr<function, u32>) -> PathResult {
    let eps = params.cam_pos.w;
    let select_p = 1.0 / f32(max(light_groups(), 1u));
    var ro = start.ro;
    var rd = start.rd;
    var radiance = vec3f(0.0);
    var beta = start.beta;
    // Segments so far, counting the one about to be traced.
    var segments = start.segments;
    var prev_pdf = start.prev_pdf;
    var prev_delta = start.prev_delta;
    var first_t = -1.0;
    var first_reflectance = vec3f(1.0);
    var first_normal = -start.rd;
    var prev_select = start.nee_select;
    loop {
        if !depth_ok(segments) {
            break;
        }
        let hit = traverse(ro, rd, INF, false);
        if first_t < 0.0 {
            first_t = hit.t;
        }
        if hit.tri == NO_HIT {
            if HAS_ENV {
                let le = env_radiance(rd);
                var w = 1.0;
                if !prev_delta {
                    w = power_heuristic(prev_pdf, prev_select * env_pdf(rd));
                }
                radiance += beta * le * w;
            }
            break;
        }
        let s = surface_at(hit, rd);
        let m = materials[s.material];
        // The back of a single-sided surface is a black absorber, as in Mitsuba.
        if !s.front && (m.flags & MAT_DOUBLE_SIDED) == 0u {
            break;
        }
        let ms = material_at(m, s.uv);
        let emission = ms.emission;
        if segments == start.segments {
            let b = material_bsdf(m, ms);
            first_reflectance = min(b.albedo + b.f0, vec3f(1.0));
            first_normal = s.ns;
        }
        if s.front && max3(emission) > 0.0 {
            var w = 1.0;
            if !prev_delta {
                let cos_l = abs(dot(s.ng, rd));
                let d2 = dot(s.p - ro, s.p - ro);
                let light_pdf = prev_select * emitter_pdf_area(m.emission) * d2 / max(cos_l, 1e-12);
                w = power_heuristic(prev_pdf, light_pdf);
            }
            radiance += beta * emission * w;
        }
        if !depth_ok(segments + 1) {
            break;
        }
        let bsdf = material_bsdf(m, ms);
        let frame = onb(s.ns);
        let wo = to_local(frame, -rd);
        let origin = offset_ray(s.p, s.ng, eps);

        // Next-event estimation (skipped when the glossy lobe is a pure mirror and there is no
        // matte lobe: no light sample can land in a delta lobe).
        let matte_present = max3(bsdf.albedo) > 0.0;
        if light_groups() > 0u && (matte_present || !bsdf.delta) {
            let ls = sample_light(s.p, rng);
            let wi_l = to_local(frame, ls.wi);
            if max3(ls.li) > 0.0 && wi_l.z > 0.0 && dot(ls.wi, s.ng) > 0.0 {
                let e = bsdf_eval(bsdf, wo, wi_l);
                if max3(e.f_cos) > 0.0 {
                    let tmax = select(INF, ls.dist * (1.0 - 1e-4) - eps, ls.dist < INF);
                    let blocked = traverse(origin, ls.wi, tmax, true).tri != NO_HIT;
                    if !blocked {
                        var w = 1.0;
                        if ls.pdf > 0.0 {
                            w = power_heuristic(ls.pdf, e.pdf);
                        }
                        radiance += beta * e.f_cos * ls.li * w;
                    }
                }
            }
        }

        // Continue the path by sampling the BSDF.
        let u_lobe = rand(rng);
        let bs = bsdf_sample(bsdf, wo, u_lobe, rand2(rng));
        if max3(bs.weight) <= 0.0 {
            break;
        }
        let wi = frame * bs.wi;
        // A direction below the geometric surface would start inside the object.
        if dot(wi, s.ng) <= 0.0 {
            break;
        }
        beta *= bs.weight;
        prev_pdf = bs.pdf;
        prev_delta = bs.delta;
        prev_select = select_p;
        ro = origin;
        rd = normalize(wi);
        segments += 1;
        // Russian roulette from the fifth segment on, as Mitsuba (unbiased).
        if segments > params.rr_depth {
            let q = min(max3(beta), 0.95);
            if rand(rng) >= q {
                break;
            }
            beta /= q;
        }
    }
    return PathResult(radiance, select(first_t, INF, first_t < 0.0), first_reflectance, first_normal);
}

