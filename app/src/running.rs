//! The viewer's window once it runs: the frame loop, the governor's glue, input, screenshots,
//! camera paths, presets and shader reloads.

use super::*;
use hush_engine::governor::{ALL_LEVELS, FrameCost};

pub(crate) struct Running {
    pub(crate) window: Arc<Window>,
    pub(crate) surface: wgpu::Surface<'static>,
    pub(crate) config: wgpu::SurfaceConfiguration,
    pub(crate) gpu: Gpu,
    pub(crate) renderer: Renderer,
    pub(crate) fly: fly::FlyCamera,
    pub(crate) panel: ui::Panel,
    pub(crate) egui_ctx: egui::Context,
    pub(crate) egui_state: egui_winit::State,
    pub(crate) egui_renderer: egui_wgpu::Renderer,
    pub(crate) last: Instant,
    pub(crate) cursor: Option<(f64, f64)>,
    pub(crate) recording: Option<CameraPath>,
    pub(crate) path: Option<CameraPath>,
    pub(crate) playback: Option<usize>,
    pub(crate) watcher: Option<ShaderWatcher>,
    /// Shader files that could not be read, and the last frame's render error (both shown over
    /// the image until they clear).
    pub(crate) shader_read_errors: Vec<String>,
    pub(crate) render_error: Option<String>,
    pub(crate) profiler: profiler::Profiler,
    pub(crate) governor: hush_engine::governor::Governor,
    /// The governor's choice the last frame ran at, and its camera (motion tells it to keep
    /// fresh samples).
    pub(crate) governed: Option<(hush_engine::governor::Choice, hush_engine::scene::Camera)>,
    /// Budgets for scenes dropped on the window (`--limit`).
    pub(crate) load: hush_engine::scene::LoadOptions,
    /// The fly camera's pose at the last frame: where a motion-blurred frame's shutter opens
    /// from.
    pub(crate) last_pose: Option<(glam::DVec3, f64, f64)>,
    /// What the shown scene was loaded from (a file or a built-in scene's name), to load it
    /// again with another of its animations.
    pub(crate) source: String,
}

impl Running {
    /// Click-to-focus: the lens focuses on the surface under the cursor (the frame covers the
    /// window, so the cursor maps to the frame's pixel by the ratio of their sizes).
    fn focus_at_cursor(&mut self) {
        let Some((x, y)) = self.cursor else { return };
        let (w, h) = self.renderer.size();
        let px = (
            (x / self.config.width.max(1) as f64 * w as f64) as u32,
            (y / self.config.height.max(1) as f64 * h as f64) as u32,
        );
        match self.renderer.view_depth_at(&self.gpu, px) {
            Ok(Some(z)) => {
                self.panel.lens.focus_distance = z as f32;
                self.panel.lens.on = true;
                self.panel.message = format!("focused at {z:.3}");
            }
            Ok(None) => self.panel.message = "nothing to focus on there".into(),
            Err(e) => self.panel.message = format!("focus: {e:#}"),
        }
    }

    fn frame_size(&self) -> (u32, u32) {
        let s = self.panel.resolution_scale.clamp(0.25, 1.0);
        (
            ((self.config.width as f32 * s) as u32).max(1),
            ((self.config.height as f32 * s) as u32).max(1),
        )
    }

    fn resize(&mut self, w: u32, h: u32) {
        if w == 0 || h == 0 {
            return; // minimized: keep everything, render nothing
        }
        self.config.width = w;
        self.config.height = h;
        self.surface.configure(&self.gpu.device, &self.config);
    }

    fn load(&mut self, path: &Path) {
        self.load.animation = None;
        self.load_source(&path.to_string_lossy());
    }

