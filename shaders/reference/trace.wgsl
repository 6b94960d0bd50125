// Reference path tracer: one path per pixel per dispatch, added to a running sum.
// Next-event estimation to one light per vertex (punctual, emissive triangles or environment,
// chosen uniformly among the groups present) combined with BSDF sampling by the power heuristic;
// Russian roulette; path length counted as Mitsuba does (max_depth segments, 2 = direct light).

// Per pixel two vec4: (sum of rgb, 0) and (sum of rgb^2, count of discarded non-finite samples).
@group(0) @binding(5) var<storage, read_write> accum: array<vec4f>;

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

fn path_radiance(ro_in: vec3f, rd_in: vec3f, rng: ptr<function, u32>) -> vec3f {
    let eps = params.cam_pos.w;
    let select_p = 1.0 / f32(max(light_groups(), 1u));
    var ro = ro_in;
    var rd = rd_in;
    var radiance = vec3f(0.0);
    var beta = vec3f(1.0);
    // Segments so far, counting the one about to be traced.
    var segments = 1;
    var prev_pdf = 0.0;
    var prev_delta = true;
    loop {
        if !depth_ok(segments) {
            break;
        }
        let hit = traverse(ro, rd, INF, false);
        if hit.tri == NO_HIT {
            if HAS_ENV {
                let le = env_radiance(rd);
                var w = 1.0;
                if !prev_delta {
                    w = power_heuristic(prev_pdf, select_p * env_pdf(rd));
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
        var emission = m.emission;
        if m.tex.w >= 0 {
            emission *= tex_sample(u32(m.tex.w), s.uv).rgb;
        }
        if s.front && max3(emission) > 0.0 {
            var w = 1.0;
            if !prev_delta {
                let cos_l = abs(dot(s.ng, rd));
                let d2 = dot(s.p - ro, s.p - ro);
                let light_pdf = select_p * emitter_pdf_area(m.emission) * d2 / max(cos_l, 1e-12);
                w = power_heuristic(prev_pdf, light_pdf);
            }
            radiance += beta * emission * w;
        }
        if !depth_ok(segments + 1) {
            break;
        }
        var base = m.base_color;
        var metallic = m.metallic;
        var roughness = m.roughness;
        if m.tex.x >= 0 {
            base *= tex_sample(u32(m.tex.x), s.uv);
        }
        if m.tex.y >= 0 {
            let mr = tex_sample(u32(m.tex.y), s.uv);
            roughness *= mr.g;
            metallic *= mr.b;
        }
        let bsdf = make_bsdf(base.rgb, metallic, roughness, m.specular_factor, m.specular_color);
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
    return radiance;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if gid.x >= params.width || gid.y >= params.height {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    var rng = rng_init(pixel, params.sample_index, params.seed);
    // A uniform position in the pixel's square (Mitsuba's box filter).
    let j = rand2(&rng);
    let ndc = vec2f(
        (f32(gid.x) + j.x) / f32(params.width) * 2.0 - 1.0,
        1.0 - (f32(gid.y) + j.y) / f32(params.height) * 2.0,
    );
    let rd = normalize(params.cam_fwd.xyz + ndc.x * params.cam_right.xyz + ndc.y * params.cam_up.xyz);
    var l = path_radiance(params.cam_pos.xyz, rd, &rng);
    var bad = 0.0;
    // NaN and Inf never reach the image: the sample is dropped and counted.
    if !is_finite3(l) {
        l = vec3f(0.0);
        bad = 1.0;
    }
    let a = accum[pixel * 2u];
    let b = accum[pixel * 2u + 1u];
    accum[pixel * 2u] = vec4f(a.rgb + l, 0.0);
    accum[pixel * 2u + 1u] = vec4f(b.rgb + l * l, b.w + bad);
}
