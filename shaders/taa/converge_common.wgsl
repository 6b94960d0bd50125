// Shared by the still-view mean's two passes (engine/src/passes/converge.rs mirrors
// ConvergeParams): the plain mean of each pixel's own samples since the view settled, and the
// image shown moved towards it where TAA's image is off by more than the mean's noise.

struct ConvergeParams {
    // 1 when the mean continues last frame's: the camera, the scene, the settings and the size
    // are the ones it was taken with.
    continues: u32,
    // The squared difference between TAA's image and the mean counts as bias past this many
    // times the mean's variance (0: the stage passes TAA's image on).
    bias_sigmas: f32,
    // Below this many samples the mean's variance is too uncertain to weigh it by.
    min_samples: f32,
    _pad: f32,
}

var<uniform> cv: ConvergeParams;