    /// Load `source` (a file or a built-in scene) under `self.load`, replacing the scene.
    fn load_source(&mut self, source: &str) {
        let path = Path::new(source);
        let r = load_scene(source, &self.load).and_then(|scene| {
            let prepared = PreparedScene::new(&scene, BvhKind::DEFAULT)?;
            let extent = prepared.extent;
            let size = self.frame_size();
            let mut r = Renderer::new(&self.gpu, scene, prepared, size)?;
            r.set_async_timings(true);
            Ok((r, extent))
        });
        match r {
            Ok((r, extent)) => {
                self.fly = fly::FlyCamera::from_camera(&r.scene.camera_or_default(), extent);
                self.last_pose = None;
                self.panel = panel_for(&self.gpu, &r, format!("loaded {}", path.display()));
                self.panel.animation = self.load.animation;
                self.source = source.to_string();
                self.window.set_title(&format!("Hush: {}", r.scene.name));
                self.renderer = r;
            }
            Err(e) => {
                log::error!("{e:#}");
                self.panel.message = format!("could not load {}: {e:#}", path.display());
            }
        }
    }

    fn screenshot(&mut self) {
        let stem = format!("hush_{}", unix_seconds());
        let r = (|| -> Result<String> {
            let png = self.renderer.display_image(&self.gpu, &self.panel.settings)?;
            png.save(format!("{stem}.png")).with_context(|| format!("writing {stem}.png"))?;
            self.renderer.read_hdr(&self.gpu)?.save(Path::new(&format!("{stem}.exr")))?;
            Ok(format!("wrote {stem}.png and {stem}.exr"))
        })();
        self.panel.message = r.unwrap_or_else(|e| format!("screenshot failed: {e:#}"));
    }

    fn toggle_record(&mut self) {
        match self.recording.take() {
            None => {
                self.recording = Some(CameraPath::default());
                self.panel.message = "recording the camera path".into();
            }
            Some(p) if !p.keys.is_empty() => {
                let file = format!("camera_path_{}.json", unix_seconds());
                self.panel.message = match p.save(Path::new(&file)) {
                    Ok(()) => format!("wrote {file} ({} keys)", p.keys.len()),
                    Err(e) => format!("{e:#}"),
                };
                self.path = Some(p);
            }
            Some(_) => self.panel.message = "nothing recorded".into(),
        }
        self.panel.recording = self.recording.is_some();
    }

    fn toggle_play(&mut self) {
        self.playback = match (self.playback, &self.path) {
            (None, Some(_)) => Some(0),
            (None, None) => {
                self.panel.message =
                    "no camera path: record one with R or pass --camera-path".into();
                None
            }
            (Some(_), _) => None,
        };
        self.panel.playing = self.playback.is_some();
    }

    /// Rebuild the pipelines whose shader files changed since the last frame.
    fn reload_shaders(&mut self) {
        let Some(w) = &self.watcher else { return };
        let changed = w.changed(&self.gpu.shaders);
        if changed.is_empty() {
            return;
        }
        let (changed, errors) = self.gpu.shaders.refresh(&changed);
        self.shader_read_errors = errors;
        if changed.is_empty() {
            return;
        }
        let outcomes = self.renderer.reload_shaders(&self.gpu, &changed);
        let ms: f64 = outcomes.iter().map(|o| o.ms).sum();
        let failed = outcomes.iter().filter(|o| o.error.is_some()).count();
        self.panel.message = format!(
            "{}: rebuilt {} of {} pipelines in {ms:.0} ms{}",
            changed.join(", "),
            outcomes.len() - failed,
            outcomes.len(),
            if failed > 0 {
                format!(", {failed} kept their last good version")
            } else {
                String::new()
            }
        );
        log::warn!("{}", self.panel.message);
        // A pass made after a failed reload (the display, the chains) may have failed for the
        // same reason; let the next frame try again.
        self.render_error = None;
    }

    /// Shader and render errors over the image, with file and line.
    fn error_overlay(ctx: &egui::Context, errors: &[String]) {
        if errors.is_empty() {
            return;
        }
        egui::Area::new(egui::Id::unique("hush error overlay"))
            .anchor(egui::Align2::LEFT_TOP, egui::vec2(8.0, 8.0))
            .show(ctx, |ui| {
                egui::Frame::popup(ui.style()).fill(egui::Color32::from_black_alpha(220)).show(
                    ui,
                    |ui| {
                        ui.set_max_width(720.0);
                        for e in errors {
                            ui.label(
                                egui::RichText::new(e)
                                    .color(egui::Color32::from_rgb(255, 110, 100))
                                    .monospace(),
                            );
                        }
                    },
                );
            });
    }

