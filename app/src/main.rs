//! `hush`: the viewer. Opens a window on a scene (the default level without an argument) and
//! shows the real-time frame, with a fly camera and a side panel of settings and debug views.

mod fly;
mod profiler;
mod settings_ui;
mod ui;

use anyhow::{Context, Result};
use hush_engine::accel::BvhKind;
use hush_engine::frame::{DisplayTarget, FrameInput, Renderer};
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::profile::puffin;
use hush_engine::scene::{CameraKey, CameraPath, Scene};
use hush_engine::shader::{ShaderLibrary, ShaderWatcher, source_tree_dir};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

const NO_DISPLAY: &str = "hush needs a display (no X11 or Wayland display was found). To render \
without a window use the command-line tool, e.g.\n    hush-cli render level --mode realtime --frames 16 --out image.png";

const USAGE: &str = "usage: hush [SCENE.gltf|SCENE.glb|level|default] [--camera-path PATH.json]
            [--preset SETTINGS.toml] [--shaders DIR] [--profiler] [--puffin-http [PORT]]
            [--limit NAME=VALUE[,NAME=VALUE...]]
  no scene: the default level. Keys: WASD move, Q/E down/up, right-drag look, wheel speed,
  shift run, middle-click focus the depth of field there, F12 screenshot (PNG + EXR),
  R record a camera path, P play it, F9 profiler,
  F10 capture frames to a .puffin file, Esc quit. Drop a .gltf/.glb on the window to load it.
  Shaders reload when their files change: debug builds read the source tree's shaders/,
  release builds embed them unless --shaders DIR or $HUSH_SHADERS names a folder.
  --profiler opens the profiler window at start; --puffin-http serves profiles to puffin_viewer on 127.0.0.1 (default port 8585).
  --limit sets a budget on what a scene file may make Hush read and build (file-bytes, json-bytes,
  image-pixels, decoded-bytes, nodes, hierarchy-depth, triangles); a file over one is refused.";

struct Args {
    scene: String,
    camera_path: Option<PathBuf>,
    preset: Option<PathBuf>,
    shaders: Option<PathBuf>,
    puffin_http: Option<u16>,
    profiler: bool,
    /// Budgets for every scene loaded, dropped files included.
    load: hush_engine::scene::LoadOptions,
}

/// The shader folder: --shaders, else $HUSH_SHADERS, else (debug builds) the source tree's.
fn shader_library(arg: Option<&Path>) -> Result<ShaderLibrary> {
    if let Some(d) = arg {
        return ShaderLibrary::from_dir(d).context("--shaders");
    }
    let tree = source_tree_dir();
    let fallback = (cfg!(debug_assertions) && tree.is_dir()).then_some(tree);
    ShaderLibrary::from_env_or(fallback.as_deref())
}

/// [`Scene::open`], its warnings in the log.
fn load_scene(path: &str, load: &hush_engine::scene::LoadOptions) -> Result<Scene> {
    let scene = Scene::open(path, load)?;
    for w in &scene.warnings {
        log::warn!("{w}");
    }
    Ok(scene)
}

fn unix_seconds() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0)
}

struct Running {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: Gpu,
    renderer: Renderer,
    fly: fly::FlyCamera,
    panel: ui::Panel,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    last: Instant,
    cursor: Option<(f64, f64)>,
    recording: Option<CameraPath>,
    path: Option<CameraPath>,
    playback: Option<usize>,
    watcher: Option<ShaderWatcher>,
    /// Shader files that could not be read, and the last frame's render error (both shown over
    /// the image until they clear).
    shader_read_errors: Vec<String>,
    render_error: Option<String>,
    profiler: profiler::Profiler,
    governor: hush_engine::governor::Governor,
    /// The governor's choice the last frame ran at, and its camera (motion tells it to keep
    /// fresh samples).
    governed: Option<(hush_engine::governor::Choice, hush_engine::scene::Camera)>,
    /// Budgets for scenes dropped on the window (`--limit`).
    load: hush_engine::scene::LoadOptions,
    /// The fly camera's pose at the last frame: where a motion-blurred frame's shutter opens
    /// from.
    last_pose: Option<(glam::DVec3, f64, f64)>,
}

struct Viewer {
    args: Args,
    state: Option<Running>,
    error: Option<anyhow::Error>,
}

