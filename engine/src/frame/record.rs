//! Recording a planned frame: one line per stage, in the order of Mara et al. 2017's Figure 2
//! with the primaries' pre-filter of Moon et al. 2017 before the trace.

use super::plan::FramePlan;
use super::targets::{Targets, Uniforms};
use super::{DisplayTarget, FrameInput, MadeDenoiser, Renderer};
use crate::denoise::{FrameContext, Outputs};
use crate::gpu::{BindKey, Gpu, Parity, Recorder};
use crate::passes::cache::{CacheInputs, RadianceCache};
use crate::passes::composite::{self, CompositePass, DisplayPass, FrameBuffers};
use crate::passes::converge::ConvergeStage;
use crate::passes::gbuffer::{self, GBufferPass};
use crate::passes::io::FrameIo;
use crate::passes::prefilter::Prefilter;
use crate::passes::primaries::Primaries;
use crate::passes::rescale::Rescale;
use crate::passes::supersample::Supersample;
use crate::passes::taa::TaaParams;
use crate::passes::taa::TaaStage;
use crate::passes::trace::{self, SceneInputs, TraceInputs, TracePass};
use crate::passes::upscale::UpscaleParams;
use crate::settings::FrameSettings;
use anyhow::{Context, Result};
use glam::{Mat4, Vec2};

/// The frame's own stages (a denoiser's are its own).
pub(super) struct Stages {
    pub gbuffer: GBufferPass,
    pub trace: TracePass,
    pub composite: CompositePass,
    /// Made for the first display target's format.
    pub display: Option<DisplayPass>,
    pub taa: TaaStage,
    pub converge: ConvergeStage,
    pub upscale: crate::passes::upscale::UpscaleStage,
    pub supersample: Supersample,
    pub primaries: Primaries,
    pub prefilter: Prefilter,
    pub cache: RadianceCache,
    pub rescale: Rescale,
}

/// What the next frame needs of the ones before it.
#[derive(Default)]
pub(super) struct FrameHistory {
    /// The index in the renderer's denoisers of the one that ran last frame (its image is
    /// then TAA's).
    pub denoised_last: Option<usize>,
    pub prev_view_proj: Option<Mat4>,
    /// The previous frame's jittered view-projection (its depth buffer was rasterised with it)
    /// and its jitter.
    pub prev_jittered: Option<(Mat4, Vec2)>,
    pub frame_index: u32,
    pub accumulated: u32,
    pub accumulated_state: Option<(FrameInput, FrameSettings)>,
    /// What the still-view mean was taken with: the camera, the shutter's camera and the
    /// settings (None: it restarts).
    pub converge_state: Option<ConvergeState>,
    /// The size the upscaler showed last frame (None: it did not run).
    pub upscaled_last: Option<(u32, u32)>,
}

pub(super) type ConvergeState = (crate::scene::Camera, Option<crate::scene::Camera>, FrameSettings);

