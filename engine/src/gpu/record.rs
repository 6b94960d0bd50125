//! What a stage records with: the device, the frame's command encoder and its pass timer, so
//! that a pass takes its own inputs and this one context.

use super::{Gpu, GpuTimer};

pub struct Recorder<'a> {
    pub gpu: &'a Gpu,
    pub enc: &'a mut wgpu::CommandEncoder,
    /// Timestamps of each pass (None: the adapter has no timestamp queries, or not timed).
    pub timer: Option<&'a mut GpuTimer>,
}

impl<'a> Recorder<'a> {
    pub fn new(
        gpu: &'a Gpu,
        enc: &'a mut wgpu::CommandEncoder,
        timer: Option<&'a mut GpuTimer>,
    ) -> Recorder<'a> {
        Recorder { gpu, enc, timer }
    }

    /// A compute pass labelled `label` (its wgpu label and its timestamps' name).
    pub fn compute_pass(&mut self, label: &'static str) -> wgpu::ComputePass<'_> {
        let timestamp_writes = self.timer.as_deref_mut().and_then(|t| t.compute(label));
        self.enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes,
        })
    }

    /// The encoder and the timestamp writes of a render pass labelled `label`.
    pub fn render_parts(
        &mut self,
        label: &'static str,
    ) -> (&mut wgpu::CommandEncoder, Option<wgpu::RenderPassTimestampWrites<'_>>) {
        (&mut *self.enc, self.timer.as_deref_mut().and_then(|t| t.render(label)))
    }
}