fn panel_for(gpu: &Gpu, r: &Renderer, message: String) -> ui::Panel {
    ui::Panel {
        settings: hush_engine::settings::FrameSettings {
            max_depth: r.scene.max_depth.max(2),
            denoiser: default_denoiser(gpu),
            ..Default::default()
        },
        resolution_scale: 1.0,
        sun: r.scene.sun_direction().map(ui::sun_angles),
        paused: false,
        time: 0.0,
        glossy: r.prepared.features.glossy,
        frame_ms: 0.0,
        pass_ms: vec![],
        report: r.report(),
        message,
        recording: false,
        playing: false,
        preset_path: "presets/my.toml".into(),
        governor: ui::GovernorPanel {
            on: true,
            target_ms: default_target_ms(gpu),
            pin_scale: false,
            pin_fraction: false,
            choice: String::new(),
        },
        lens: ui::LensPanel::new(r.scene.camera_or_default().lens, r.prepared.extent),
    }
}

/// The denoiser the viewer starts with: on a software rasterizer the progressive filter, whose
/// sample fractions below 1 let the governor hold its target at a larger scale than a filter
/// that needs every pixel each frame; on a GPU Mara's chains.
fn default_denoiser(gpu: &Gpu) -> hush_engine::settings::Denoiser {
    if gpu.info.device_type == wgpu::DeviceType::Cpu {
        hush_engine::settings::Denoiser::named("progressive")
    } else {
        hush_engine::settings::Denoiser::MARA
    }
}

/// The governor's starting target: 10 frames a second on a software rasterizer (a CPU device,
/// e.g. lavapipe), 30 on a GPU.
fn default_target_ms(gpu: &Gpu) -> f64 {
    if gpu.info.device_type == wgpu::DeviceType::Cpu { 100.0 } else { 33.3 }
}

