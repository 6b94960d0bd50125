// Composite: remodulate the light buffers with the material (Mara et al. eq. (9) and (10)):
//   L = emission + direct + matte x m (1 - F(w_s))^2 + glossy x F(w_s)
// with m = base colour x (1 - metallic) (the Lambertian rho of eq. (2); the pi of eq. (9) is
// already in the matte light). Writes linear HDR radiance; in accumulate mode also adds it to
// the running sum (converging to the reference image while the camera is still).

var<storage, read_write> hdr: array<vec4f>;
var<storage, read_write> accumulation: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let px = gid.xy;
    if px.x >= frame.size.x || px.y >= frame.size.y {
        return;
    }
    let p = vec2i(px);
    let g = gbuffer_at(p);
    var l = textureLoad(tr_direct, p, 0).rgb;
    // Emission is added where there is no surface too: traced primaries (a thin lens) store the
    // mean over their k samples, which may hit an emitter where sample 0 missed.
    l += g.emission;
    if g.hit {
        let rd = camera_ray(px);
        let f_s = fresnel_mirror(g, dot(g.n, -rd));
        l += textureLoad(tr_matte, p, 0).rgb * matte_factor(g, f_s);
        l += glossy_light(p) * f_s;
    }
    l = select(vec3f(0.0), l, (l == l) & (abs(l) <= vec3f(3.0e38)));
    let i = px.y * frame.size.x + px.x;
    hdr[i] = vec4f(l, 1.0);
    if frame.accumulated > 0u {
        let a = select(vec4f(0.0), accumulation[i], frame.accumulated > 1u);
        accumulation[i] = vec4f(a.rgb + l, 0.0);
    }
}