impl Renderer {
    /// Record the planned frame, one line per stage, and submit it.
    pub(super) fn record_frame(
        &mut self,
        gpu: &Gpu,
        plan: &FramePlan,
        target: Option<&DisplayTarget>,
    ) -> Result<()> {
        // Kept until the frame is submitted: its textures are read by the resampling.
        let rescale_from = self.rescale_from.take();
        let encode = crate::profile::scope("encode");
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let moving = self.prepared.shutter_moves();
        let Renderer {
            gpu_scene,
            targets: t,
            uniforms: u,
            stages: s,
            denoisers,
            timer,
            posing,
            last_rescale,
            ..
        } = self;
        if let Some(t) = timer.as_mut() {
            t.begin_frame();
        }
        let mut rec = Recorder::new(gpu, &mut enc, timer.as_mut());
        if let Err(e) =
            record_rescale(&mut rec, &mut s.rescale, rescale_from.as_ref(), t, last_rescale)
        {
            // Nothing was resampled: the next frame must not read these targets as histories.
            self.history.denoised_last = None;
            return Err(e);
        }
        if let Some(p) = posing.as_mut() {
            p.record(&mut rec, gpu_scene);
        }
        let (scene, trace, io) = frame_inputs(plan, (t, u), gpu_scene, moving);
        // primaries [-> pre-filter] -> trace [-> mix] [-> radiance cache] -> denoise -> composite [-> resolve] -> TAA
        // [-> still-view mean] -> display; then this frame's G-buffer becomes the next one's previous.
        s.record_primaries(&mut rec, plan, scene, t)?;
        s.record_trace(&mut rec, plan, &trace, t)?;
        let io = s.record_mix(&mut rec, plan, &trace, t, io)?;
        let io = s.record_cache(&mut rec, plan, scene, t, io)?;
        let denoiser = record_denoiser(&mut rec, plan, denoisers, &io)?;
        s.record_composite(&mut rec, plan, &io, denoiser.as_ref(), u.shown(t, &io, None))?;
        s.record_resolve(&mut rec, plan, &io, t)?;
        s.record_taa(&mut rec, plan, &io, denoiser.as_ref())?;
        s.record_converge(&mut rec, plan, &io)?;
        s.record_upscale(&mut rec, plan, &io, gpu_scene)?;
        s.record_display(&mut rec, plan, (&io, u, t), target)?;
        if let (true, Some(p)) = (denoiser.is_some(), &t.previous) {
            p.record_copy(rec.enc, &t.gbuffer, t.size);
        }
        drop(encode);
        self.submit(gpu, enc, plan);
        drop(rescale_from);
        Ok(())
    }

    /// Resolve the pass times, submit, and make this frame the next one's previous.
    fn submit(&mut self, gpu: &Gpu, mut enc: wgpu::CommandEncoder, plan: &FramePlan) {
        if let Some(timer) = self.timer.as_mut() {
            timer.resolve(&gpu.device, &mut enc, self.async_timings);
        }
        let _submit = crate::profile::scope("submit");
        if let Some(timer) = self.timer.as_mut() {
            timer.submitted_ns = puffin::now_ns();
        }
        gpu.queue.submit([enc.finish()]);
        if let Some(timer) = self.timer.as_mut() {
            timer.submitted();
        }
        if let Some(p) = self.posing.as_mut() {
            p.submitted();
        }
        let h = &mut self.history;
        h.prev_view_proj = Some(plan.view_proj);
        h.prev_jittered = Some((plan.jittered, plan.jitter));
        h.frame_index = h.frame_index.wrapping_add(1);
    }

    /// Draw the last frame again into `target` (another view, a screenshot) without rendering.
    pub fn redisplay(
        &mut self,
        gpu: &Gpu,
        settings: &FrameSettings,
        target: &DisplayTarget,
    ) -> Result<()> {
        gpu.validated("displaying the frame", || {
            self.prepare_display(gpu, target, settings)?;
            // Only the exposure changes; the rest of the uniform is the last frame's.
            gpu.queue.write_buffer(
                &self.uniforms.frame,
                std::mem::offset_of!(super::FrameParams, exposure) as u64,
                bytemuck::bytes_of(&settings.exposure_scale()),
            );
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            let (t, u) = (&self.targets, &self.uniforms);
            let io = t.io(&u.frame, &self.gpu_scene);
            let denoised = self.history.denoised_last;
            let bind_key = self.bind_key(denoised);
            let s = &mut self.stages;
            let after_taa = after_taa(&s.taa, &s.converge, &s.upscale, &t.hdr);
            let fb = u.shown(t, &io, after_taa.filter(|_| denoised.is_some()));
            let (view, view_key) = t.view_texture(settings, &s.upscale.memory);
            let key = BindKey { view: view_key, ..bind_key };
            if let Some(d) = s.display.as_mut() {
                d.record(&mut Recorder::new(gpu, &mut enc, None), key, &fb, view, target.view)?;
            }
            gpu.queue.submit([enc.finish()]);
            Ok(())
        })
    }

