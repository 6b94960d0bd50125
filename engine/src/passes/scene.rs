//! The scene as every shading stage binds it (the trace, the traced primaries, the radiance
//! cache): its own module so that those stages depend on it and not on one another.

use crate::gpu::{Bindings, GpuScene};

/// The scene as the frame's shading stages bind it: its buffers, the trace uniform
/// (`TraceParams`) and the frame uniform (`FrameParams`).
#[derive(Clone, Copy)]
pub struct SceneInputs<'a> {
    pub scene: &'a GpuScene,
    pub params: &'a wgpu::Buffer,
    pub frame: &'a wgpu::Buffer,
    /// Objects move during the shutter: the motion-blur programs.
    pub moving: bool,
}

impl<'a> SceneInputs<'a> {
    pub fn bindings(&self) -> Bindings<'a> {
        self.scene.bindings().buffer("params", self.params).buffer("frame", self.frame)
    }
}
