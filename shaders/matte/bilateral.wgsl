// Stage (7): the final sparse bilateral, with the per-pixel radius of stage (5); it fills
// disocclusions and removes low-frequency noise. The radius is at least min_radius_px (a
// departure from the paper, whose r = (1 - c) R all but vanishes at full confidence): outside
// the history loop the blur does not compound, and the normal and plane weights keep it on
// the surface, so it trades little bias for the residual noise of a history tens of frames
// long (MatteSettings::min_radius_fraction). Taps are also weighed by their luminance
// difference against edge_stop_sigmas standard deviations of the noise (SVGF's luminance
// weighting function, Dundr §4.4.3 after Schied et al. 2017), measured on a guide rather than
// on the taps themselves: the luminance of each pixel's 3x3 mean on its surface, which stage
// (6)'s pass writes into its alpha (matte/firefly.wgsl). The guide's noise is a third of the
// n-frame mean's, so a contact shadow two pixels wide stands out of it where single taps'
// noise hid it, while taps that differ by noise alone keep their weight. The n-frame mean's
// noise comes from this frame's input minus the history's mean, so a shadow's own contrast
// does not count as noise (matte/sparse_bilateral.wgsl: history_noise).
var filter_in: texture_2d<f32>;
var radius_in: texture_2d<f32>;
var reason_in: texture_2d<u32>;
var out_matte: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    let p = vec2i(gid.xy);
    if !in_bounds(p) {
        return;
    }
    var v = textureLoad(filter_in, p, 0).rgb;
    if stage_on(STAGE_BILATERAL) {
        v = sparse_bilateral(p, max(textureLoad(radius_in, p, 0).r, mp.min_radius_px), mp.edge_stop_sigmas);
    }
    textureStore(out_matte, p, vec4f(half_safe(v), 1.0));
}
