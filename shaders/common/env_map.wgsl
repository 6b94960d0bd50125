// Equirectangular environment with importance sampling by luminance x sin(theta) (a piecewise
// constant 2D distribution: marginal CDF over rows, conditional CDFs over columns; Pharr et al.,
// PBRT 3rd ed. 13.6.7 and 14.2.4). Mitsuba's mapping: column u from the left, row v from the top,
// local l = (sin 2πu sin πv, cos πv, -cos 2πu sin πv), world = R_y(a) l.
// Buffer: W*H RGB texels, then the marginal CDF (H+1), then H conditional CDFs (W+1 each).
var<storage, read> env_data: array<f32>;

fn env_texel(col: u32, row: u32) -> vec3f {
    let i = (row * params.env_size.x + col) * 3u;
    return vec3f(env_data[i], env_data[i + 1u], env_data[i + 2u]);
}

fn env_uv(d: vec3f) -> vec2f {
    // Undo R_y(a): rotate by -a.
    let c = params.env_rot.x;
    let s = params.env_rot.y;
    let l = vec3f(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
    var u = atan2(l.x, -l.z) * (0.5 * INV_PI);
    u = select(u, u + 1.0, u < 0.0);
    let v = acos(clamp(l.y, -1.0, 1.0)) * INV_PI;
    return vec2f(u, v);
}

fn env_dir(uv: vec2f) -> vec3f {
    let st = sin(PI * uv.y);
    let l = vec3f(sin(2.0 * PI * uv.x) * st, cos(PI * uv.y), -cos(2.0 * PI * uv.x) * st);
    let c = params.env_rot.x;
    let s = params.env_rot.y;
    return vec3f(c * l.x + s * l.z, l.y, -s * l.x + c * l.z);
}

fn env_cell(uv: vec2f) -> vec2u {
    let w = params.env_size.x;
    let h = params.env_size.y;
    return vec2u(min(u32(uv.x * f32(w)), w - 1u), min(u32(uv.y * f32(h)), h - 1u));
}

// Nearest texel: the radiance is constant over each cell, exactly as the sampling density is.
fn env_radiance(d: vec3f) -> vec3f {
    let cell = env_cell(env_uv(d));
    return env_texel(cell.x, cell.y);
}

fn env_pdf_at(uv: vec2f) -> f32 {
    let cell = env_cell(uv);
    let sin_c = sin(PI * (f32(cell.y) + 0.5) / f32(params.env_size.y));
    let sin_t = sin(PI * uv.y);
    if sin_t <= 1e-7 {
        return 0.0;
    }
    // env_rot.z = W H / (sum over cells of luminance x sin(theta_centre) x 2 pi^2).
    return luminance(env_texel(cell.x, cell.y)) * sin_c * params.env_rot.z / sin_t;
}

fn env_pdf(d: vec3f) -> f32 {
    return env_pdf_at(env_uv(d));
}

// Index i with cdf[i] <= u < cdf[i+1] in the n+1 values at env_data[base..].
fn env_search(base: u32, n: u32, u: f32) -> u32 {
    var lo = 0u;
    var hi = n - 1u;
    while lo < hi {
        let mid = (lo + hi + 1u) / 2u;
        if env_data[base + mid] <= u {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    return lo;
}

fn sample_env(u: vec2f) -> LightSample {
    let w = params.env_size.x;
    let h = params.env_size.y;
    let mbase = params.env_size.z;
    let row = env_search(mbase, h, u.y);
    let r0 = env_data[mbase + row];
    let r1 = env_data[mbase + row + 1u];
    let fv = select(0.5, (u.y - r0) / (r1 - r0), r1 > r0);
    let cbase = params.env_size.w + row * (w + 1u);
    let col = env_search(cbase, w, u.x);
    let c0 = env_data[cbase + col];
    let c1 = env_data[cbase + col + 1u];
    let fu = select(0.5, (u.x - c0) / (c1 - c0), c1 > c0);
    let uv = vec2f((f32(col) + clamp(fu, 0.0, 0.999)) / f32(w), (f32(row) + clamp(fv, 0.0, 0.999)) / f32(h));
    let pdf = env_pdf_at(uv);
    if pdf <= 0.0 {
        return no_light();
    }
    return LightSample(env_dir(uv), INF, env_texel(col, row) / pdf, pdf);
}
