//! Planning a frame: from the settings and the input to what the frame will record, with every
//! allocation made and every refusal returned before the first pass.

use super::{DisplayTarget, FrameInput, FrameParams, MadeDenoiser, Renderer, halton_jitter};
use crate::denoise::DenoiserScene;
use crate::gpu::{BindKey, Gpu, Parity};
use crate::passes::converge::ConvergeParams;
use crate::passes::io::ChainView;
use crate::passes::reference::{TraceView, make_params};
use crate::passes::upscale::UpscaleParams;
use crate::settings::{
    FrameSettings, MAX_PATHS_PER_PIXEL, MAX_PRIMARY_SAMPLES, MAX_SAMPLES_PER_PIXEL,
};
use anyhow::{Context, Result, bail};
use glam::{Mat4, Vec2};

/// What one frame records, decided from its settings and input.
pub(super) struct FramePlan<'s> {
    pub settings: &'s FrameSettings,
    /// The index in the renderer's denoisers of the one that runs (None: the raw frame).
    pub denoiser: Option<usize>,
    /// Samples per pixel k (Voorhuis §5): k > 1 mixes traced samples into their guides.
    pub samples: u32,
    /// 1 / f: every frame traces one pixel in `period` (Dundr §5).
    pub period: u32,
    /// The G-buffer is traced (thin lens, moving shutter), not rasterised.
    pub traced: bool,
    /// Moon et al. 2017's pre-filter runs between the traced features and the G-buffer.
    pub prefilter: bool,
    /// The radiance cache runs (passes/cache.rs): it is on and a denoiser may read it.
    pub cache: bool,
    /// The cameras of this frame and the last, as the denoisers and TAA see them.
    pub view: ChainView,
    /// This frame's jittered view-projection, its jitter and its unjittered view-projection:
    /// the next frame's "previous".
    pub jittered: Mat4,
    pub jitter: Vec2,
    pub view_proj: Mat4,
    /// Bind groups of the stages before the denoiser, and after it (which bind its output).
    pub key: BindKey,
    pub output_key: BindKey,
    /// Frames rendered before this one (wraps), and its parity.
    pub frame_index: u32,
    pub parity: Parity,
    /// The still-view mean's parameters where it runs (passes/converge.rs).
    pub converge: Option<ConvergeParams>,
    /// The upscaler's parameters where it runs in TAA's place (passes/upscale.rs).
    pub upscale: Option<UpscaleParams>,
    /// TAA runs after frames the upscaler ran instead: its history restarts.
    pub taa_restarts: bool,
}

