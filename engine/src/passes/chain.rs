//! One compute pass of a denoise chain (matte.rs, glossy.rs): its pipeline and layout, and its
//! bind groups for history parity 0 and 1, remade when the key of what they bind changes.

use crate::gpu::scene::compute_pipeline_at;
use crate::gpu::{Bindings, Gpu, GpuTimer};
use crate::shader::Reloadable;
use anyhow::Result;

pub struct ChainStage {
    pub label: &'static str,
    pub pipeline: Reloadable<wgpu::ComputePipeline>,
    layout: wgpu::BindGroupLayout,
    groups: Option<(u64, [wgpu::BindGroup; 2])>,
}

impl ChainStage {
    /// `layout`: the stage's bindings for either parity (only their types matter here).
    pub fn new(gpu: &Gpu, label: &'static str, modules: &[&'static str], entry: &str, layout: Bindings) -> Result<ChainStage> {
        let layout = layout.create_layout(&gpu.device, label);
        let (l, entry) = (layout.clone(), entry.to_string());
        let pipeline = Reloadable::new(gpu, label, "", modules, move |d, m| compute_pipeline_at(d, label, m, &l, &entry))?;
        Ok(ChainStage { label, pipeline, layout, groups: None })
    }

    /// Dispatch one thread per pixel in 8x8 groups; `bindings(p)` gives what parity p binds.
    #[allow(clippy::too_many_arguments)]
    pub fn record<'a>(&mut self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, key: u64, parity: usize, size: (u32, u32), timer: Option<&mut GpuTimer>, bindings: impl Fn(usize) -> Bindings<'a>) {
        if self.groups.as_ref().is_none_or(|(k, _)| *k != key) {
            let g = |p| bindings(p).create_group(&gpu.device, self.label, &self.layout);
            self.groups = Some((key, [g(0), g(1)]));
        }
        let _scope = crate::profile::scope(self.label);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(self.label), timestamp_writes: timer.and_then(|t| t.compute(self.label)) });
        pass.set_pipeline(self.pipeline.get());
        pass.set_bind_group(0, &self.groups.as_ref().unwrap().1[parity], &[]);
        pass.dispatch_workgroups(size.0.div_ceil(8), size.1.div_ceil(8), 1);
    }
}
