// Real-time trace: one sample per pixel at the G-buffer's surface, split by the factored BRDF of
// Mara et al. 2017 (§3.2-3.3). Light buffers carry no material: the matte buffer holds
// sum L_i / N of eq. (9) and the glossy buffer the sum of eq. (10) divided by F(w_s, w_o), so
// that filters never blur texture and the composite multiplies the material back in.
//
// - Punctual lights are evaluated exhaustively with the full BRDF into `direct`: at one sample
//   they carry no noise (their only randomness would be the choice of light), so they bypass
//   the filters and keep their hard shadows.
// - Emissive triangles and the environment are sampled once (next-event estimation) and split
//   into a matte and a glossy part, each weighed by the power heuristic against the path that
//   samples the same lobe, so the chains filter their noise with the indirect light.
// - One matte path (cosine-sampled, eq. (6)) and one glossy path (GGX visible normals) continue
//   with the reference tracer's loop (common/path.wgsl).
//
// The primary hit is re-derived from the triangle the raster (or, with a thin lens, the traced
// primaries) stored and this frame's camera ray (realtime/lens.wgsl), so it is exact (the same
// point the reference tracer would find for that ray). `shade` is also
// the supersampling's (realtime/samples.wgsl) for the samples it traces beside the raster's.

var gb_ids: texture_2d<u32>;
// The G-buffer's material and normal: with traced primaries (k > 1) the mean over the pixel's
// samples, which the composite remodulates with (own_over_mean).
var tr_mean_normal: texture_2d<f32>;
var tr_mean_base: texture_2d<f32>;
var tr_mean_specular: texture_2d<f32>;
var tr_mean_emission: texture_2d<f32>;
var out_matte: texture_storage_2d<rgba16float, write>;
var out_direct: texture_storage_2d<rgba16float, write>;

// The matte light's alpha: the paths its estimate averages (realtime/uncovered.wgsl).
fn write_all(px: vec2u, matte: vec3f, direct: vec3f, paths: u32) {
    textureStore(out_matte, px, vec4f(half_safe(matte), f32(paths)));
    textureStore(out_direct, px, vec4f(half_safe(direct), 1.0));
}

// What one sample at a surface carries (the buffers write_all and write_glossy fill).
struct Shaded {
    matte: vec3f,
    direct: vec3f,
    glossy: vec3f,
    // The glossy path's secondary hit distance, its first hit's reflectance and normal.
    glossy_t: f32,
    hit_reflectance: vec3f,
    hit_normal: vec3f,
    mirror: vec3f,
    representative_t: f32,
    // The shading normal (the supersampling's guide similarity, Voorhuis §5).
    n: vec3f,
    // A back face of a one-sided material: no light, and the glossy outputs of a miss.
    backface: bool,
}

// What the composite would multiply this sample's matte and glossy light by, were the pixel's
// material this sample's alone: the G-buffer's fields as the traced primaries write them
// (realtime/primaries.wgsl), with the composite's own formulas (realtime/frame.wgsl's
// schlick_mirror and remodulated_matte at camera_ray).
struct Factors {
    matte: vec3f,
    glossy: vec3f,
}

fn composite_factors(n: vec3f, base: vec3f, metallic: f32, f0: vec3f, f90: f32, rd: vec3f) -> Factors {
    let f_s = schlick_mirror(f0, f90, dot(n, -rd));
    return Factors(remodulated_matte(base, metallic, f_s), f_s);
}

// With k > 1 traced primaries the G-buffer holds the mean of the k samples' materials, and the
// composite multiplies sample 0's light by it; where the samples hit two surfaces (a defocused
// edge, a blurred silhouette) the mean of (light x material) is not (sample 0's light) x (mean
// material): a pixel mixing metal (F about 0.9, no matte albedo) with a lit wall would show the
// metal's glossy light at about half. So the light is written as sample 0's light x its own
// factor / the mean's: the composite then gives sample 0's own radiance, whose mean over
// frames is the pixel's. The material's part of the ratio is at most k (sample 0 is one of the
// k; the mean normal's Fresnel may move it a little), and the ratio is 0 where the mean factor
// is (then so is sample 0's).
fn own_over_mean(px: vec2u, hit: Hit, rd_sample: vec3f) -> Factors {
    let p = vec2i(px);
    let rd = camera_ray(px);
    let s = surface_at(hit, rd_sample);
    let m = material(s.material);
    let ms = material_at(m, s.tc);
    let bsdf = with_glass(material_bsdf(m, ms), m, ms, s.front);
    var own = Factors(vec3f(0.0), vec3f(0.0));
    if bsdf.transmission > 0.0 {
        own = composite_factors(s.ns, vec3f(0.0), 0.0, vec3f(1.0), 1.0, rd);
    } else if s.front || (m.flags & MAT_DOUBLE_SIDED) != 0u {
        let base = clamp(ms.base.rgb, vec3f(0.0), vec3f(1.0));
        let f0 = clamp(bsdf.f0, vec3f(0.0), vec3f(1.0));
        own = composite_factors(s.ns, base, clamp(ms.metallic, 0.0, 1.0), f0, clamp(max3(bsdf.f90), 0.0, 1.0), rd);
    }
    let bc = textureLoad(tr_mean_base, p, 0);
    let sp = textureLoad(tr_mean_specular, p, 0);
    let n = oct_decode(textureLoad(tr_mean_normal, p, 0).xy);
    let mean = composite_factors(n, bc.rgb, bc.a, sp.rgb, textureLoad(tr_mean_emission, p, 0).a, rd);
    return Factors(safe_ratio(own.matte, mean.matte), safe_ratio(own.glossy, mean.glossy));
}

