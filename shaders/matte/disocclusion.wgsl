// Stage (5): r = (1 - min over a 2R x 2R box of c) x R by two 1D min passes (horizontal, then
// vertical), times `low_confidence_multiplier` where the pixel's own c < 1/2 (capped at
// max_radius_px). Entry points: min_h reads c as the temporal stage wrote it alone (in the
// radius texture, 1 off the surface), min_v writes r.

var filter_in: texture_2d<f32>;
var min_in: texture_2d<f32>;
var out_min: texture_storage_2d<r32float, write>;

fn box_radius() -> i32 {
    return max(i32(mp.disocclusion_radius_px), 1);
}

@compute @workgroup_size(8, 8)
fn min_h(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    var m = 1.0;
    let r = box_radius();
    for (var d = -r; d < r; d++) {
        let q = vec2i(clamp(p.x + d, 0, i32(frame.size.x) - 1), p.y);
        m = min(m, textureLoad(min_in, q, 0).r);
    }
    textureStore(out_min, p, vec4f(m, 0.0, 0.0, 0.0));
}

@compute @workgroup_size(8, 8)
fn min_v(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    var m = 1.0;
    let r = box_radius();
    for (var d = -r; d < r; d++) {
        m = min(m, textureLoad(min_in, vec2i(p.x, clamp(p.y + d, 0, i32(frame.size.y) - 1)), 0).r);
    }
    var radius = (1.0 - m) * mp.disocclusion_radius_px;
    if textureLoad(filter_in, p, 0).a < 0.5 {
        radius *= mp.low_confidence_multiplier;
    }
    if !stage_on(STAGE_DISOCCLUSION) {
        radius = 0.0;
    }
    textureStore(out_min, p, vec4f(min(radius, mp.max_radius_px), 0.0, 0.0, 0.0));
}
