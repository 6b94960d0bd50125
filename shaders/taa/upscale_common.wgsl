// The temporal upscaler (engine/src/passes/upscale.rs): where the frame is traced below the size
// it is shown at, each shown pixel accumulates the composite's jittered samples that land near
// it, in place of TAA. The raster samples render pixel i at i + frame.jitter (Halton(2, 3)), so
// over frames the samples of a render pixel sweep the shown pixels it covers.
//
// The light is accumulated demodulated: each sample divided by its render pixel's material
// (`demodulation`), the mean multiplied by the materials of a raster at the shown size averaged
// over its own jitter, so that textures keep the shown size's detail whatever the scale (the
// raster is the cheap part of the frame).
//
// Each shown pixel o keeps a weighted mean of the samples it received (rgb) and their weight
// (a). A sample at distance d (in shown pixels) from o's centre weighs exp(-d^2 / 2 sigma^2):
// with sigma about half a shown pixel the mean converges to the image at the shown resolution,
// not the render resolution's (a bilinear stretch keeps the render pixel's box forever). The
// history is reprojected through the motion of the render pixel nearest the camera among the
// nine around o (motion dilated from the nearest depth, so an edge moves with its foreground),
// tested against the previous depth buffer as TAA tests its own (taa/history_test.wgsl) and,
// while anything moves, clamped to the YCoCg box of the nine samples around o (Karis 2014) and
// capped at `moving_weight`: about `TaaSettings::upscale_moving_frames` frames of samples. In a
// still view the weight grows without bound, and the mean is the plain kernel-weighted mean of
// every sample since the view settled.
//
// Beside it, in a still view, the upscaler keeps the same kernel-weighted mean of the raw
// samples (the trace's light remodulated, as the still-view mean after TAA keeps it at the
// render size: passes/converge.rs), and the image shown moves towards that mean where the
// denoised one is off by more than the mean's noise (taa/upscale_shown.wgsl).
//
// What is shown also takes a small weight (`fill_weight`, a quarter of a frame's samples) of
// the nine samples filtered with a Gaussian of half a render pixel: where the history has no
// weight (a first frame, a surface just uncovered) that spatial estimate is the image, and it
// fades as samples arrive.
//
// taa/upscale_samples.wgsl first writes each render pixel's demodulated light and raw sample
// once (a shown pixel reads nine of them: sixteen shown pixels a render pixel at scale 0.25).

struct UpscaleParams {
    // The size shown (the history's and the output's); frame.size is the render size.
    out_size: vec2u,
    // The accumulation kernel's standard deviation, in shown pixels.
    sigma: f32,
    // The most weight a history keeps while anything moves.
    moving_weight: f32,
    // Weight of the spatial estimate in the image shown.
    fill_weight: f32,
    // 1 when the history continues last frame's (same shown size, upscaled last frame).
    continues: u32,
    // 1 when the raw samples' mean continues (the still-view mean's condition, passes/converge.rs).
    raw_continues: u32,
    // TaaSettings::converge_sigmas and converge_min_samples (0 sigmas: no raw mean).
    bias_sigmas: f32,
    min_samples: f32,
    // TaaSettings::upscale_moving_frames: the materials' mean's length while anything moves.
    moving_frames: f32,
    // 1: the materials come from the shown size's raster (TaaSettings::upscale_materials).
    materials: u32,
    pad0: u32,
}

var<uniform> up: UpscaleParams;

// What the light is divided by at the render size and multiplied by at the shown size, so that
// the materials' detail comes from the shown size's raster: the diffuse albedo plus the
// specular reflectance at normal incidence (1 off any surface). Emission is taken out before
// and put back after, from the shown size's raster, so that a lamp's edge is the shown size's.
fn demodulation(hit: bool, base: vec4f, f0: vec3f) -> vec3f {
    if !hit {
        return vec3f(1.0);
    }
    return max(base.rgb * (1.0 - base.a) + f0, vec3f(0.02));
}
