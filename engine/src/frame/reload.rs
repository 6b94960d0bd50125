//! Hot reload of the frame's pipelines: a changed module rebuilds exactly the pipelines whose
//! programs contain it (each pipeline records its modules); the others are not touched.

use super::Renderer;
use crate::gpu::Gpu;
use crate::shader::{Reload, ReloadOutcome};

impl Renderer {
    /// Every pipeline of the frame that exists now (denoisers, TAA and the display are made on
    /// first use).
    pub fn pipelines(&mut self) -> Vec<&mut dyn Reload> {
        let mut v: Vec<&mut dyn Reload> =
            vec![&mut self.stages.gbuffer.pipeline, &mut self.stages.composite.pipeline];
        if let Some(d) = self.stages.display.as_mut() {
            v.push(&mut d.pipeline);
        }
        v.extend(self.stages.taa.pipelines());
        v.extend(self.stages.converge.pipelines());
        v.extend(self.stages.supersample.pipelines());
        v.extend(self.stages.primaries.pipelines());
        v.extend(self.stages.trace.pipelines());
        v.extend(self.stages.prefilter.pipelines());
        v.extend(self.stages.cache.pipelines());
        v.extend(self.stages.rescale.pipelines());
        for d in &mut self.denoisers {
            v.extend(d.denoiser.pipelines());
        }
        v
    }

    /// Rebuild the pipelines that use any of `changed` (module paths under `shaders/`, already
    /// refreshed in `gpu.shaders`). A pipeline that fails keeps its last good version.
    pub fn reload_shaders(&mut self, gpu: &Gpu, changed: &[&str]) -> Vec<ReloadOutcome> {
        let mut out = vec![];
        for p in self.pipelines() {
            if p.modules().iter().any(|m| changed.contains(m)) {
                out.push(p.reload(gpu));
            }
        }
        // The still-view mean holds samples of the shaders before.
        if !out.is_empty() {
            self.history.converge_state = None;
        }
        out
    }

    /// (pipeline, error) for every pipeline whose last reload failed.
    pub fn shader_errors(&mut self) -> Vec<(String, String)> {
        self.pipelines()
            .into_iter()
            .filter_map(|p| p.error().map(|e| (p.label().to_string(), e.to_string())))
            .collect()
    }
}
