//! One compute pass of a denoise chain (matte.rs, glossy.rs): its pipeline, and its bind groups
//! by variant (history parity, level, ...), remade when the key of what they bind or the
//! pipeline changes.

use crate::gpu::{BindCache, BindKey, Bindings, Gpu, Parity, Recorder, set_compute_groups};
use crate::shader::compute_pipeline;
use crate::shader::{Reload, Reloadable};
use anyhow::Result;

/// The stages in `slot`, made by `make` the first time they are needed (a stage is checked
/// against the names the frame offers, so a pass or a denoiser makes its stages on its first
/// frame).
pub fn made<T>(slot: &mut Option<T>, make: impl FnOnce() -> Result<T>) -> Result<&mut T> {
    match slot {
        Some(t) => Ok(t),
        None => Ok(slot.insert(make()?)),
    }
}

/// As [`made`], where what the stages were made for can change between frames (an input the
/// frame offers, or a setting that is a constant of their programs): the stages in `slot` are
/// kept while `fits` says they suit this frame, and made again otherwise.
pub fn made_for<T>(
    slot: &mut Option<T>,
    fits: impl FnOnce(&T) -> bool,
    make: impl FnOnce() -> Result<T>,
) -> Result<&mut T> {
    if slot.as_ref().is_some_and(|t| !fits(t)) {
        *slot = None;
    }
    made(slot, make)
}

/// Per-pixel targets in `slot` made for the frame targets of `epoch` (once per size): `make`
/// runs where the slot holds none or another epoch's. True if it did.
pub fn made_for_epoch<T>(
    slot: &mut Option<(u64, T)>,
    epoch: u64,
    make: impl FnOnce() -> T,
) -> bool {
    if slot.as_ref().is_some_and(|(e, _)| *e == epoch) {
        return false;
    }
    *slot = Some((epoch, make()));
    true
}

/// One compute pass of a chain: its pipeline and its bind groups by variant `V` (by default
/// the history parity; a stage with levels or several inputs names its own variant type).
pub struct ChainStage<V = Parity> {
    pub label: &'static str,
    pub pipeline: Reloadable<wgpu::ComputePipeline>,
    groups: BindCache<V>,
}

impl<V: std::hash::Hash + Eq + Copy> ChainStage<V> {
    /// `offered`: what the stage binds in any variant (only the names matter here).
    pub fn new(
        gpu: &Gpu,
        label: &'static str,
        modules: &[&'static str],
        entry: &str,
        offered: &Bindings,
    ) -> Result<ChainStage<V>> {
        ChainStage::with_prelude(gpu, label, "", modules, entry, offered)
    }

    /// As [`ChainStage::new`], with `prelude` (constants of the program) before the modules.
    pub fn with_prelude(
        gpu: &Gpu,
        label: &'static str,
        prelude: &str,
        modules: &[&'static str],
        entry: &str,
        offered: &Bindings,
    ) -> Result<ChainStage<V>> {
        let entry = entry.to_string();
        let pipeline = Reloadable::new(
            gpu,
            label,
            prelude,
            modules,
            wgpu::ShaderStages::COMPUTE,
            offered,
            move |d, m, l| compute_pipeline(d, label, m, l, &entry),
        )?;
        Ok(ChainStage { label, pipeline, groups: BindCache::default() })
    }

    /// Drop its bind groups: the textures they bind were released.
    pub fn release_groups(&mut self) {
        self.groups.clear();
    }

    /// Dispatch one thread per pixel in 8x8 groups, bound as `variant`; `bindings(v)` gives
    /// what variant v binds (asked once per variant while `key` and the pipeline stay).
    pub fn record<'a>(
        &mut self,
        rec: &mut Recorder,
        key: BindKey,
        variant: V,
        size: (u32, u32),
        bindings: impl Fn(V) -> Bindings<'a>,
    ) -> Result<()> {
        let p = &self.pipeline;
        let groups = self
            .groups
            .get(key, p.builds(), variant, |v| p.bind_groups(&rec.gpu.device, &bindings(v)))?;
        let _scope = crate::profile::scope(self.label);
        let mut pass = rec.compute_pass(self.label);
        pass.set_pipeline(p.get());
        set_compute_groups(&mut pass, groups);
        pass.dispatch_workgroups(size.0.div_ceil(8), size.1.div_ceil(8), 1);
        Ok(())
    }
}
