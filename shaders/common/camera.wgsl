// A camera sample, as both modes start their paths: the ray through image point ndc (x, y in
// [-1, 1], y up), at a uniformly random time in the shutter where it is open (params.shutter.x
// > 0: the camera blended linearly between its open frame, params.cam_open_*, and its close,
// params.cam_*, and the ray's time set for the geometry, common/motion_*.wgsl), from a uniform
// point of the aperture where the camera has a thin lens (params.lens: radius, focus distance;
// Mitsuba's thinlens, aimed where the pinhole ray meets the focus plane). Random numbers are
// drawn only for what the camera has, so a pinhole's sequences are untouched.

struct CameraRay {
    ro: vec3f,
    rd: vec3f,
    // In [0, 1]: 0 the shutter's open, 1 its close (and every ray of an instant exposure).
    time: f32,
}

fn camera_sample(ndc: vec2f, rng: ptr<function, u32>) -> CameraRay {
    var pos = params.cam_pos.xyz;
    var right = params.cam_right.xyz;
    var up = params.cam_up.xyz;
    var fwd = params.cam_fwd.xyz;
    var time = 1.0;
    if params.shutter.x > 0.0 {
        time = rand(rng);
        pos = mix(params.cam_open_pos.xyz, pos, time);
        right = mix(params.cam_open_right.xyz, right, time);
        up = mix(params.cam_open_up.xyz, up, time);
        fwd = mix(params.cam_open_fwd.xyz, fwd, time);
    }
    set_ray_time(time);
    // d has unit length along the view axis: the focus plane is at pos + d * focus.
    let d = fwd + ndc.x * right + ndc.y * up;
    if params.lens.x <= 0.0 {
        return CameraRay(pos, normalize(d), time);
    }
    let u = rand2(rng);
    let r = params.lens.x * sqrt(u.x);
    let a = 6.283185307 * u.y;
    let ro = pos + r * (cos(a) * normalize(right) + sin(a) * normalize(up));
    return CameraRay(ro, normalize(pos + d * params.lens.y - ro), time);
}
