// ReSTIR DI's temporal reuse (Bitterli et al. 2020, "Spatiotemporal reservoir resampling for
// real-time ray tracing with dynamic direct lighting", §4 and Alg. 4) for the primary surface's
// matte light sample: each pixel resamples frame.light_candidates candidates of the light tree
// or the environment (RIS, eq. (5)-(6)), then merges the reservoir the last frame kept where the
// surface point was, its sample evaluated at this frame's point and where its light is now (a
// reservoir holds the light's triangle and the point's barycentrics, not a position, so a lamp
// that moved is shaded where it is). The target p^ is the unshadowed matte contribution
// luminance(L_e) cos θ / π x G in the sample's own measure (area for emitters, G = cos θ_l / d²;
// solid angle for the environment, G = 1). The merge is the biased 1 / M combination of Alg. 4
// with visibility reuse (§4.3: a kept sample its shadow ray finds hidden is stored with W = 0);
// tests/light_tree.rs measures what that costs a still view's mean. The reservoirs' buffer holds
// two slots a pixel, this frame's written and the last frame's read by the frame's parity.

const HAS_RESERVOIRS: bool = true;

struct Reservoir {
    // The pixel's surface point and its shading normal (octahedral snorm16x2): the test that the
    // reservoir a reprojected pixel holds was made for this frame's surface.
    p: vec3f,
    n: u32,
    // The light: an emitter's triangle slot or RESERVOIR_ENV; NO_EMITTER for none.
    id: u32,
    // The point: barycentric numbers (unorm16x2) or the environment's direction (octahedral
    // snorm16x2).
    u: u32,
    // The unbiased contribution weight W (eq. (6)) and the candidates M it stands for.
    w: f32,
    m: f32,
}

var<storage, read_write> reservoirs: array<Reservoir>;

const RESERVOIR_ENV: u32 = 0xfffffffeu;
// The most candidates a reused reservoir counts, in this frame's candidates (§6: 20 frames).
const RESERVOIR_HISTORY_CAP: f32 = 20.0;
// Reuse only a reservoir made within 2% of the point's distance from the camera and for a
// normal within 25 degrees: another surface's reservoir would bring its own domain of lights.
const RESERVOIR_MAX_MOVE: f32 = 0.02;
const RESERVOIR_MIN_COS: f32 = 0.9;

struct DirectSample {
    id: u32,
    u: u32,
    wi: vec3f,
    dist: f32,
    le: vec3f,
    g: f32,
}

fn no_direct_sample() -> DirectSample {
    return DirectSample(NO_EMITTER, 0u, vec3f(0.0, 0.0, 1.0), 0.0, vec3f(0.0), 0.0);
}

// Light sample (id, u) as seen from p this frame.
fn direct_sample_at(id: u32, u: u32, p: vec3f) -> DirectSample {
    if id == RESERVOIR_ENV {
        let d = oct_decode(unpack2x16snorm(u));
        return DirectSample(id, u, d, INF, env_radiance(d), 1.0);
    }
    if id == NO_EMITTER || !HAS_EMITTERS {
        return no_direct_sample();
    }
    let e = emitter_point(id, unpack2x16unorm(u), p);
    return DirectSample(id, u, e.wi, e.dist, e.le, e.g);
}

// p^ at the surface with shading normal ns and geometric normal ng.
fn direct_target(d: DirectSample, ns: vec3f, ng: vec3f) -> f32 {
    let c = dot(d.wi, ns);
    if c <= 0.0 || dot(d.wi, ng) <= 0.0 || d.g <= 0.0 {
        return 0.0;
    }
    return luminance(d.le) * c * INV_PI * d.g;
}

struct DirectCandidate {
    d: DirectSample,
    // Its source density, in its own measure, with the choice between emitters and environment.
    pdf: f32,
}

fn direct_candidate(p: vec3f, ng: vec3f, rng: ptr<function, u32>) -> DirectCandidate {
    let groups = f32(area_groups());
    let u_group = rand(rng);
    if HAS_EMITTERS && (!HAS_ENV || u_group < 0.5) {
        let u = vec3f(rand(rng), rand(rng), rand(rng));
        let c = choose_emitter(p, ng, u.x);
        if c.slot == NO_EMITTER {
            return DirectCandidate(no_direct_sample(), 0.0);
        }
        return DirectCandidate(direct_sample_at(c.slot, pack2x16unorm(u.yz), p), c.pdf_area / groups);
    }
    let ls = sample_env(rand2(rng));
    let d = direct_sample_at(RESERVOIR_ENV, pack2x16snorm(oct_encode(ls.wi)), p);
    return DirectCandidate(d, env_pdf(d.wi) / groups);
}

// Pixel px's reservoir in the slot of frames of `parity`: this frame writes the slot of
// frame.index + 1, reads the other.
fn reservoir_index(px: vec2u, parity: u32) -> u32 {
    return (parity & 1u) * frame.size.x * frame.size.y + px.y * frame.size.x + px.x;
}

// A pixel this frame does not resample (background, glass, a back face) leaves no reservoir.
fn reservoir_clear(px: vec2u) {
    reservoirs[reservoir_index(px, frame.index + 1u)].m = 0.0;
}

// The pixel's resampled matte light (L_e cos θ / π G W, its shadow ray traced), its reservoir
// stored for the next frame.
fn reservoir_direct(px: vec2u, p: vec3f, ns: vec3f, ng: vec3f, origin: vec3f, eps: f32, m: u32, rng: ptr<function, u32>) -> vec3f {
    var y = no_direct_sample();
    var t_y = 0.0;
    var w_sum = 0.0;
    for (var i = 0u; i < m; i++) {
        let c = direct_candidate(p, ng, rng);
        let t = direct_target(c.d, ns, ng);
        if ris_accept(&w_sum, t / c.pdf, rng) {
            y = c.d;
            t_y = t;
        }
    }
    var m_total = f32(m);
    let clip = frame.prev_view_proj * vec4f(p, 1.0);
    if frame.period == 1u && clip.w > 0.0 {
        let q = vec2i(floor(to_pixels(clip)));
        if all(q >= vec2i(0)) && all(q < vec2i(frame.size)) {
            let prev = reservoirs[reservoir_index(vec2u(q), frame.index)];
            let near = length(prev.p - p) <= RESERVOIR_MAX_MOVE * length(p - frame.cam_pos.xyz);
            let facing = dot(oct_decode(unpack2x16snorm(prev.n)), ns) >= RESERVOIR_MIN_COS;
            if prev.m > 0.0 && near && facing {
                let mp = min(prev.m, RESERVOIR_HISTORY_CAP * f32(m));
                let d = direct_sample_at(prev.id, prev.u, p);
                let t = direct_target(d, ns, ng);
                if ris_accept(&w_sum, t * prev.w * mp, rng) {
                    y = d;
                    t_y = t;
                }
                m_total += mp;
            }
        }
    }
    var big_w = 0.0;
    if t_y > 0.0 {
        big_w = w_sum / (m_total * t_y);
    }
    var li = vec3f(0.0);
    if big_w > 0.0 && big_w < 3.0e38 {
        let leg = shadow_leg(origin, p, y.wi, y.dist, eps);
        if traverse(origin, leg.dir, leg.tmax, true).tri == NO_HIT {
            li = y.le * (dot(y.wi, ns) * INV_PI * y.g * big_w);
        } else {
            big_w = 0.0;
        }
    } else {
        big_w = 0.0;
    }
    reservoirs[reservoir_index(px, frame.index + 1u)] = Reservoir(p, pack2x16snorm(oct_encode(ns)), y.id, y.u, big_w, m_total);
    return li;
}
