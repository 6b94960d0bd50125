// Primary rays of the real-time frame: through sample j's position in the pixel and, where the
// camera has a thin lens (params.lens: aperture radius, focus distance), through a point of the
// aperture, as the reference tracer samples it (Mitsuba's thinlens). The traced primaries
// (realtime/primaries.wgsl) and the trace regenerate the same ray from (pixel, frame, j), so the
// trace re-derives sample 0's hit exactly from the triangle the primaries stored.

struct PrimaryRay {
    ro: vec3f,
    rd: vec3f,
}

// Sample j's position in its pixel: this frame's jitter for j = 0 (the raster's, which TAA and
// the motion vectors follow), then the R2 sequence (Roberts 2018) rotated by it.
fn primary_offset(j: u32) -> vec2f {
    return fract(frame.jitter + f32(j) * vec2f(0.7548776662, 0.5698402910));
}

fn primary_ray(px: vec2u, j: u32) -> PrimaryRay {
    let x = vec2f(px) + primary_offset(j);
    let ndc = vec2f(x.x / f32(frame.size.x) * 2.0 - 1.0, 1.0 - x.y / f32(frame.size.y) * 2.0);
    // d has unit length along the view axis: the focus plane is at cam_pos + d * focus.
    let d = frame.cam_fwd.xyz + ndc.x * frame.cam_right.xyz + ndc.y * frame.cam_up.xyz;
    if params.lens.x <= 0.0 {
        return PrimaryRay(frame.cam_pos.xyz, normalize(d));
    }
    var rng = rng_init(px.y * frame.size.x + px.x, frame.index * 256u + j, params.seed ^ 0x6c656e73u);
    let u = rand2(&rng);
    let r = params.lens.x * sqrt(u.x);
    let a = 6.283185307 * u.y;
    let ro = frame.cam_pos.xyz + r * (cos(a) * normalize(frame.cam_right.xyz) + sin(a) * normalize(frame.cam_up.xyz));
    return PrimaryRay(ro, normalize(frame.cam_pos.xyz + d * params.lens.y - ro));
}
