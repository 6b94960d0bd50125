// Reflection motion vectors by diamond search (Voorhuis §4.1 and Appendix A, after Zhu and Ma
// 2000): find the previous frame's pixel whose reflected hit is closest to this pixel's. The
// including module defines `Probe` (what is searched for) and `search_distance(q, probe)`
// (distance to the previous frame's pixel q, or INF where q is off-screen or has no glossy
// surface): glossy/motion.wgsl by eq. (1) and (5), tests by synthetic positions.

struct SearchResult {
    // Matched position in the previous frame (pixel centres at integer + 0.5), sub-pixel.
    coord: vec2f,
    best: vec2i,
    dist: f32,
    // Large-pattern iterations taken.
    steps: u32,
}

// 5-tap LDSP (Cheng et al., Voorhuis Figure 3): the centre and these, scaled by the step.
const LDSP = array<vec2i, 4>(vec2i(2, 0), vec2i(-2, 0), vec2i(0, 2), vec2i(0, -2));
const SDSP = array<vec2i, 4>(vec2i(1, 0), vec2i(-1, 0), vec2i(0, 1), vec2i(0, -1));

// Appendix A: start at p or at p moved by the surface motion vector, whichever is closer; LDSP
// iterations re-centre on the best tap and halve the step when the centre stays best, until the
// step is 1; one final SDSP. `initial_step` 1 is the search without LDSP scaling.
fn diamond_search(p: vec2i, by_surface: vec2i, initial_step: u32, max_steps: u32, probe: Probe) -> SearchResult {
    var best = p;
    var best_d = search_distance(p, probe);
    let dm = search_distance(by_surface, probe);
    if dm < best_d {
        best = by_surface;
        best_d = dm;
    }
    var center = best;
    var step = i32(max(initial_step, 1u));
    var steps = 0u;
    loop {
        if steps >= max_steps {
            break;
        }
        steps += 1u;
        for (var i = 0u; i < 4u; i++) {
            let q = center + LDSP[i] * step;
            let d = search_distance(q, probe);
            if d < best_d {
                best_d = d;
                best = q;
            }
        }
        if all(best == center) {
            if step == 1 {
                break;
            }
            step /= 2;
        }
        center = best;
    }
    for (var i = 0u; i < 4u; i++) {
        let q = center + SDSP[i];
        let d = search_distance(q, probe);
        if d < best_d {
            best_d = d;
            best = q;
        }
    }
    return SearchResult(refine(best, best_d, probe), best, best_d, steps);
}

// Every pixel of a (2r + 1)^2 window: the yardstick of §7.4.
fn brute_force_search(p: vec2i, r: i32, probe: Probe) -> SearchResult {
    var best = p;
    var best_d = search_distance(p, probe);
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let q = p + vec2i(dx, dy);
            let d = search_distance(q, probe);
            if d < best_d {
                best_d = d;
                best = q;
            }
        }
    }
    return SearchResult(refine(best, best_d, probe), best, best_d, 0u);
}

// Sub-pixel refinement, eq. (2)-(3): of the four 2x2 blocks that contain the best pixel, the one
// with the smallest summed distance; each of its pixels weighted by the product of the other
// three's distances (a pixel at distance 0 takes all the weight).
fn refine(best: vec2i, best_d: f32, probe: Probe) -> vec2f {
    let centre = vec2f(best) + 0.5;
    if !(best_d < INF) || best_d <= 0.0 {
        return centre;
    }
    var d: array<f32, 9>;
    for (var i = 0; i < 9; i++) {
        d[i] = search_distance(best + vec2i(i % 3 - 1, i / 3 - 1), probe);
    }
    var block = vec2i(-1);
    var block_sum = INF;
    for (var oy = 0; oy <= 1; oy++) {
        for (var ox = 0; ox <= 1; ox++) {
            let s = d[oy * 3 + ox] + d[oy * 3 + ox + 1] + d[oy * 3 + ox + 3] + d[oy * 3 + ox + 4];
            if s < block_sum {
                block_sum = s;
                block = vec2i(ox, oy);
            }
        }
    }
    if block.x < 0 {
        return centre;
    }
    var c: array<vec2f, 4>;
    var dd: array<f32, 4>;
    for (var k = 0; k < 4; k++) {
        let o = block + vec2i(k % 2, k / 2);
        // Relative to the block's sum, so that the products neither overflow nor underflow.
        dd[k] = d[o.y * 3 + o.x] / block_sum;
        c[k] = centre + vec2f(o - vec2i(1));
    }
    var sum_w = 0.0;
    var coord = vec2f(0.0);
    for (var k = 0; k < 4; k++) {
        var wk = 1.0;
        for (var j = 0; j < 4; j++) {
            if j != k {
                wk *= dd[j];
            }
        }
        sum_w += wk;
        coord += wk * c[k];
    }
    if !(sum_w > 0.0) || !(sum_w < INF) {
        return centre;
    }
    return coord / sum_w;
}
