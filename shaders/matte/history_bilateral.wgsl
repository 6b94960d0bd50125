// Stage (4): the sparse bilateral applied only to what goes back into the history (Mara et al.
// §3.4: newly sampled paths are never blurred here; the blur is amortised over frames).
var filter_in: texture_2d<f32>;
// Reason flags and, above them, the history length n (matte/temporal.wgsl).
var reason_in: texture_2d<u32>;
var out_history: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    var v = textureLoad(filter_in, p, 0).rgb;
    let n = f32(textureLoad(reason_in, p, 0).x >> 8u);
    if stage_on(STAGE_HISTORY_BILATERAL) {
        // The disk shrinks past history_full_frames (settings: MatteSettings).
        v = sparse_bilateral(p, mp.history_radius_px * history_falloff(mp.history_full_frames, n), 0.0);
    }
    textureStore(out_history, p, vec4f(half_safe(v), n));
}
