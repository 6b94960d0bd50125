// Traced primaries: with a thin lens the primary hit is random, so the raster cannot draw it.
// k = frame.primary_samples lens rays per pixel (realtime/lens.wgsl) give what the raster's
// G-buffer holds, as means over the samples (Moon et al. 2017 §4.1: "feature images are computed
// by averaging ... samples at each pixel"), and the statistics of the samples' world positions
// the pre-filter needs (§4.2-4.3, appendix B). Sample 0's triangle is the pixel's id: the trace
// continues its path from that hit (trace.wgsl re-derives it from the same ray).
//
// Eq. (2): a world position sample is the hit point carried by its object's motion to the
// shutter's close (common/motion_*.wgsl: compensated_position; the hit itself without motion
// blur), so that a moving object's samples spread along its motion only as far as the camera
// and the lens spread them, and the covariance shows the motion's direction (§4.2).
//
// Per pixel, as u32 words (floats bitcast) so that ids pass unchanged:
//   pr_features (the G-buffer, realtime/primaries_resolve.wgsl writes it into the targets):
//     0: mean shading normal (facing the camera) xyz, mean view depth
//     1: base colour rgb, metallic      2: F0 rgb, roughness
//     3: emission rgb (sum over all k samples / k: a miss adds none), f90
//     4: motion xy (pixels), object index and triangle slot of sample 0 (NO_SURFACE: a miss)
//   pr_moments (the pre-filter's):
//     0: mean world position p~ xyz, hits n      1: S xx, xy, xz, yy (eq. (10))
//     2: S yz, zz, hits of the even samples n_A  3: mean position of the even samples xyz
// Means of features and positions are over the samples that hit.

var<storage, read_write> pr_features: array<vec4u>;
var<storage, read_write> pr_moments: array<vec4u>;

const FEATURE_WORDS: u32 = 5u;
const MOMENT_WORDS: u32 = 4u;

fn bits(v: vec4f) -> vec4u {
    return bitcast<vec4u>(v);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let px = gid.xy;
    if px.x >= frame.size.x || px.y >= frame.size.y {
        return;
    }
    let pixel = px.y * frame.size.x + px.x;
    let k = max(frame.primary_samples, 1u);
    let fwd = normalize(frame.cam_fwd.xyz);
    var ids = vec2u(NO_HIT, NO_HIT);
    var n = 0.0;
    var n_a = 0.0;
    var normal = vec3f(0.0);
    var base = vec4f(0.0);
    var spec = vec4f(0.0);
    var emission = vec4f(0.0);
    var motion = vec2f(0.0);
    var depth = 0.0;
    // Positions relative to the first hit (shifted data keep the covariance's f32 sums exact far
    // from the origin); second moments as xx, xy, xz, yy, yz, zz.
    var origin = vec3f(0.0);
    var sum_p = vec3f(0.0);
    var sum_a = vec3f(0.0);
    var m_a = vec3f(0.0);
    var m_b = vec3f(0.0);
    for (var j = 0u; j < k; j++) {
        let ray = primary_ray(px, j);
        let hit = traverse(ray.ro, ray.rd, INF, false);
        if hit.tri == NO_HIT {
            continue;
        }
        let s = surface_at(hit, ray.rd);
        let m = material(s.material);
        let ms = material_at(m, s.tc);
        let bsdf = with_glass(material_bsdf(m, ms), m, ms, s.front);
        let object = hit_object(hit);
        if j == 0u {
            ids = vec2u(object, hit.tri);
        }
        let p = compensated_position(hit, s.p);
        if n == 0.0 {
            origin = p;
        }
        n += 1.0;
        normal += s.ns;
        if bsdf.transmission > 0.0 {
            // Glass, as the raster writes it (realtime/gbuffer.wgsl).
            spec += vec4f(1.0, 1.0, 1.0, clamp(ms.roughness, 0.0, 1.0));
            emission += vec4f(half_safe(select(vec3f(0.0), ms.emission, s.front)), 1.0);
        } else if s.front || (m.flags & MAT_DOUBLE_SIDED) != 0u {
            base += vec4f(clamp(ms.base.rgb, vec3f(0.0), vec3f(1.0)), clamp(ms.metallic, 0.0, 1.0));
            spec += vec4f(clamp(bsdf.f0, vec3f(0.0), vec3f(1.0)), clamp(ms.roughness, 0.0, 1.0));
            emission += vec4f(half_safe(select(vec3f(0.0), ms.emission, s.front)), clamp(max3(bsdf.f90), 0.0, 1.0));
        } else {
            // The tracer's black absorber (the back of a one-sided surface), as the raster writes it.
            spec.a += 1.0;
        }
        let cur = to_pixels(frame.unjittered_view_proj * vec4f(p, 1.0));
        let prev = to_pixels(frame.prev_view_proj * vec4f(previous_vertex(hit.tri, hit.b, object, p), 1.0));
        motion += prev - cur;
        depth += dot(p - frame.cam_pos.xyz, fwd);
        let d = p - origin;
        sum_p += d;
        m_a += d * d;
        m_b += vec3f(d.x * d.y, d.x * d.z, d.y * d.z);
        if j % 2u == 0u {
            sum_a += d;
            n_a += 1.0;
        }
    }
    let fo = pixel * FEATURE_WORDS;
    let mo = pixel * MOMENT_WORDS;
    let inv_n = 1.0 / max(n, 1.0);
    let mean_d = sum_p * inv_n;
    // Appendix B, eq. (10): the biased (1/n) sample covariance.
    let c_a = m_a * inv_n - mean_d * mean_d;
    let c_b = m_b * inv_n - vec3f(mean_d.x * mean_d.y, mean_d.x * mean_d.z, mean_d.y * mean_d.z);
    pr_features[fo] = bits(vec4f(normal * inv_n, depth * inv_n));
    pr_features[fo + 1u] = bits(base * inv_n);
    pr_features[fo + 2u] = bits(spec * inv_n);
    // Emission over all k samples: the composite adds it wherever sample 0 lands, so that its
    // mean over frames is the lens's mean (a miss adds none, as the reference's camera ray).
    pr_features[fo + 3u] = bits(vec4f(emission.rgb / f32(k), emission.a * inv_n));
    pr_features[fo + 4u] = vec4u(bitcast<vec2u>(motion * inv_n), ids);
    pr_moments[mo] = bits(vec4f(origin + mean_d, n));
    pr_moments[mo + 1u] = bits(vec4f(max(c_a.x, 0.0), c_b.x, c_b.y, max(c_a.y, 0.0)));
    pr_moments[mo + 2u] = bits(vec4f(c_b.z, max(c_a.z, 0.0), n_a, 0.0));
    pr_moments[mo + 3u] = bits(vec4f(origin + sum_a / max(n_a, 1.0), 0.0));
}
