//! `prefilter`: Moon et al. 2017's G-buffer pre-filter over the traced primaries
//! (passes/primaries.rs), the frame's pre-filter stage. Three passes (shaders/prefilter/):
//! `prefilter/covariance` smooths and inverts each pixel's world-position covariance,
//! `prefilter/sure` chooses each pixel's bandwidth by SURE (eq. 6), `prefilter/features` smooths
//! the bandwidths and filters the features with the world-position weights (eq. 1, 3, 4) into a
//! buffer of the primaries' layout, which `gbuffer/resolve` writes as the G-buffer.
//!
//! Per pixel: 64 bytes of statistics, 4 of bandwidths, 80 of filtered features and 16 of debug
//! views (164 bytes).

use super::chain::ChainStage;
use super::primaries::{FEATURE_WORDS, PrimaryTargets};
use crate::gpu::{Bindings, GpuMemory, Recorder, Tex};
use crate::shader::Reload;
use anyhow::Result;

pub const COVARIANCE: &str = "prefilter/covariance";
pub const SURE: &str = "prefilter/sure";
pub const FEATURES: &str = "prefilter/features";

pub struct PrefilterTargets {
    pub epoch: u64,
    /// The covariance step's statistics for the later steps (prefilter/stats.wgsl): the inverse
    /// covariance (two textures), the mean position and the even samples' mean position.
    pub stats: [Tex; 4],
    pub bandwidth: wgpu::Buffer,
    /// The filtered features, in the primaries' layout.
    pub features: wgpu::Buffer,
    /// Bandwidth before and after smoothing, the positions' spread in pixels, the normal's
    /// variance (the `prefilter/...` debug views).
    pub view: Tex,
    /// The raw octahedral normal and the filtered view depth's relative variance.
    pub normals: Tex,
}

impl PrefilterTargets {
    pub const PREFIX: &str = "prefilter/";

    pub fn new(
        d: &wgpu::Device,
        mem: &mut GpuMemory,
        size: (u32, u32),
        epoch: u64,
    ) -> PrefilterTargets {
        let pixels = size.0 as u64 * size.1 as u64;
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let tex = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        PrefilterTargets {
            epoch,
            stats: [
                "prefilter/inverse covariance a",
                "prefilter/inverse covariance b",
                "prefilter/position",
                "prefilter/even position",
            ]
            .map(|l| mem.texture(d, l, size, wgpu::TextureFormat::Rgba32Float, tex)),
            bandwidth: mem.buffer(d, "prefilter/bandwidth", pixels * 4, usage),
            features: mem.buffer(d, "prefilter/features", pixels * FEATURE_WORDS * 16, usage),
            view: mem.texture(d, "prefilter/view", size, wgpu::TextureFormat::Rgba16Float, tex),
            normals: mem.texture(
                d,
                "prefilter/normals",
                size,
                wgpu::TextureFormat::Rgba16Float,
                tex,
            ),
        }
    }
}

/// What the pre-filter binds: the frame uniform, the primaries' buffers and its own.
pub fn bindings<'a>(
    frame: &'a wgpu::Buffer,
    p: &'a PrimaryTargets,
    t: &'a PrefilterTargets,
) -> Bindings<'a> {
    Bindings::new()
        .buffer("frame", frame)
        .buffer("pr_features", &p.features)
        .buffer("pr_moments", &p.moments)
        .texture("pf_inv_a", &t.stats[0].1)
        .texture("pf_inv_b", &t.stats[1].1)
        .texture("pf_position", &t.stats[2].1)
        .texture("pf_half", &t.stats[3].1)
        .buffer("pf_bandwidth", &t.bandwidth)
        .buffer("pf_features", &t.features)
        .texture("pf_view", &t.view.1)
        .texture("pf_normals", &t.normals.1)
}

/// The modules of a pre-filter step (`prefilter/covariance.wgsl`, `sure.wgsl`, `features.wgsl`).
pub fn modules(step: &'static str) -> Vec<&'static str> {
    let mut m = vec!["common/math.wgsl", "realtime/frame.wgsl", "prefilter/common.wgsl"];
    if step != "prefilter/covariance.wgsl" {
        m.push("prefilter/stats.wgsl");
    }
    m.push(step);
    m
}

#[derive(Default)]
pub struct Prefilter {
    stages: Option<[ChainStage<()>; 3]>,
}

impl Prefilter {
    pub fn pipelines(&mut self) -> Vec<&mut dyn Reload> {
        self.stages
            .iter_mut()
            .flat_map(|s| s.iter_mut().map(|s| &mut s.pipeline as &mut dyn Reload))
            .collect()
    }

    /// Record the three passes over `size` pixels; `key` changes whenever a bound buffer may
    /// have been replaced.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        key: crate::gpu::BindKey,
        size: (u32, u32),
        offered: &Bindings,
    ) -> Result<()> {
        let gpu = rec.gpu;
        let stages = super::chain::made(&mut self.stages, || {
            let stage = |label, file| ChainStage::new(gpu, label, &modules(file), "main", offered);
            Ok([
                stage(COVARIANCE, "prefilter/covariance.wgsl")?,
                stage(SURE, "prefilter/sure.wgsl")?,
                stage(FEATURES, "prefilter/features.wgsl")?,
            ])
        })?;
        for s in stages {
            s.record(rec, key, (), size, |_| offered.clone())?;
        }
        Ok(())
    }
}