    /// Make the display pass for `target`'s format and write its options (the view's map).
    pub(super) fn prepare_display(
        &mut self,
        gpu: &Gpu,
        target: &DisplayTarget,
        settings: &FrameSettings,
    ) -> Result<()> {
        let (t, u) = (&self.targets, &self.uniforms);
        if self.stages.display.as_ref().is_none_or(|d| d.format != target.format) {
            let io = t.io(&u.frame, &self.gpu_scene);
            let pass = DisplayPass::new(gpu, &u.shown(t, &io, None), target.format);
            self.stages.display = Some(pass.context("creating the display pass")?);
        }
        let spec = match settings.view.is_final() {
            true => None,
            false => Some(
                settings
                    .view
                    .spec()
                    .with_context(|| format!("no view {:?}", settings.view.name()))?,
            ),
        };
        // The image's size: the upscaler's where it runs this frame (or ran, for a redisplay).
        let image = self.history.upscaled_last.unwrap_or(t.size);
        let frame_weight = UpscaleParams::frame_weight(&settings.taa, (t.size, image));
        let (map, channel, param) =
            spec.map_or((0, 0, 0.0), |s| s.map.encode(t.size.0, frame_weight));
        let srgb = !target.format.is_srgb() as u32;
        let options: [u32; 8] =
            [srgb, map, target.size.0, target.size.1, channel, param.to_bits(), image.0, image.1];
        gpu.queue.write_buffer(&u.display, 0, bytemuck::cast_slice(&options));
        Ok(())
    }
}

/// The image after TAA (and the still-view mean where it ran), once TAA ran; the upscaler's
/// where it ran in TAA's place.
pub(super) fn after_taa<'a>(
    taa: &'a TaaStage,
    converge: &'a ConvergeStage,
    upscale: &'a crate::passes::upscale::UpscaleStage,
    hdr: &'a wgpu::Buffer,
) -> Option<&'a wgpu::Buffer> {
    upscale.output().map(|(b, _)| b).or(converge.output(hdr)).or(taa.output())
}

/// What the stages read: the scene, the trace's inputs, and the frame's I/O with the
/// pre-filter's statistics where it ran.
fn frame_inputs<'a>(
    plan: &FramePlan,
    (t, u): (&'a Targets, &'a Uniforms),
    scene: &'a crate::gpu::GpuScene,
    moving: bool,
) -> (SceneInputs<'a>, TraceInputs<'a>, FrameIo<'a>) {
    let s = SceneInputs { scene, params: &u.params, frame: &u.frame, moving };
    // The previous depth is this frame's last frame only where a denoiser ran (it is copied
    // after a denoised frame).
    let previous_depth =
        t.previous.as_ref().filter(|_| plan.denoiser.is_some()).map(|p| &p.depth.1);
    let trace = TraceInputs { scene: s, g: &t.gbuffer, t: &t.trace, cache: None, previous_depth };
    let mut io = t.io(&u.frame, scene);
    io.feature_uncertainty = t.prefilter.as_ref().filter(|_| plan.prefilter).map(|pf| &pf.view.1);
    (s, trace, io)
}

/// After a change of size, the last size's histories resampled into this one's
/// (passes/rescale.rs), and what that carried into `last`.
fn record_rescale(
    rec: &mut Recorder,
    rescale: &mut Rescale,
    old: Option<&Targets>,
    t: &Targets,
    last: &mut crate::passes::rescale::Rescaled,
) -> Result<()> {
    if let Some(old) = old {
        let from = (&old.memory, old.previous.as_ref());
        *last = rescale.record(rec, from, (&t.memory, t.previous.as_ref()))?;
    }
    Ok(())
}

/// The denoiser the plan chose, recorded on the frame's I/O: what it made.
fn record_denoiser<'d>(
    rec: &mut Recorder,
    plan: &FramePlan,
    denoisers: &'d mut [MadeDenoiser],
    io: &FrameIo,
) -> Result<Option<Outputs<'d>>> {
    let Some(d) = plan.denoiser.and_then(|i| denoisers.get_mut(i)) else { return Ok(None) };
    let cx = FrameContext {
        index: plan.frame_index,
        parity: plan.parity,
        view: plan.view,
        settings: plan.settings,
        key: plan.key,
    };
    Ok(Some(d.denoiser.record(rec, io, &cx)?))
}

