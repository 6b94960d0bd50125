//! The denoiser of Mara et al. 2017 (§3.4, Figure 2): the matte chain (stages 3-7, [`matte`])
//! and, in scenes with a specular lobe, the glossy chain (stages 8-10 with Voorhuis's
//! reflection reprojection, [`glossy`]; SVGF's glossy signal reuses its reflection motion).
//! TAA follows both chains' temporal outputs ([`TaaFollow`]). Its settings are
//! `settings/mara.rs` (what the registry knows), `settings/matte.rs` and `settings/glossy.rs`;
//! its WGSL is `shaders/matte/` and `shaders/glossy/`.

pub mod glossy;
pub mod matte;

use super::{Denoised, Denoiser, DenoiserScene, FrameContext, FrameSettings, Outputs};
use crate::gpu::{Gpu, GpuMemory, Parity, Recorder};
use crate::passes::chain::made_for;
use crate::passes::io::FrameIo;
use crate::passes::taa::{GlossyFollow, MatteFollow, MatteState, TaaFollow};
use anyhow::{Context, Result};
use glossy::{GlossyChain, GlossyChainTargets, GlossyInputs, GlossyParams, MotionProgram};
use matte::{ChainInputs, MatteChain, MatteParams, MatteTargets};

pub fn make(gpu: &Gpu, scene: &DenoiserScene) -> Result<Box<dyn Denoiser>> {
    let mut memory = GpuMemory::default();
    let u = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
    let d = &gpu.device;
    let params = memory.buffer(d, "matte/params", size_of::<MatteParams>() as u64, u);
    let glossy_params = memory.buffer(d, "glossy/params", size_of::<GlossyParams>() as u64, u);
    Ok(Box::new(Mara {
        scene: *scene,
        params,
        glossy_params,
        targets: None,
        matte: None,
        glossy: None,
    }))
}

struct Mara {
    scene: DenoiserScene,
    params: wgpu::Buffer,
    glossy_params: wgpu::Buffer,
    targets: Option<(MatteTargets, Option<GlossyChainTargets>)>,
    matte: Option<MatteChain>,
    glossy: Option<GlossyChain>,
}

impl Denoiser for Mara {
    fn needs_previous_gbuffer(&self) -> bool {
        true
    }

    /// The glossy chain reprojects along the virtual position and demodulates behind mirrors.
    fn reads_reflections(&self) -> bool {
        true
    }

    /// Every texture outlives the frame (TAA follows the temporal outputs, the rest are a few
    /// bytes a pixel), so `kept` holds already.
    fn allocate(
        &mut self,
        gpu: &Gpu,
        memory: &mut GpuMemory,
        size: (u32, u32),
        _kept: &[String],
        _settings: &FrameSettings,
    ) -> Result<()> {
        let d = &gpu.device;
        let glossy = self.scene.glossy.then(|| GlossyChainTargets::new(d, memory, size));
        self.targets = Some((MatteTargets::new(d, memory, size), glossy));
        Ok(())
    }

    fn release(&mut self) {
        self.targets = None;
        self.matte.iter_mut().for_each(MatteChain::release_groups);
        self.glossy.iter_mut().for_each(GlossyChain::release_groups);
    }

    fn record<'s>(
        &'s mut self,
        rec: &mut Recorder,
        io: &FrameIo,
        cx: &FrameContext,
    ) -> Result<Outputs<'s>> {
        let gpu = rec.gpu;
        let (m, g) =
            self.targets.as_ref().context("the Mara denoiser records before its textures exist")?;
        let s = cx.settings;
        let mp = MatteParams::new(&s.matte, io.size.0, cx.index);
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&mp));
        let gp = GlossyParams::new(&s.glossy, self.scene.extent, cx.view.static_view);
        gpu.queue.write_buffer(&self.glossy_params, 0, bytemuck::bytes_of(&gp));
        let inputs = ChainInputs { io: *io, params: &self.params, matte: m };
        let motion = self.scene.motion;
        // Made again when the radiance cache starts or stops offering its prior, or the
        // pre-filter its statistics.
        let (prior, uncertain) = (io.cache_prior.is_some(), io.feature_uncertainty.is_some());
        let matte = made_for(
            &mut self.matte,
            |c| c.prior == prior && c.uncertain == uncertain,
            || MatteChain::new(gpu, &inputs, motion).context("creating the matte chain"),
        )?;
        matte.record(rec, cx.key, &inputs, cx.parity)?;
        if let Some(g) = g {
            let inputs = GlossyInputs {
                io: *io,
                matte: &self.params,
                params: &self.glossy_params,
                glossy: g,
            };
            // Made again when the pre-filter starts or stops offering its statistics, or the
            // motion search's program constants change.
            let (uncertain, program) =
                (io.feature_uncertainty.is_some(), MotionProgram::of(&s.glossy));
            let glossy = made_for(
                &mut self.glossy,
                |c| c.uncertain == uncertain && c.motion_program == program,
                || {
                    GlossyChain::new(gpu, &inputs, motion, program)
                        .context("creating the glossy chain")
                },
            )?;
            glossy.record(rec, cx.key, &inputs, cx.parity, &s.glossy)?;
        }
        let light = Denoised {
            matte: Some(&m.denoised.1),
            glossy: g.as_ref().map(|g| &g.denoised.1),
            direct: None,
        };
        let follow = Parity::BOTH.map(|p| self.taa_follow(m, g.as_ref(), p));
        Ok(Outputs { light: [light; 2], follow })
    }

    fn pipelines(&mut self) -> Vec<&mut dyn crate::shader::Reload> {
        let mut v: Vec<&mut dyn crate::shader::Reload> = vec![];
        if let Some(c) = self.matte.as_mut() {
            v.extend(c.pipelines());
        }
        if let Some(c) = self.glossy.as_mut() {
            v.extend(c.pipelines());
        }
        v
    }
}

impl Mara {
    /// What TAA follows at parity `parity`: the matte chain's temporal output (before its
    /// spatial stages) and what the glossy temporal wrote this frame and read.
    fn taa_follow<'a>(
        &'a self,
        m: &'a MatteTargets,
        g: Option<&'a GlossyChainTargets>,
        parity: Parity,
    ) -> TaaFollow<'a> {
        TaaFollow {
            matte: Some(MatteFollow {
                light: &m.temporal.1,
                state: &m.reason.1,
                form: MatteState::Reason,
            }),
            // What the glossy temporal wrote this frame, and what it read.
            glossy: g.map(|g| GlossyFollow {
                denoised: &g.denoised.1,
                temporal: &g.history.output(parity).1,
                previous: &g.history.history(parity).1,
                info: &g.info.1,
                params: &self.glossy_params,
            }),
        }
    }
}