impl Renderer {
    /// Animate, allocate what the settings need, refuse what they cannot have, and write the
    /// frame's uniforms.
    pub(super) fn plan<'s>(
        &mut self,
        gpu: &Gpu,
        input: &FrameInput,
        settings: &'s FrameSettings,
        target: Option<&DisplayTarget>,
    ) -> Result<FramePlan<'s>> {
        let mut moved = false;
        if self.prepared.features.animated {
            puffin::profile_scope!("animate");
            moved = self.prepared.expose(&self.scene, input.time, input.shutter.map(|s| s.time));
            self.gpu_scene.update_geometry(gpu, &self.prepared, moved);
            if let Some(p) = self.posing.as_mut() {
                p.prepare(gpu, &self.scene, &mut self.prepared, &self.gpu_scene)?;
            }
        }
        let _setup = crate::profile::scope("upload");
        self.update_accumulation(gpu, input, settings);
        let denoiser = self.denoiser_for(gpu, settings)?;
        // After a resize: the histories are resampled to the new size where the settings ask
        // for it and a denoiser keeps them, else every one restarts.
        let resample = settings.resample_history_frames > 0.0 && denoiser.is_some();
        if self.rescale_from.is_some() && !resample {
            self.rescale_from = None;
            let h = &mut self.history;
            *h = super::FrameHistory { frame_index: h.frame_index, ..Default::default() };
        }
        let upscaled = self.upscaled_size(settings, denoiser);
        if denoiser.is_some() {
            let t = &mut self.targets;
            // The upscaler runs in TAA's place and keeps its own still-view mean.
            let changed = match upscaled {
                None => self.stages.taa.allocate(gpu, &mut t.memory, t.size, t.epoch),
                Some(_) => {
                    let taa = self.stages.taa.release(&mut t.memory, t.epoch);
                    self.stages.converge.release(&mut t.memory, t.epoch) || taa
                }
            };
            if changed {
                t.generation += 1;
            }
            // TAA's test of what a move uncovered reads the previous depth.
            t.ensure_previous(gpu);
        }
        self.reflections(gpu, settings, denoiser);
        self.reservoirs(gpu, settings);
        let (samples, period) = self.sampling(gpu, settings, denoiser)?;
        let (traced, primary_samples, prefilter) = self.primaries(gpu, input, settings, samples)?;
        let cache = settings.cache.enabled && denoiser.is_some();
        if cache {
            if self.stages.cache.prepare(gpu, &settings.cache, settings.exposure_scale()) {
                self.targets.generation += 1;
            }
            self.targets.ensure_cache(gpu);
            // The gather's test of what the last frame saw.
            self.targets.ensure_previous(gpu);
        }
        let cam = self.camera_setup(&input.camera);
        let h = &self.history;
        // The raster's position in the pixel: Halton for TAA and the upscaler, uniformly random
        // for the accumulate mode's box filter, the centre otherwise.
        let jitter = if settings.accumulate {
            super::random_jitter(h.frame_index, settings.seed)
        } else if denoiser.is_some() && (settings.taa.enabled || upscaled.is_some()) {
            halton_jitter(h.frame_index)
        } else {
            Vec2::splat(0.5)
        };
        let jittered = cam.jittered(jitter, self.targets.size);
        let (prev_jittered, prev_jitter) = h.prev_jittered.unwrap_or((jittered, jitter));
        let view = ChainView {
            inv_view_proj: jittered.inverse(),
            prev_inv_view_proj: prev_jittered.inverse(),
            jitter_shift: prev_jitter - jitter,
            history_valid: denoiser.is_some()
                && h.denoised_last == denoiser
                && h.prev_jittered.is_some(),
            static_view: !moved && h.prev_view_proj == Some(cam.view_proj),
        };
        let converge = self.converge_plan(
            gpu,
            input,
            settings,
            (denoiser, samples, upscaled.is_none()),
            &view,
        );
        let upscale = self.upscale_plan(gpu, settings, (denoiser, upscaled), converge.as_ref());
        let taa_restarts = upscale.is_none() && self.history.upscaled_last.is_some();
        self.history.upscaled_last = upscaled;
        let denoised = denoiser.is_some();
        // Extra paths where a move uncovered a surface only where a history is there to restart
        // (on a cut, a first frame or a change of denoiser every pixel would take them) and
        // something moved (in a still frame nothing is uncovered: the depth tests are skipped).
        let uncovered_paths =
            if view.history_valid && !view.static_view { settings.uncovered_paths } else { 0 };
        self.upload(
            gpu,
            input,
            settings,
            (&cam, jittered, jitter, &view),
            denoised,
            (primary_samples, uncovered_paths, prev_jitter),
        );
        if let Some(shown) = upscaled {
            self.upload_shown(gpu, input, settings, shown, jitter);
        }
        self.history.denoised_last = denoiser;
        if let Some(target) = target {
            self.prepare_display(gpu, target, settings)?;
        }
        Ok(FramePlan {
            settings,
            denoiser,
            samples,
            period,
            traced,
            prefilter,
            cache,
            view,
            jittered,
            jitter,
            view_proj: cam.view_proj,
            key: self.bind_key(None),
            output_key: self.bind_key(denoiser),
            frame_index: self.history.frame_index,
            parity: Parity::of_frame(self.history.frame_index),
            converge,
            upscale,
            taa_restarts,
        })
    }

    /// The frame's uniform at the shown size, for the upscaler's raster of the materials: the
    /// same camera, sampled at `jitter` within each shown pixel.
    fn upload_shown(
        &self,
        gpu: &Gpu,
        input: &FrameInput,
        settings: &FrameSettings,
        shown: (u32, u32),
        jitter: Vec2,
    ) {
        let cam = super::CameraSetup::new(&input.camera, self.prepared.origin, shown, self.near());
        let jittered = cam.jittered(jitter, shown);
        let prev = self.history.prev_view_proj.unwrap_or(cam.view_proj);
        let index = self.history.frame_index;
        let eps = self.prepared.ray_epsilon();
        let fp =
            FrameParams::new(&cam, jittered, prev, jitter, shown, index, settings, 0, eps, 0.0);
        self.stages.upscale.write_frame(gpu, &fp);
    }

    /// The size the upscaler shows this frame at, where it runs: a denoiser runs, the setting
    /// is on and the frame is shown larger than it renders (never smaller on either axis).
    fn upscaled_size(
        &self,
        settings: &FrameSettings,
        denoiser: Option<usize>,
    ) -> Option<(u32, u32)> {
        let render = self.targets.size;
        self.shown_size.filter(|s| {
            denoiser.is_some()
                && settings.taa.upscale
                && *s != render
                && s.0 >= render.0
                && s.1 >= render.1
        })
    }

    /// The upscaler's parameters where it shows at `shown`; its targets are made or dropped
    /// here. Its history continues where it ran last frame at the same shown size and
    /// denoiser, its raw samples' mean where the still-view mean (`converge`) continues.
    fn upscale_plan(
        &mut self,
        gpu: &Gpu,
        settings: &FrameSettings,
        (denoiser, shown): (Option<usize>, Option<(u32, u32)>),
        converge: Option<&ConvergeParams>,
    ) -> Option<UpscaleParams> {
        let render = self.targets.size;
        if self.stages.upscale.allocate(gpu, shown) {
            self.targets.generation += 1;
        }
        let h = &self.history;
        let continues = shown.is_some() && h.upscaled_last == shown && h.denoised_last == denoiser;
        shown.map(|s| UpscaleParams::new(&settings.taa, (render, s), continues, converge))
    }

    /// The still-view mean's parameters where it runs this frame (its textures made where
    /// `allocate`): a denoiser ran (TAA's image is
    /// there to move), the stage is on, and every pixel is one sample (k > 1 mixes samples into
    /// guides the mean cannot remodulate). It continues last frame's mean while the view stands
    /// still with the same camera, settings and size; anything else restarts it, but for the
    /// settings that do not change a pixel's samples.
    fn converge_plan(
        &mut self,
        gpu: &Gpu,
        input: &FrameInput,
        settings: &FrameSettings,
        (denoiser, samples, allocate): (Option<usize>, u32, bool),
        view: &ChainView,
    ) -> Option<ConvergeParams> {
        let taa = &settings.taa;
        if denoiser.is_none() || taa.converge_sigmas <= 0.0 || samples != 1 {
            self.history.converge_state = None;
            return None;
        }
        // What decides the samples: not which pixels a frame traces (the governor's fraction),
        // nor the display's exposure and view.
        let samples_from = FrameSettings {
            sample_fraction: Default::default(),
            exposure_ev: 0.0,
            view: Default::default(),
            ..settings.clone()
        };
        let state = (input.camera, input.shutter.map(|s| s.camera), samples_from);
        let h = &mut self.history;
        // A resize cleared the state (Renderer::resize).
        let continues =
            view.history_valid && view.static_view && h.converge_state.as_ref() == Some(&state);
        h.converge_state = Some(state);
        let t = &mut self.targets;
        let keep_composite = crate::gpu::graph::is_kept(&self.kept, "composite/hdr");
        // Where the upscaler runs it keeps the mean itself and only the parameters are asked for.
        if allocate
            && self.stages.converge.allocate(gpu, &mut t.memory, (t.size, t.epoch), keep_composite)
        {
            t.generation += 1;
        }
        Some(ConvergeParams {
            continues: continues as u32,
            bias_sigmas: taa.converge_sigmas.clamp(0.0, 1024.0),
            min_samples: taa.converge_min_samples.clamp(2.0, 1.0e9),
            _pad: 0.0,
        })
    }

    /// The index in `denoisers` of the one `settings` asks for (made and allocated on first
    /// use), or None for the raw frame; None also in accumulate mode.
    pub(super) fn denoiser_for(
        &mut self,
        gpu: &Gpu,
        settings: &FrameSettings,
    ) -> Result<Option<usize>> {
        if settings.accumulate {
            self.release_denoisers(None);
            return Ok(None);
        }
        let name = settings.denoiser.name();
        let i = match self.denoisers.iter().position(|d| d.name == name) {
            Some(i) => i,
            None => {
                let Some(make) = crate::denoise::find(name)?.make else {
                    self.release_denoisers(None);
                    return Ok(None);
                };
                let scene = DenoiserScene {
                    glossy: self.prepared.features.glossy,
                    motion: self.prepared.features.motion(),
                    extent: self.prepared.extent as f32,
                };
                let denoiser =
                    make(gpu, &scene).with_context(|| format!("creating the {name} denoiser"))?;
                let (kept, labels) = (vec![], vec![]);
                let name = name.to_string();
                let d = MadeDenoiser { name, epoch: None, kept, layout: 0, labels, denoiser };
                self.denoisers.push(d);
                self.denoisers.len() - 1
            }
        };
        self.release_denoisers(Some(i));
        let t = &mut self.targets;
        let mut kept = self.kept.clone();
        kept.extend(settings.view.spec().map(|v| v.texture.to_string()));
        let d = &mut self.denoisers[i];
        let layout = d.denoiser.layout(settings);
        if d.epoch != Some(t.epoch) || d.kept != kept || d.layout != layout {
            // Made again for a new size, or placed again for other textures to keep or other
            // settings: what it made before in these targets goes.
            if d.epoch == Some(t.epoch) {
                t.memory.forget_labels(&d.labels);
            }
            let before = t.memory.labels();
            d.denoiser
                .allocate(gpu, &mut t.memory, t.size, &kept, settings)
                .with_context(|| format!("allocating the {name} denoiser's textures"))?;
            d.labels = t.memory.labels().into_iter().filter(|l| !before.contains(l)).collect();
            (d.epoch, d.kept, d.layout) = (Some(t.epoch), kept, layout);
            t.generation += 1;
        }
        if d.denoiser.needs_previous_gbuffer() {
            t.ensure_previous(gpu);
        }
        Ok(Some(i))
    }

    /// The trace writes the glossy path's reflection data where the active denoiser reads it,
    /// the view shows it or [`Renderer::keep`] names it, and drops it otherwise (28 bytes a
    /// pixel in a glossy scene).
    fn reflections(&mut self, gpu: &Gpu, settings: &FrameSettings, denoiser: Option<usize>) {
        use crate::passes::trace::REFLECTION_LABELS;
        let read = denoiser.is_some_and(|i| self.denoisers[i].denoiser.reads_reflections());
        let shown = settings.view.spec().is_some_and(|v| REFLECTION_LABELS.contains(&v.texture));
        let kept = REFLECTION_LABELS.iter().any(|l| crate::gpu::graph::is_kept(&self.kept, l));
        let shown = shown || kept;
        let t = &mut self.targets;
        if t.trace.set_reflections(gpu, &mut t.memory, t.size, read || shown) {
            t.generation += 1;
        }
    }

    /// The trace keeps the matte light's reservoirs while the settings reuse light samples (64
    /// bytes a pixel), and drops them otherwise.
    fn reservoirs(&mut self, gpu: &Gpu, settings: &FrameSettings) {
        let reuse = settings.light_candidates > 1 && settings.light_reuse;
        let t = &mut self.targets;
        if t.trace.set_reservoirs(gpu, &mut t.memory, t.size, reuse) {
            t.generation += 1;
        }
    }

    /// Only the active denoiser (`active`, an index in `denoisers`) holds textures: every other
    /// one drops its own, and the frame's memory forgets them.
    fn release_denoisers(&mut self, active: Option<usize>) {
        for (j, d) in self.denoisers.iter_mut().enumerate() {
            if Some(j) == active || d.epoch.is_none() {
                continue;
            }
            d.denoiser.release();
            // Another size's targets went with their memory.
            if d.epoch == Some(self.targets.epoch) {
                self.targets.memory.forget_labels(&d.labels);
            }
            (d.epoch, d.labels) = (None, vec![]);
            self.targets.generation += 1;
        }
    }

    /// Accumulation restarts whenever anything that changes the image changes.
    fn update_accumulation(&mut self, gpu: &Gpu, input: &FrameInput, settings: &FrameSettings) {
        let h = &mut self.history;
        if !settings.accumulate {
            h.accumulated = 0;
            h.accumulated_state = None;
            return;
        }
        let same = h.accumulated_state.as_ref().is_some_and(|(i, s)| {
            i == input && s.max_depth == settings.max_depth && s.seed == settings.seed
        });
        h.accumulated = if same { h.accumulated + 1 } else { 1 };
        h.accumulated_state = Some((*input, settings.clone()));
        self.targets.ensure_accumulation(gpu);
    }

    /// Samples per pixel k and the sample period 1 / f, refusing what cannot go together.
    fn sampling(
        &mut self,
        gpu: &Gpu,
        settings: &FrameSettings,
        denoiser: Option<usize>,
    ) -> Result<(u32, u32)> {
        // Samples per pixel (Voorhuis §5); the accumulate mode box-filters by itself.
        let samples = match settings.accumulate {
            true => 1,
            false => settings.samples_per_pixel.clamp(1, MAX_SAMPLES_PER_PIXEL),
        };
        // Below one sample per pixel (Dundr §5): only denoisers that fill the untraced pixels.
        let period = settings.sample_period();
        if period > 1 && samples > 1 {
            bail!(
                "sample fraction {} traces some pixels each frame and {samples} samples per pixel \
                 traces every pixel {samples} times: choose one",
                settings.sample_fraction
            );
        }
        let refuses = |i: &usize| !self.denoisers[*i].denoiser.fills_untraced_pixels();
        if let Some(i) = denoiser.filter(refuses).filter(|_| period > 1) {
            let fills: Vec<&str> = crate::denoise::entries()
                .into_iter()
                .filter(|e| e.info.fractions)
                .map(|e| e.info.name)
                .collect();
            bail!(
                "the {} denoiser needs every pixel traced each frame; sample fraction {} needs one \
                 that fills untraced pixels ({})",
                self.denoisers[i].name,
                settings.sample_fraction,
                fills.join(", ")
            );
        }
        if samples > 1 {
            self.targets.ensure_supersample(gpu, samples, self.prepared.features.glossy);
        }
        Ok((samples, period))
    }

    /// Whether the G-buffer is traced, with how many primary samples, and whether the
    /// pre-filter runs; allocates their targets.
    fn primaries(
        &mut self,
        gpu: &Gpu,
        input: &FrameInput,
        settings: &FrameSettings,
        samples: u32,
    ) -> Result<(bool, u32, bool)> {
        // A thin lens or motion blur (a stochastic primary hit): the G-buffer is traced (k rays
        // per pixel, each through its own lens point at its own time), not rasterised; the
        // accumulate mode traces one, so that its mean over frames is exact.
        let blurred = input.shutter.is_some_and(|s| s.camera != input.camera)
            || self.prepared.shutter_moves();
        let traced = input.camera.lens.is_some_and(|l| l.aperture_radius > 0.0) || blurred;
        let primary_samples = match (traced, settings.accumulate) {
            (false, _) => 0,
            (true, true) => 1,
            (true, false) => settings.primary_samples.clamp(1, MAX_PRIMARY_SAMPLES),
        };
        let prefilter = traced && settings.prefilter && !settings.accumulate;
        if traced {
            if samples > 1 {
                bail!(
                    "{samples} samples per pixel (guide rays) need the raster's G-buffer, which \
                     depth of field and motion blur replace by traced primaries: set samples per \
                     pixel to 1 (they trace {} primary samples per pixel)",
                    settings.primary_samples
                );
            }
            self.targets.ensure_primaries(gpu, prefilter);
        }
        Ok((traced, primary_samples, prefilter))
    }

    /// Write the frame and trace uniforms for the camera `cam`, jittered by `jitter`.
    fn upload(
        &self,
        gpu: &Gpu,
        input: &FrameInput,
        settings: &FrameSettings,
        (cam, jittered, jitter, view): (&super::CameraSetup, Mat4, Vec2, &ChainView),
        denoised: bool,
        (primary_samples, uncovered_paths, prev_jitter): (u32, u32, Vec2),
    ) {
        let (size, h) = (self.targets.size, &self.history);
        let g = &settings.glossy;
        // The glossy chain's reflection motion wants the representative ray of glossy surfaces.
        // Only the reflection data (the virtual position) reads the representative ray's hit.
        let representative = if denoised
            && self.targets.trace.has_reflections()
            && g.trace_representative_ray
            && g.reflection_mv != crate::settings::ReflectionMv::Primary
        {
            g.roughness_threshold
        } else {
            0.0
        };
        let prev = h.prev_view_proj.unwrap_or(cam.view_proj);
        let mut fp = FrameParams::new(
            cam,
            jittered,
            prev,
            jitter,
            size,
            h.frame_index,
            settings,
            h.accumulated,
            self.prepared.ray_epsilon(),
            representative,
        );
        fp.set_view(view);
        fp.primary_samples = primary_samples;
        fp.uncovered_paths = uncovered_paths.min(MAX_PATHS_PER_PIXEL);
        (fp.prev_jitter_x, fp.prev_jitter_y) = (prev_jitter.x, prev_jitter.y);
        if self.rescale_from.is_some() {
            fp.rescaled_frames = settings.resample_history_frames;
        }
        let trace_view = TraceView {
            camera: input.camera,
            width: size.0,
            height: size.1,
            max_depth: settings.max_depth,
            seed: settings.seed,
            shutter_camera: input.shutter.map(|s| s.camera),
            texture_lod: settings.texture_lod,
        };
        let mut tp = make_params(&self.prepared, &trace_view);
        tp.switches[1] = settings.screen_strata as u32 as f32;
        gpu.queue.write_buffer(&self.uniforms.params, 0, bytemuck::bytes_of(&tp));
        gpu.queue.write_buffer(&self.uniforms.frame, 0, bytemuck::bytes_of(&fp));
    }
}
