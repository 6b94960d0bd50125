// Per-dispatch parameters of the reference tracer (engine/src/passes/reference.rs: TraceParams).
struct Params {
    width: u32,
    height: u32,
    sample_index: u32,
    seed: u32,
    max_depth: i32,
    rr_depth: i32,
    num_lights: u32,
    num_emitters: u32,
    // xyz: camera position (scene-relative); w: the scene's ray-offset epsilon.
    cam_pos: vec4f,
    // Camera axes scaled so that a pixel's direction is fwd + x right + y up for x, y in [-1, 1].
    cam_right: vec4f,
    cam_up: vec4f,
    cam_fwd: vec4f,
    // rgb: constant environment radiance.
    env_radiance: vec4f,
    // cos a, sin a, pdf normaliser, unused.
    env_rot: vec4f,
    // width, height, marginal CDF offset, conditional CDF offset.
    env_size: vec4u,
    // Thin lens: x aperture radius (0: a pinhole), y focus distance.
    lens: vec4f,
    // x: samples per pixel this dispatch traces (the reference tracer), from sample_index on.
    batch: vec4u,
    // The camera at the shutter's open (cam_* are at its close; the same without motion blur).
    cam_open_pos: vec4f,
    cam_open_right: vec4f,
    cam_open_up: vec4f,
    cam_open_fwd: vec4f,
    // x: 1 where each path sees the scene at a random time in the shutter, 0: all at the close.
    shutter: vec4f,
    // x: 1 where ray cones choose texture mip levels after the primary hit, 0: the finest.
    // y: 1 where the real-time trace draws its leading dimensions from the screen's strata
    // (common/rng.wgsl), 0: from the pixel's random sequence.
    switches: vec4f,
}

var<uniform> params: Params;