impl Viewer {
    fn start(&mut self, el: &ActiveEventLoop) -> Result<()> {
        let t0 = Instant::now();
        let scene = load_scene(&self.args.scene, &self.args.load)?;
        let prepared = PreparedScene::new(&scene, BvhKind::DEFAULT)?;
        let load_ms = t0.elapsed().as_secs_f64() * 1e3;
        let attrs = Window::default_attributes()
            .with_title(format!("Hush: {}", scene.name))
            .with_inner_size(winit::dpi::LogicalSize::new(1280.0, 720.0));
        let window = Arc::new(el.create_window(attrs).context("creating the window")?);
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let surface =
            instance.create_surface(window.clone()).context("creating the window surface")?;
        let size = window.inner_size();
        let (w, h) = (size.width.max(1), size.height.max(1));
        // The viewer asks for the adapter's own limits: scenes dropped on it later may be larger.
        let mut req = prepared.realtime_requirements((w, h));
        req.adapter_limits = true;
        let mut gpu = Gpu::for_surface(instance, &surface, &req)?;
        gpu.shaders = shader_library(self.args.shaders.as_deref())?;
        let watcher = match gpu.shaders.dir() {
            Some(dir) => {
                log::warn!("shaders from {} (reloaded on change)", dir.display());
                Some(ShaderWatcher::new(&gpu.shaders)?)
            }
            None => None,
        };
        let caps = surface.get_capabilities(&gpu.adapter);
        // egui blends in gamma space: prefer a non-sRGB surface (the display pass then encodes sRGB).
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .or(caps.formats.first().copied())
            .context("the surface offers no format")?;
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: w,
            height: h,
            present_mode: wgpu::PresentMode::AutoVsync,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            desired_maximum_frame_latency: 2,
            color_space: Default::default(),
        };
        surface.configure(&gpu.device, &config);
        let extent = prepared.extent;
        let mut renderer = Renderer::new(&gpu, scene, prepared, (w, h))?;
        renderer.set_async_timings(true);
        let fly = fly::FlyCamera::from_camera(&renderer.scene.camera_or_default(), extent);
        let mut panel = panel_for(&gpu, &renderer, format!("loaded in {load_ms:.0} ms"));
        if let Some(p) = &self.args.preset {
            panel.settings = hush_engine::settings::FrameSettings::load_preset(p)?;
            panel.preset_path = p.display().to_string();
        }
        let mut profiler = profiler::Profiler::new(self.args.puffin_http)?;
        if self.args.profiler {
            profiler.toggle();
        }
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(gpu.device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer =
            egui_wgpu::Renderer::new(&gpu.device, format, egui_wgpu::RendererOptions::default());
        let path = self.args.camera_path.as_deref().map(CameraPath::load).transpose()?;
        let playback = path.as_ref().map(|_| 0);
        self.state = Some(Running {
            window,
            surface,
            config,
            gpu,
            renderer,
            fly,
            panel,
            egui_ctx,
            egui_state,
            egui_renderer,
            last: Instant::now(),
            cursor: None,
            recording: None,
            path,
            playback,
            watcher,
            shader_read_errors: vec![],
            render_error: None,
            profiler,
            governor: hush_engine::governor::Governor::new(100.0),
            governed: None,
            load: self.args.load,
            last_pose: None,
        });
        Ok(())
    }
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
        let r = load_scene(&path.to_string_lossy(), &self.load).and_then(|scene| {
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
        g.pinned_scale = p.governor.pin_scale.then_some(p.resolution_scale);
        g.pinned_fraction = p.governor.pin_fraction.then_some(p.settings.sample_fraction);
        g.fractions_allowed =
            self.renderer.fills_untraced_pixels(&self.gpu, &p.settings).unwrap_or(false);
        let choice = match self.governed {
            Some((last, camera)) => {
                let trace_ms = p
                    .pass_ms
                    .iter()
                    .filter(|(l, _)| *l == hush_engine::passes::trace::LABEL)
                    .map(|(_, ms)| ms)
                    .sum();
                g.record(hush_engine::governor::FrameCost {
                    wall_ms: dt * 1e3,
                    trace_ms,
                    choice: last,
                    moving: camera != input.camera,
                })
            }
            None => g.choice(),
        };
        p.resolution_scale = choice.scale;
        p.settings.sample_fraction = choice.fraction;
        let predicted = g.predict(choice).map_or(String::new(), |t| format!(", about {t:.0} ms"));
        p.governor.choice =
            format!("scale {:.3}, {} spp{predicted}", choice.scale, choice.fraction);
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
                self.renderer.render(&self.gpu, &input, &self.panel.settings, Some(&target))
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
    fn event(&mut self, event: &WindowEvent) -> Result<bool> {
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

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.state.is_none() {
            if let Err(e) = self.start(el) {
                self.error = Some(e);
                el.exit();
            } else if let Some(s) = &self.state {
                s.window.request_redraw();
            }
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(s) = &mut self.state else { return };
        match s.event(&event) {
            Ok(true) => el.exit(),
            Ok(false) => {}
            Err(e) => {
                self.error = Some(e);
                el.exit();
            }
        }
    }
}

fn has_display() -> bool {
    if cfg!(target_os = "linux") || cfg!(target_os = "freebsd") {
        return ["DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"]
            .iter()
            .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()));
    }
    true
}

fn parse_args() -> Result<Option<Args>> {
    let mut scene = None;
    let (mut camera_path, mut preset, mut shaders, mut puffin_http, mut profiler) =
        (None, None, None, None, false);
    let mut load = hush_engine::scene::LoadOptions::default();
    let mut it = std::env::args().skip(1).peekable();
    while let Some(a) = it.next() {
        match a.as_str() {
            "-h" | "--help" => return Ok(None),
            "--camera-path" => {
                camera_path = Some(PathBuf::from(it.next().context("--camera-path needs a file")?))
            }
            "--preset" => preset = Some(PathBuf::from(it.next().context("--preset needs a file")?)),
            "--shaders" => {
                shaders = Some(PathBuf::from(it.next().context("--shaders needs a folder")?))
            }
            "--profiler" => profiler = true,
            "--limit" => load.limits.apply(&it.next().context("--limit needs NAME=VALUE")?)?,
            "--puffin-http" => {
                let port = match it.peek().and_then(|p| p.parse::<u16>().ok()) {
                    Some(p) => {
                        it.next();
                        p
                    }
                    None => puffin_http::DEFAULT_PORT,
                };
                puffin_http = Some(port);
            }
            s if s.starts_with('-') => anyhow::bail!("unknown option {s}\n{USAGE}"),
            s => scene = Some(s.to_string()),
        }
    }
    Ok(Some(Args {
        scene: scene.unwrap_or_else(|| "level".into()),
        camera_path,
        preset,
        shaders,
        puffin_http,
        profiler,
        load,
    }))
}

fn run() -> Result<()> {
    let Some(args) = parse_args()? else {
        println!("{USAGE}");
        return Ok(());
    };
    if !has_display() {
        anyhow::bail!(NO_DISPLAY);
    }
    let event_loop = EventLoop::new().map_err(|e| anyhow::anyhow!("{NO_DISPLAY}\n({e})"))?;
    let mut viewer = Viewer { args, state: None, error: None };
    event_loop.run_app(&mut viewer)?;
    match viewer.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    if let Err(e) = run() {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