    fn frame(&mut self) -> Result<()> {
        if self.config.width == 0
            || self.config.height == 0
            || self.window.is_minimized() == Some(true)
        {
            return Ok(());
        }
        {
            puffin::profile_scope!("frame");
            self.frame_inner()?;
        }
        // The times of a frame the GPU finished (one or two frames back); never waits.
        if let Some(spans) = self.renderer.poll_pass_spans(&self.gpu) {
            self.panel.pass_ms = hush_engine::profile::per_label(&spans);
        }
        hush_engine::profile::end_frame();
        self.profiler.after_frame();
        self.window.request_redraw();
        Ok(())
    }

    /// With the governor on: report the last frame (its whole loop's time and its trace's GPU
    /// time, which arrives a frame or two late) and take its choice for this one.
    fn govern(&mut self, dt: f64, input: &FrameInput) {
        let g = &mut self.governor;
        let p = &mut self.panel;
        if !p.governor.on || p.settings.accumulate {
            self.governed = None;
            return;
        }
        g.target_ms = p.governor.target_ms;
        g.still_ratio = p.governor.still_ratio;
        g.keeps_history = p.settings.resample_history_frames > 0.0;
        g.pinned_scale = p.governor.pin_scale.then_some(p.resolution_scale);
        g.pinned_fraction = p.governor.pin_fraction.then_some(p.settings.sample_fraction);
        g.fractions_allowed =
            self.renderer.fills_untraced_pixels(&self.gpu, &p.settings).unwrap_or(false);
        g.filter_levels = hush_engine::settings::filter_levels(&p.settings).unwrap_or(0);
        let choice = match self.governed {
            Some((last, camera)) => {
                let moving = camera != input.camera;
                g.record(FrameCost::from_passes(dt * 1e3, &p.pass_ms, last, moving))
            }
            None => g.choice(),
        };
        p.resolution_scale = choice.scale;
        p.settings.sample_fraction = choice.fraction;
        let predicted = g.predict(choice).map_or(String::new(), |t| format!(", about {t:.0} ms"));
        let still = if g.still() { " (still view: most samples per second)" } else { "" };
        let levels = match g.filter_levels {
            l if choice.levels < l => format!(", {} of {l} a-trous levels", choice.levels),
            _ => String::new(),
        };
        p.governor.choice =
            format!("scale {:.3}, {} spp{levels}{predicted}{still}", choice.scale, choice.fraction);
        self.governed = Some((choice, input.camera));
    }

