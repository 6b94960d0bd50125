// Reference path tracer: one path per pixel per dispatch, added to a running sum
// (common/path.wgsl has the path loop).

// Per pixel two vec4: (sum of rgb, 0) and (sum of rgb^2, count of discarded non-finite samples).
var<storage, read_write> accum: array<vec4f>;

// Camera ray of one sample: a uniform position in the pixel's square (Mitsuba's box filter),
// through the thin lens and at a time in the shutter where the camera has them
// (common/camera.wgsl).
fn camera_start(px: vec2u, rng: ptr<function, u32>) -> PathStart {
    let j = rand2(rng);
    let ndc = vec2f(
        (f32(px.x) + j.x) / f32(params.width) * 2.0 - 1.0,
        1.0 - (f32(px.y) + j.y) / f32(params.height) * 2.0,
    );
    let ray = camera_sample(ndc, rng);
    return camera_path(ray.ro, ray.rd);
}

// params.batch.x samples of the pixel, each with its own random sequence (sample_index + k), as
// one loop of path segments: a path that ends makes way for the pixel's next sample.
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if gid.x >= params.width || gid.y >= params.height {
        return;
    }
    let pixel = gid.y * params.width + gid.x;
    var k = 0u;
    var rng = rng_init(pixel, params.sample_index, params.seed);
    var st = path_begin(camera_start(gid.xy, &rng));
    var sum = vec3f(0.0);
    var sum2 = vec3f(0.0);
    var bad = 0.0;
    loop {
        if st.done {
            var l = path_result(st).radiance;
            // NaN and Inf never reach the image: the sample is dropped and counted.
            if !is_finite3(l) {
                l = vec3f(0.0);
                bad += 1.0;
            }
            sum += l;
            sum2 += l * l;
            k += 1u;
            if k >= params.batch.x {
                break;
            }
            rng = rng_init(pixel, params.sample_index + k, params.seed);
            st = path_begin(camera_start(gid.xy, &rng));
        }
        path_step(&st, &rng);
    }
    let a = accum[pixel * 2u];
    let b = accum[pixel * 2u + 1u];
    accum[pixel * 2u] = vec4f(a.rgb + sum, 0.0);
    accum[pixel * 2u + 1u] = vec4f(b.rgb + sum2, b.w + bad);
}