impl Stages {
    /// The G-buffer: rasterised, or with a thin lens or an open shutter traced, pre-filtered
    /// (Moon et al. 2017) and resolved.
    fn record_primaries(
        &mut self,
        rec: &mut Recorder,
        plan: &FramePlan,
        scene: SceneInputs,
        t: &Targets,
    ) -> Result<()> {
        let Some(p) = t.primaries.as_ref().filter(|_| plan.traced) else {
            let _pass = crate::profile::scope(gbuffer::LABEL);
            return self.gbuffer.record(rec, scene.scene, scene.frame, &t.gbuffer);
        };
        self.primaries.record_trace(rec, plan.key, scene, p, t.size)?;
        let mut edges = None;
        if let Some(pf) = t.prefilter.as_ref().filter(|_| plan.prefilter) {
            let offered = crate::passes::prefilter::bindings(scene.frame, p, pf);
            self.prefilter.record(rec, plan.key, t.size, &offered)?;
            edges = Some(&pf.features);
        }
        self.primaries.record_resolve(rec, plan.key, scene.frame, (p, edges), &t.gbuffer)
    }

    /// The trace; matte paths end in the radiance cache where it ran the frame before, and
    /// where their length is unlimited (shaders/cache/path_end.wgsl).
    fn record_trace(
        &mut self,
        rec: &mut Recorder,
        plan: &FramePlan,
        trace: &TraceInputs,
        t: &Targets,
    ) -> Result<()> {
        let _pass = crate::profile::scope(trace::LABEL);
        let s = plan.settings;
        let ends = plan.cache && s.cache.path_end_samples > 0.0 && s.max_depth < 0;
        let cache = self.cache.live_cells(plan.frame_index).filter(|_| ends);
        let inputs = TraceInputs { cache, ..*trace };
        self.trace.record(rec, plan.key, &inputs, t.size, plan.period)
    }