    fn frame_inner(&mut self) -> Result<()> {
        self.reload_shaders();
        let now = Instant::now();
        let dt = (now - self.last).as_secs_f64();
        self.last = now;
        self.panel.frame_ms = dt * 1e3;
        self.fly.lens = self.panel.lens.lens();
        self.fly.update(dt);
        let accumulate = self.panel.settings.accumulate;
        if !self.panel.paused && !accumulate {
            self.panel.time += dt;
        }
        // Motion blur: the shutter opens a fraction of the way back to the last frame's pose and
        // clock.
        let shutter = self.panel.lens.shutter as f64;
        let pose = self.last_pose.unwrap_or(self.fly.pose());
        let clock = if !self.panel.paused && !accumulate { dt } else { 0.0 };
        let mut input = FrameInput::exposed(
            |t| self.fly.camera_between(pose, 1.0 - (self.panel.time - t) / dt.max(1e-9)),
            self.panel.time,
            shutter,
            dt,
        );
        if clock == 0.0 && input.shutter.is_some_and(|s| s.camera == input.camera) {
            input.shutter = None;
        } else if let Some(open) = input.shutter.as_mut() {
            open.time = self.panel.time - shutter * clock;
        }
        self.last_pose = Some(self.fly.pose());
        if let (Some(i), Some(p)) = (self.playback, &self.path) {
            let key = p.frame(i);
            let spacing = if i > 0 { key.time - p.frame(i - 1).time } else { 0.0 };
            input = FrameInput::exposed(
                |t| p.camera_at(t),
                key.time,
                shutter,
                if spacing > 0.0 { spacing } else { dt },
            );
            self.playback = if i + 1 < p.keys.len() { Some(i + 1) } else { None };
            self.panel.playing = self.playback.is_some();
        }
        if let Some(rec) = &mut self.recording {
            rec.keys.push(CameraKey::from_camera(&input.camera, input.time));
        }
        self.govern(dt, &input);
        let size = self.frame_size();
        self.renderer.resize(&self.gpu, size)?;
        // Below the window's size the upscaler reconstructs it (taa.upscale).
        self.renderer.show_at(Some((self.config.width, self.config.height)))?;

        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.gpu.device, &self.config);
                return Ok(());
            }
            other => {
                log::warn!("surface: {other:?}");
                return Ok(());
            }
        };
        let view = frame.texture.create_view(&Default::default());
        let target = DisplayTarget {
            view: &view,
            format: self.config.format,
            size: (self.config.width, self.config.height),
        };
        if self.render_error.is_none() {
            // A failed frame (a pass that cannot be made while a shader is broken) stays on
            // screen as an error until a reload or a settings change lets it through.
            let r = {
                puffin::profile_scope!("render");
                // The governor may run fewer of the filter's levels than the panel's (they stay
                // the user's setting).
                let mut capped = None;
                if let Some((c, _)) = self.governed.filter(|(c, _)| c.levels != ALL_LEVELS) {
                    let mut s = self.panel.settings.clone();
                    hush_engine::settings::cap_filter_levels(&mut s, c.levels);
                    capped = Some(s);
                }
                let settings = capped.as_ref().unwrap_or(&self.panel.settings);
                self.renderer.render(&self.gpu, &input, settings, Some(&target))
            };
            if let Err(e) = r {
                log::error!("{e:#}");
                self.render_error = Some(format!("{e:#}"));
            }
        }
        if accumulate {
            self.panel.message = format!("accumulated {} frames", self.renderer.accumulated());
        }

        let ui_scope = hush_engine::profile::scope("ui");
        let raw = self.egui_state.take_egui_input(&self.window);
        let mut actions = ui::Actions::default();
        let panel = &mut self.panel;
        let profiler = &mut self.profiler;
        let mut errors: Vec<String> =
            self.renderer.shader_errors().into_iter().map(|(_, e)| e).collect();
        errors.extend(self.shader_read_errors.iter().cloned());
        errors.extend(self.render_error.iter().cloned());
        let settings_before = panel.settings.clone();
        let out = self.egui_ctx.run_ui(raw, |ui| {
            egui::Panel::right("settings").show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| actions = panel.show(ui));
            });
            Self::error_overlay(ui.ctx(), &errors);
            if profiler.open {
                profiler.window(ui.ctx());
            }
        });
        if panel.settings != settings_before {
            self.render_error = None;
        }
        self.egui_state.handle_platform_output(&self.window, out.platform_output);
        let jobs = self.egui_ctx.tessellate(out.shapes, out.pixels_per_point);
        drop(ui_scope);
        // Drawing the UI waits for the GPU where the driver throttles submissions.
        let draw_scope = hush_engine::profile::scope("ui draw");
        let mut textures = out.textures_delta;
        let (d, q) = (&self.gpu.device, &self.gpu.queue);
        for (id, deltas) in textures.set.drain() {
            for delta in &deltas {
                self.egui_renderer.update_texture(d, q, id, delta);
            }
        }
        let sd = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: out.pixels_per_point,
        };
        let mut enc =
            d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("egui") });
        let extra = self.egui_renderer.update_buffers(d, q, &mut enc, &jobs, &sd);
        {
            let mut pass = enc
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("egui"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                })
                .forget_lifetime();
            self.egui_renderer.render(&mut pass, &jobs, &sd);
        }
        q.submit(extra.into_iter().chain([enc.finish()]));
        for id in textures.free.drain() {
            self.egui_renderer.free_texture(&id);
        }
        drop(draw_scope);
        let _present = hush_engine::profile::scope("present");
        self.gpu.queue.present(frame);

        if let (true, Some((az, el))) = (actions.sun_changed, self.panel.sun) {
            self.renderer.set_sun_direction(&self.gpu, ui::sun_dir(az, el));
        }
        if actions.screenshot {
            self.screenshot();
        }
        if actions.toggle_record {
            self.toggle_record();
        }
        if actions.toggle_play {
            self.toggle_play();
        }
        if actions.toggle_profiler {
            self.profiler.toggle();
        }
        if actions.save_preset || actions.load_preset {
            self.preset(actions.save_preset);
        }
        if let Some(choice) = self.panel.animation_request.take() {
            // Another of the file's animations: the scene is loaded again with it.
            self.load.animation = choice;
            let source = self.source.clone();
            self.load_source(&source);
        }
        if !self.profiler.message.is_empty() {
            self.panel.message = std::mem::take(&mut self.profiler.message);
        }
        Ok(())
    }

    fn preset(&mut self, save: bool) {
        let path = PathBuf::from(&self.panel.preset_path);
        let r = if save {
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                let _ = std::fs::create_dir_all(dir);
            }
            self.panel.settings.save_preset(&path).map(|_| format!("saved {}", path.display()))
        } else {
            hush_engine::settings::FrameSettings::load_preset(&path).map(|s| {
                self.panel.settings = s;
                self.render_error = None;
                format!("loaded {}", path.display())
            })
        };
        self.panel.message = r.unwrap_or_else(|e| format!("{e:#}"));
    }

    /// Returns true when the viewer should quit.
    pub(crate) fn event(&mut self, event: &WindowEvent) -> Result<bool> {
        let consumed = self.egui_state.on_window_event(&self.window, event).consumed;
        match event {
            WindowEvent::CloseRequested => return Ok(true),
            WindowEvent::Resized(s) => self.resize(s.width, s.height),
            WindowEvent::RedrawRequested => self.frame()?,
            WindowEvent::DroppedFile(p) => self.load(p),
            WindowEvent::KeyboardInput { event, .. }
                if !consumed || event.state == ElementState::Released =>
            {
                if let PhysicalKey::Code(code) = event.physical_key {
                    let pressed = event.state == ElementState::Pressed;
                    if pressed {
                        self.fly.held.insert(code);
                    } else {
                        self.fly.held.remove(&code);
                    }
                    if pressed && !event.repeat {
                        match code {
                            KeyCode::Escape => return Ok(true),
                            KeyCode::F12 => self.screenshot(),
                            KeyCode::KeyR => self.toggle_record(),
                            KeyCode::KeyP => self.toggle_play(),
                            KeyCode::F9 => self.profiler.toggle(),
                            KeyCode::F10 => self.profiler.start_capture(unix_seconds()),
                            _ => {}
                        }
                    }
                }
            }
            WindowEvent::MouseInput { state, button: MouseButton::Right, .. } => {
                self.fly.looking = *state == ElementState::Pressed && !consumed
            }
            WindowEvent::MouseInput {
                state: ElementState::Pressed,
                button: MouseButton::Middle,
                ..
            } if !consumed => self.focus_at_cursor(),
            WindowEvent::CursorMoved { position, .. } => {
                if let (true, Some((x, y))) = (self.fly.looking, self.cursor) {
                    self.fly.look(position.x - x, position.y - y);
                }
                self.cursor = Some((position.x, position.y));
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => match delta {
                MouseScrollDelta::LineDelta(_, y) => self.fly.wheel(*y as f64),
                MouseScrollDelta::PixelDelta(p) => self.fly.wheel(p.y / 40.0),
            },
            _ => {}
        }
        Ok(false)
    }
}
