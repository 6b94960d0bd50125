// The covariance step's per-pixel statistics (prefilter/common.wgsl: Stats), as the SURE and
// feature steps read them.
var pf_inv_a: texture_2d<f32>;
var pf_inv_b: texture_2d<f32>;
var pf_position: texture_2d<f32>;
var pf_half: texture_2d<f32>;

fn stats_at(p: vec2i) -> Stats {
    let a = textureLoad(pf_inv_a, p, 0);
    let b = textureLoad(pf_inv_b, p, 0);
    let q = textureLoad(pf_position, p, 0);
    let h = textureLoad(pf_half, p, 0);
    return Stats(a, b.xy, b.z, b.w, q.xyz, h.xyz, h.w);
}