    /// With k > 1 samples per pixel, the extra samples mixed into their guides (Voorhuis §5,
    /// eq. 7): the I/O then offers the mixed light as the trace's.
    fn record_mix<'a>(
        &mut self,
        rec: &mut Recorder,
        plan: &FramePlan,
        trace: &TraceInputs,
        t: &'a Targets,
        mut io: FrameIo<'a>,
    ) -> Result<FrameIo<'a>> {
        if let Some(ss) = t.supersample.as_ref().filter(|s| s.k == plan.samples) {
            self.supersample.record_mix(rec, plan.key, trace, &io, ss)?;
            io.mixed = Some(&ss.mixed);
        }
        Ok(io)
    }

    /// The radiance cache where it runs: the I/O then offers its prior (`cache_prior`).
    fn record_cache<'a>(
        &mut self,
        rec: &mut Recorder,
        plan: &FramePlan,
        scene: SceneInputs,
        t: &'a Targets,
        mut io: FrameIo<'a>,
    ) -> Result<FrameIo<'a>> {
        let Some(ct) = t.cache.as_ref().filter(|_| plan.cache) else { return Ok(io) };
        let inputs = CacheInputs { scene, io: &io, targets: ct };
        self.cache.record(rec, plan.key, &inputs, &plan.settings.cache, plan.frame_index)?;
        io.cache_prior = Some((&ct.prior.1, &ct.prior_m2.1));
        Ok(io)
    }

    fn record_composite(
        &mut self,
        rec: &mut Recorder,
        plan: &FramePlan,
        io: &FrameIo,
        denoiser: Option<&Outputs>,
        shown: FrameBuffers,
    ) -> Result<()> {
        let fb = |p: Parity| {
            let out = denoiser.map(|d| d.at(p).0).unwrap_or_default();
            let (matte, glossy, direct) = (out.matte, out.glossy, out.direct);
            let (shown, accumulation, display) = (shown.shown, shown.accumulation, shown.display);
            FrameBuffers { io: *io, shown, accumulation, display, matte, glossy, direct }
        };
        let _pass = crate::profile::scope(composite::COMPOSITE);
        self.composite.record(rec, plan.output_key, fb, plan.parity)
    }

    /// After the composite, with k > 1: each pixel the mean of its samples' guides.
    fn record_resolve(
        &mut self,
        rec: &mut Recorder,
        plan: &FramePlan,
        io: &FrameIo,
        t: &Targets,
    ) -> Result<()> {
        match t.supersample.as_ref().filter(|s| s.k == plan.samples) {
            Some(ss) => self.supersample.record_resolve(rec, plan.key, io, ss),
            None => Ok(()),
        }
    }

    /// TAA after any denoiser; with its stage off it passes the composite on.
    fn record_taa(
        &mut self,
        rec: &mut Recorder,
        plan: &FramePlan,
        io: &FrameIo,
        denoiser: Option<&Outputs>,
    ) -> Result<()> {
        let Some(d) = denoiser.filter(|_| plan.upscale.is_none()) else { return Ok(()) };
        let s = plan.settings;
        let mut tp = TaaParams::new(&s.taa);
        // Its history was not written while the upscaler ran in its place.
        if plan.taa_restarts {
            tp.enabled = 0;
        }
        // A frame that traces one pixel in N (N > 1) shows light that gains a sample per pixel
        // only every N frames, so a still pixel's frames are not alike: TAA's long still-view
        // mean (taa.still_frames) would keep the young, hole-filled frames in the image for
        // tens of frames. There TAA blends at taa.alpha (docs/decisions.md, "Progressive
        // filter", equal samples).
        if s.sample_period() > 1 {
            tp.still_frames = 0.0;
        }
        let follow = |p: Parity| {
            let (light, follow) = d.at(p);
            (follow, light.glossy)
        };
        self.taa.record(rec, plan.output_key, io, follow, &tp, plan.parity)
    }

    /// In a still view, TAA's image moved towards the mean of the pixel's samples
    /// (passes/converge.rs).
    fn record_converge(
        &mut self,
        rec: &mut Recorder,
        plan: &FramePlan,
        io: &FrameIo,
    ) -> Result<()> {
        let (Some(params), Some(taa), None) = (plan.converge, self.taa.output(), plan.upscale)
        else {
            self.converge.skip();
            return Ok(());
        };
        self.converge.record(rec, plan.output_key, io, taa, &params, plan.parity)
    }

    /// Below the size shown, the upscaler in TAA's place (passes/upscale.rs).
    fn record_upscale(
        &mut self,
        rec: &mut Recorder,
        plan: &FramePlan,
        io: &FrameIo,
        scene: &crate::gpu::GpuScene,
    ) -> Result<()> {
        let Some(params) = plan.upscale.as_ref() else {
            self.upscale.skip();
            return Ok(());
        };
        let _pass = crate::profile::scope(crate::passes::upscale::LABEL);
        self.upscale.record(rec, (plan.output_key, scene), io, params, plan.parity)
    }

    /// The image after TAA (or the upscaler) when a denoiser ran, else the composite's,
    /// tone-mapped (or the debug view) into `target`.
    fn record_display(
        &mut self,
        rec: &mut Recorder,
        plan: &FramePlan,
        (io, u, t): (&FrameIo, &Uniforms, &Targets),
        target: Option<&DisplayTarget>,
    ) -> Result<()> {
        let (Some(target), Some(d)) = (target, self.display.as_mut()) else { return Ok(()) };
        let _pass = crate::profile::scope(composite::DISPLAY);
        let after_taa = after_taa(&self.taa, &self.converge, &self.upscale, &t.hdr);
        let shown = u.shown(t, io, after_taa.filter(|_| plan.denoiser.is_some()));
        let (view, view_key) = t.view_texture(plan.settings, &self.upscale.memory);
        d.record(rec, BindKey { view: view_key, ..plan.output_key }, &shown, view, target.view)
    }
}
