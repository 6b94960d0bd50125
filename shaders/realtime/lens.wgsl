// Primary rays of the real-time frame: sample j of a pixel, through its position in the pixel
// and, with a thin lens or an open shutter, its own aperture point and time
// (common/camera.wgsl). The traced primaries (realtime/primaries.wgsl) and the trace regenerate
// the same ray from (pixel, frame, j), so the trace re-derives sample 0's hit exactly from the
// triangle the primaries stored.

// Sample j's position in its pixel: this frame's jitter for j = 0 (the raster's, which TAA and
// the motion vectors follow), then the R2 sequence (Roberts 2018) rotated by it.
fn primary_offset(j: u32) -> vec2f {
    return fract(frame.jitter + f32(j) * vec2f(0.7548776662, 0.5698402910));
}

fn primary_ray(px: vec2u, j: u32) -> CameraRay {
    let x = vec2f(px) + primary_offset(j);
    let ndc = vec2f(x.x / f32(frame.size.x) * 2.0 - 1.0, 1.0 - x.y / f32(frame.size.y) * 2.0);
    var rng = 0u;
    if params.shutter.x > 0.0 || params.lens.x > 0.0 {
        rng = rng_init(px.y * frame.size.x + px.x, frame.index * 256u + j, params.seed ^ 0x6c656e73u);
    }
    return camera_sample(ndc, &rng);
}

// The raster's hit of pixel px's camera ray rd: its triangle (G-buffer ids: object, slot), with
// exact barycentrics of this frame's ray (no bounds test: at a silhouette the sample may sit a
// hair outside it).
fn raster_hit(ro: vec3f, rd: vec3f, ids: vec2u) -> Hit {
    let slot = ids.y;
    let inst = instance_of_object(ids.x);
    let v0 = inst_point(inst, tri_vertex(slot * 3u));
    let e1 = inst_point(inst, tri_vertex(slot * 3u + 1u)) - v0;
    let e2 = inst_point(inst, tri_vertex(slot * 3u + 2u)) - v0;
    let pv = cross(rd, e2);
    let inv = 1.0 / dot(e1, pv);
    let tv = ro - v0;
    let qv = cross(tv, e1);
    return Hit(dot(e2, qv) * inv, slot, vec2f(dot(tv, pv) * inv, dot(rd, qv) * inv), inst);
}