fn safe_ratio(a: vec3f, b: vec3f) -> vec3f {
    return select(vec3f(0.0), a / max(b, vec3f(1e-20)), b > vec3f(0.0));
}

// Resampled light samples on glossy lobes at least this rough (GGX roughness, alpha = 0.04);
// smoother lobes keep MIS with their glossy path, whose BSDF sample finds a sharp highlight more
// often than light candidates chosen by a matte-like tree importance do. The threshold is not
// yet measured: of the scenes with emitters, only the many-lamp hall's floor (0.35) is rough
// glossy.
const RESAMPLED_GLOSSY_ROUGHNESS: f32 = 0.2;

// A resampled light sample's light where its shadow ray reaches it.
fn visible_light(origin: vec3f, p: vec3f, r: ResampledLight, eps: f32) -> vec3f {
    if !(max3(r.li) > 0.0) {
        return vec3f(0.0);
    }
    let leg = shadow_leg(origin, p, r.wi, r.dist, eps);
    if traverse(origin, leg.dir, leg.tmax, true).tri == NO_HIT {
        return r.li;
    }
    return vec3f(0.0);
}

// One factored sample at the hit of camera ray direction rd, its area-light sample and paths
// averaged over `path_count` independent ones. With `screen_strata` on, pixel px's light sample
// and first matte direction come from the screen's strata, seeded by strata_seed.
fn shade(rd: vec3f, hit: Hit, path_count: u32, px: vec2u, strata_seed: u32, rng: ptr<function, u32>) -> Shaded {
    let eps = params.cam_pos.w;
    let s = surface_at(hit, rd);
    let m = material(s.material);
    if !s.front && (m.flags & MAT_DOUBLE_SIDED) == 0u {
        return Shaded(vec3f(0.0), vec3f(0.0), vec3f(0.0), INF, vec3f(1.0), -rd, rd, INF, s.ns, true);
    }
    let ms = material_at(m, s.tc);
    let bsdf = with_glass(material_bsdf(m, ms), m, ms, s.front);
    if bsdf.transmission > 0.0 {
        return shade_glass(rd, hit, s, ms, path_count, rng);
    }
    let basis = onb(s.ns);
    let wo = to_local(basis, -rd);
    let origin = offset_ray(s.p, s.ng, eps);
    // F at the mirror direction w_s: the half vector is the normal, so F(w_s, w_o) = F(n . w_o).
    let f_s = fresnel(bsdf, wo.z);
    let has_matte = max3(bsdf.albedo) > 0.0;
    let has_glossy = HAS_GLOSSY && max3(f_s) > 0.0;
    let mirror = reflect(rd, s.ns);
    // The camera ray's cone where it meets the surface (secondary hits filter their textures).
    let cone_width = pixel_spread() * hit.t;
    var matte = vec3f(0.0);
    var glossy = vec3f(0.0);
    var direct = vec3f(0.0);
    var glossy_t = INF;
    var hit_reflectance = vec3f(1.0);
    var hit_normal = -mirror;
    if !depth_ok(2) || wo.z <= 0.0 {
        return Shaded(matte, direct, glossy, glossy_t, hit_reflectance, hit_normal, mirror, glossy_t, s.ns, false);
    }

    direct = punctual_light(s, bsdf, wo, basis, origin);

    let paths = max(path_count, 1u);
    for (var k = 0u; k < paths; k++) {
        // With the screen's strata on (params.switches.y), the light's point and the matte
        // path's first direction come from them (common/rng.wgsl), each use its own lattice:
        // a 16-pixel block's matte light is then stratified over the light and the hemisphere.
        // Below one sample per pixel (1 / period) a lattice spans the `period` frames in which
        // every pixel is traced once (frame.wgsl's schedule), so that a tile's samples of those
        // frames take the whole lattice, as one frame's do at one sample per pixel; a lattice
        // per frame would give its 256 / period traced pixels scattered points of 256.
        let strata = params.switches.y > 0.0;
        let epoch = frame.index / max(frame.period, 1u);
        let st_light = strata_init(px, epoch, strata_seed ^ ((2u * k + 1u) * 0x9e3779b9u));
        let st_dir = strata_init(px, epoch, strata_seed ^ ((2u * k + 2u) * 0x9e3779b9u));
        let groups = area_groups();
        let nee_select = 1.0 / f32(max(groups, 1u));
        var matte_select = nee_select;
        var glossy_select = nee_select;
        // With more than one light candidate the matte light sample is resampled (its own
        // shadow ray), and so is the glossy one on a lobe rough enough for light samples to
        // find its highlights (RESAMPLED_GLOSSY_ROUGHNESS); a smoother lobe's glossy light
        // keeps the first candidate and its MIS with the glossy path.
        let resampled = groups > 0u && frame.light_candidates > 1u;
        let glossy_nee = has_glossy && !bsdf.delta;
        let glossy_resampled = resampled && glossy_nee && ms.roughness >= RESAMPLED_GLOSSY_ROUGHNESS;
        let reused = resampled && has_matte && HAS_RESERVOIRS && k == 0u;
        if groups > 0u && (has_matte || glossy_nee) {
            var ls: LightSample;
            if strata {
                ls = sample_area_light_strata(s.p, s.ng, st_light, rng);
            } else {
                ls = sample_area_light(s.p, s.ng, rng);
            }
            let wi = to_local(basis, ls.wi);
            let first_matte = has_matte && !resampled;
            let first_glossy = glossy_nee && !glossy_resampled;
            if max3(ls.li) > 0.0 && wi.z > 0.0 && dot(ls.wi, s.ng) > 0.0 && (first_matte || first_glossy) {
                let leg = shadow_leg(origin, s.p, ls.wi, ls.dist, eps);
                if traverse(origin, leg.dir, leg.tmax, true).tri == NO_HIT {
                    if first_matte {
                        // Eq. (9): the matte light is L_i cos / pi over the pdf; m (1 - F)^2 comes later.
                        matte += ls.li * (wi.z * INV_PI) * power_heuristic(ls.pdf, wi.z * INV_PI);
                    }
                    if first_glossy {
                        let g = glossy_eval(bsdf, wo, wi);
                        glossy += ls.li * g.f_cos / f_s * power_heuristic(ls.pdf, g.pdf);
                    }
                }
            }
            if reused {
                // The first path's matte sample reuses the last frame's (realtime/reservoir.wgsl).
                matte += reservoir_direct(px, s.p, s.ns, s.ng, origin, eps, frame.light_candidates, rng);
                matte_select = NEE_RESAMPLED;
            }
            let matte_here = resampled && has_matte && !reused;
            if matte_here || glossy_resampled {
                let r = resample_area_light(s.p, s.ng, basis, bsdf, wo, f_s, ls, frame.light_candidates, glossy_resampled, rng);
                if matte_here {
                    matte += visible_light(origin, s.p, r.matte, eps);
                    matte_select = NEE_RESAMPLED;
                }
                if glossy_resampled {
                    glossy += visible_light(origin, s.p, r.glossy, eps);
                    glossy_select = NEE_RESAMPLED;
                }
            }
        }

        if has_matte {
            var u_dir: vec2f;
            if strata {
                u_dir = strata2(st_dir);
            } else {
                u_dir = rand2(rng);
            }
            matte += matte_path(basis, s.p, origin, s.ng, cone_width, matte_select, u_dir, rng);
        } else if !strata {
            // Keep the random sequence of the glossy path independent of the material.
            rand2(rng);
        }

        if has_glossy {
            var wl: vec3f;
            var start: PathStart;
            if bsdf.delta {
                // A mirror: F(h) = F(w_s) exactly, so the demodulated weight is 1.
                wl = vec3f(-wo.xy, wo.z);
                start = PathStart(origin, mirror, vec3f(1.0), 2, 0.0, true, nee_select, s.p, s.ng, vec2f(cone_width, pixel_spread()));
            } else {
                wl = reflect(-wo, sample_vndf(bsdf.alpha, wo, rand2(rng)));
                let g = glossy_eval(bsdf, wo, wl);
                var weight = vec3f(0.0);
                if g.pdf > 0.0 {
                    weight = g.f_cos / (g.pdf * f_s);
                }
                let cone = vec2f(cone_width, cone_spread_after(pixel_spread(), g.pdf));
                start = PathStart(origin, normalize(basis * wl), weight, 2, g.pdf, false, glossy_select, s.p, s.ng, cone);
            }
            if wl.z > 0.0 && dot(start.rd, s.ng) > 0.0 && max3(start.beta) > 0.0 {
                let r = trace_path(start, rng);
                glossy += r.radiance;
                glossy_t = r.first_t;
                hit_reflectance = r.first_reflectance;
                hit_normal = r.first_normal;
            }
        }
    }
    matte /= f32(paths);
    glossy /= f32(paths);

    // The representative ray's own hit distance (Voorhuis eq. (4) uses the sample's, which at
    // roughness 0.2 jumps between near and far geometry from pixel to pixel and makes the
    // reflection search ambiguous): one more closest-hit ray, only below the chain's threshold.
    var representative_t = glossy_t;
    if has_glossy && !bsdf.delta && ms.roughness < frame.representative_roughness && dot(mirror, s.ng) > 0.0 {
        representative_t = traverse(origin, mirror, INF, false).t;
    }
    return Shaded(matte, direct, glossy, glossy_t, hit_reflectance, hit_normal, mirror, representative_t, s.ns, false);
}

