// Glossy motion: where each pixel's reflection was in the previous frame (Voorhuis §4.1-4.2.1;
// Mara et al. §3.4's virtual position), and this frame's representative hits for the next
// frame's search. Outputs:
//   motion: xy = the motion vector the glossy temporal uses (pixels, previous - current),
//           zw = the virtual-position motion vector (both kinds, for the debug views);
//   search: x = diamond iterations, y = disagreement in pixels (diamond vs virtual, or vs the
//           brute-force search when it runs), z = best distance in reflected pixel footprints;
//   hit:    xyz = representative hit (eq. 4), w = surface kind and secondary distance
//           (encode_hit_w).
// The program's prelude defines TRACED_HITS (GlossySettings::trace_representative_ray) and
// REFERENCE_RADIUS (GlossySettings::reference_search_radius, 0: no brute-force search) as
// constants (denoise/mara/glossy.rs: MotionProgram says why they are not uniforms).

var prev_depth: texture_depth_2d;
var prev_hit: texture_2d<f32>;
var out_motion: texture_storage_2d<rgba32float, write>;
var out_search: texture_storage_2d<rgba16float, write>;
var out_hit: texture_storage_2d<rgba32float, write>;

struct Probe {
    // Primary hit and representative hit of the pixel searched for, and its kind (HIT_*).
    o: vec3f,
    h: vec3f,
    kind: u32,
}

// Distance to the previous frame's pixel q with the same kind of surface.
fn search_distance(q: vec2i, probe: Probe) -> f32 {
    if !in_bounds(q) {
        return INF;
    }
    let ph = textureLoad(prev_hit, q, 0);
    if decode_hit_class(ph.w) != probe.kind {
        return INF;
    }
    // Eq. (1) wherever the representative hit is a real hit: on mirrors, and on glossy surfaces
    // when the trace traced their representative ray; eq. (5) on sampled depths.
    if probe.kind == HIT_MIRROR || TRACED_HITS {
        return length(probe.h - ph.xyz);
    }
    let oq = world_from_depth(frame.prev_inv_view_proj, q, textureLoad(prev_depth, q, 0));
    return ray_distance(probe.o, probe.h, oq, ph.xyz);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    let surface_mv = textureLoad(gb_motion, p, 0).xy;
    if !has_surface(p) {
        textureStore(out_motion, p, vec4f(surface_mv, surface_mv));
        textureStore(out_search, p, vec4f(0.0));
        textureStore(out_hit, p, vec4f(0.0, 0.0, 0.0, encode_hit_w(HIT_NONE, 0.0)));
        return;
    }
    let x = position_at(p);
    let h = representative_hit(p, x);
    let roughness = roughness_at(p);
    textureStore(out_hit, p, vec4f(h, encode_hit_w(hit_class(roughness), secondary_t(p))));

    let reflective = roughness < gp.roughness_threshold;
    let v = virtual_motion(p, x);
    let virtual_mv = select(surface_mv, v.xy, v.z > 0.0);
    var mv = surface_mv;
    var search = vec4f(0.0);
    if reflective && gp.mode == MV_VIRTUAL {
        mv = virtual_mv;
    }
    if reflective && gp.mode == MV_DIAMOND && frame.history_valid != 0u {
        let probe = Probe(x, h, hit_class(roughness));
        let start = vec2i(floor(vec2f(p) + 0.5 + surface_mv));
        let r = diamond_search(p, start, gp.initial_step, gp.max_search_steps, probe);
        // The search matches samples; the two frames sampled their pixels at different jitters.
        if r.dist < INF {
            mv = r.coord - (vec2f(p) + 0.5) + frame.jitter_shift;
        }
        let reach = reflected_footprint(p, x);
        // A still surface (no surface motion) whose pixel still shows the same reflected point
        // (within half a reflected footprint), or where the search lands within half a pixel of
        // zero (about its accuracy: tests/glossy.rs), keeps the zero motion. The search's
        // sub-pixel answer is only as good as eq. (2)-(3)'s fit (a few tenths of a pixel on
        // curved reflectors), and the temporal stage resamples history bilinearly at it every
        // frame: in a still view that compounding resampling smeared the hall's metal spheres
        // over several pixels (the level at 320x180: FLIP 0.0621; 0.0599 with this; 0.0578 with
        // surface motion everywhere). Under motion the search's answer is kept: snapping to the surface
        // motion there cost the `reflections` strafe 9% FLIP.
        let still = all(surface_mv == vec2f(0.0));
        if still && (search_distance(start, probe) <= 0.5 * reach || length(mv) < 0.5) {
            mv = surface_mv;
        }
        search = vec4f(f32(r.steps), length(mv - virtual_mv), r.dist / reach, 0.0);
        if REFERENCE_RADIUS > 0 {
            let b = brute_force_search(p, REFERENCE_RADIUS, probe);
            let ref_mv = select(mv, b.coord - (vec2f(p) + 0.5) + frame.jitter_shift, b.dist < INF);
            search.y = length(mv - ref_mv);
            // The reference's answer replaces the virtual one in zw.
            textureStore(out_motion, p, vec4f(mv, ref_mv));
            textureStore(out_search, p, vec4f(search.x, search.y, search.z, b.dist / reach));
            return;
        }
    }
    // A static view: whatever the search found (the two frames' representative hits differ by
    // their jitter and, on rough surfaces, by the sampled ray), the reflection stood still. The
    // search still runs, for its debug views and so that the frame's cost does not depend on
    // whether the camera moves.
    if gp.static_view != 0u {
        mv = surface_mv;
    }
    textureStore(out_motion, p, vec4f(mv, virtual_mv));
    textureStore(out_search, p, search);
}
