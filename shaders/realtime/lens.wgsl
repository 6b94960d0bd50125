// Primary rays of the real-time frame: through sample j's position in the pixel and, where the
// camera has a thin lens (params.lens: aperture radius, focus distance), through a point of the
// aperture, as the reference tracer samples it (Mitsuba's thinlens); with motion blur
// (params.shutter.x > 0) at a uniformly random time in the shutter, the camera blended between
// its open and close frames (params.cam_open_*, frame.cam_*) and the ray's time set for the
// geometry (common/motion_*.wgsl). The traced primaries (realtime/primaries.wgsl) and the trace
// regenerate the same ray from (pixel, frame, j), so the trace re-derives sample 0's hit exactly
// from the triangle the primaries stored.

struct PrimaryRay {
    ro: vec3f,
    rd: vec3f,
    // In [0, 1]: 0 the shutter's open, 1 its close (and every ray without motion blur).
    time: f32,
}

// Sample j's position in its pixel: this frame's jitter for j = 0 (the raster's, which TAA and
// the motion vectors follow), then the R2 sequence (Roberts 2018) rotated by it.
fn primary_offset(j: u32) -> vec2f {
    return fract(frame.jitter + f32(j) * vec2f(0.7548776662, 0.5698402910));
}

fn primary_ray(px: vec2u, j: u32) -> PrimaryRay {
    let x = vec2f(px) + primary_offset(j);
    let ndc = vec2f(x.x / f32(frame.size.x) * 2.0 - 1.0, 1.0 - x.y / f32(frame.size.y) * 2.0);
    var rng = rng_init(px.y * frame.size.x + px.x, frame.index * 256u + j, params.seed ^ 0x6c656e73u);
    var time = 1.0;
    var pos = frame.cam_pos.xyz;
    var right = frame.cam_right.xyz;
    var up = frame.cam_up.xyz;
    var fwd = frame.cam_fwd.xyz;
    if params.shutter.x > 0.0 {
        time = rand(&rng);
        pos = mix(params.cam_open_pos.xyz, pos, time);
        right = mix(params.cam_open_right.xyz, right, time);
        up = mix(params.cam_open_up.xyz, up, time);
        fwd = mix(params.cam_open_fwd.xyz, fwd, time);
    }
    set_ray_time(time);
    // d has unit length along the view axis: the focus plane is at pos + d * focus.
    let d = fwd + ndc.x * right + ndc.y * up;
    if params.lens.x <= 0.0 {
        return PrimaryRay(pos, normalize(d), time);
    }
    let u = rand2(&rng);
    let r = params.lens.x * sqrt(u.x);
    let a = 6.283185307 * u.y;
    let ro = pos + r * (cos(a) * normalize(right) + sin(a) * normalize(up));
    return PrimaryRay(ro, normalize(pos + d * params.lens.y - ro), time);
}