// Glass (common/transmission.wgsl) at the primary hit: reflection and refraction together are
// the glossy signal, which the G-buffer's glass marker (F = 1, no matte) composites unchanged.
// Each sample is the reference tracer's path from the camera (one more primary traversal, on
// glass pixels only), so next-event estimation and MIS at the glass are those of the reference
// mode. A pixel has one motion vector: the refracted image is reprojected with the glass
// surface (virtual distance 0), which is exact for a still camera and thin glass, and lags for
// thick glass under motion.
fn shade_glass(rd: vec3f, hit: Hit, s: Surface, ms: MaterialSample, path_count: u32, rng: ptr<function, u32>) -> Shaded {
    let ro = s.p - rd * hit.t;
    let paths = max(path_count, 1u);
    var glossy = vec3f(0.0);
    for (var k = 0u; k < paths; k++) {
        glossy += trace_path(camera_path(ro, rd), rng).radiance;
    }
    // The composite adds the surface's own emission.
    glossy = max(glossy / f32(paths) - select(vec3f(0.0), ms.emission, s.front), vec3f(0.0));
    let mirror = reflect(rd, s.ns);
    return Shaded(vec3f(0.0), vec3f(0.0), glossy, 0.0, vec3f(1.0), s.ns, mirror, 0.0, s.ns, false);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    // Below one sample per pixel the dispatch covers the tiles, one thread each (frame.wgsl).
    var px = gid.xy;
    if frame.period > 1u {
        px = scheduled_pixel(gid.xy);
    }
    if px.x >= frame.size.x || px.y >= frame.size.y {
        return;
    }
    var rng = rng_init(px.y * frame.size.x + px.x, frame.index, params.seed);
    reservoir_clear(px);
    // Sample 0 of the pixel: the raster's ray, or the traced primaries' first lens ray.
    let ray = primary_ray(px, 0u);
    let ro = ray.ro;
    let rd = ray.rd;
    let ids = textureLoad(gb_ids, px, 0).xy;
    if ids.y == NO_HIT {
        // Background: what the camera sees of the environment goes straight to the screen.
        write_all(px, vec3f(0.0), env_radiance(rd), 1u);
        write_glossy(px, vec3f(0.0), INF, rd, rd, vec3f(1.0), -rd, INF);
        return;
    }
    let hit = raster_hit(ro, rd, ids);
    let paths = pixel_paths(ro + rd * hit.t);
    var sh = shade(rd, hit, paths, px, params.seed ^ 0x73747261u, &rng);
    if frame.primary_samples > 1u && !sh.backface {
        let r = own_over_mean(px, hit, rd);
        sh.matte *= r.matte;
        sh.glossy *= r.glossy;
    }
    write_all(px, sh.matte, sh.direct, paths);
    write_glossy(px, sh.glossy, sh.glossy_t, select(ro - frame.cam_pos.xyz + rd * hit.t, rd, sh.backface), sh.mirror, sh.hit_reflectance, sh.hit_normal, sh.representative_t);
}
