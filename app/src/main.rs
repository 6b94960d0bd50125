//! `hush`: the viewer. Opens a window on a scene (the built-in one without an argument) and
//! shows the reference path tracer converging, one sample per pixel per frame.

mod display;

use anyhow::{Context, Result};
use hush_engine::accel::BvhKind;
use hush_engine::gpu::{Gpu, GpuScene, PreparedScene};
use hush_engine::passes::{ReferenceTracer, TraceView};
use hush_engine::scene::Scene;
use std::sync::Arc;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, KeyEvent, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

const NO_DISPLAY: &str = "hush needs a display (no X11 or Wayland display was found). To render \
without a window use the command-line tool, e.g.\n    hush-cli render default --spp 64 --out image.png";

struct Viewer {
    scene: Scene,
    prepared: PreparedScene,
    state: Option<Running>,
    error: Option<anyhow::Error>,
}

struct Running {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: Gpu,
    gscene: GpuScene,
    tracer: ReferenceTracer,
    display: display::Display,
}

impl Viewer {
    fn start(&mut self, el: &ActiveEventLoop) -> Result<()> {
        let attrs = Window::default_attributes()
            .with_title(format!("Hush: {}", self.scene.name))
            .with_inner_size(winit::dpi::LogicalSize::new(960.0, 540.0));
        let window = Arc::new(el.create_window(attrs).context("creating the window")?);
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let surface = instance.create_surface(window.clone()).context("creating the window surface")?;
        let size = window.inner_size();
        // The accumulation buffer is 32 bytes per pixel; allow the window to grow to four times
        // its first area before the device's binding limit would need raising.
        let accum_bytes = size.width.max(1) as u64 * size.height.max(1) as u64 * 32 * 4;
        let gpu = Gpu::for_surface(instance, &surface, &self.prepared.requirements(accum_bytes))?;
        let caps = surface.get_capabilities(&gpu.adapter);
        let format = caps.formats.first().copied().context("the surface offers no format")?;
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            desired_maximum_frame_latency: 2,
            color_space: Default::default(),
        };
        surface.configure(&gpu.device, &config);
        let gscene = self.prepared.upload(&gpu);
        let tracer = ReferenceTracer::new(&gpu, &self.prepared, &gscene, &self.view(config.width, config.height))?;
        let display = display::Display::new(&gpu, format, &tracer)?;
        self.state = Some(Running { window, surface, config, gpu, gscene, tracer, display });
        Ok(())
    }

    fn view(&self, width: u32, height: u32) -> TraceView {
        TraceView { camera: self.scene.camera_or_default(), width, height, max_depth: self.scene.max_depth, seed: 0 }
    }

    fn resize(&mut self, w: u32, h: u32) -> Result<()> {
        let view = self.view(w, h);
        let Some(s) = &mut self.state else { return Ok(()) };
        if w == 0 || h == 0 {
            return Ok(()); // minimized: keep everything, render nothing
        }
        s.config.width = w;
        s.config.height = h;
        s.surface.configure(&s.gpu.device, &s.config);
        s.tracer = ReferenceTracer::new(&s.gpu, &self.prepared, &s.gscene, &view)?;
        s.display = display::Display::new(&s.gpu, s.config.format, &s.tracer)?;
        Ok(())
    }

    fn frame(&mut self) -> Result<()> {
        let Some(s) = &mut self.state else { return Ok(()) };
        if s.config.width == 0 || s.config.height == 0 || s.window.is_minimized() == Some(true) {
            return Ok(());
        }
        s.tracer.dispatch(&s.gpu, 1);
        let frame = match s.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f) | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                s.surface.configure(&s.gpu.device, &s.config);
                return Ok(());
            }
            other => {
                log::warn!("surface: {other:?}");
                return Ok(());
            }
        };
        s.display.draw(&s.gpu, &s.tracer, &frame.texture);
        s.gpu.queue.present(frame);
        s.window.set_title(&format!("Hush: {} - reference, {} spp", self.scene.name, s.tracer.samples));
        s.window.request_redraw();
        Ok(())
    }
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.state.is_none() {
            if let Err(e) = self.start(el) {
                self.error = Some(e);
                el.exit();
            }
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let r = match event {
            WindowEvent::CloseRequested => {
                el.exit();
                Ok(())
            }
            WindowEvent::KeyboardInput { event: KeyEvent { logical_key: Key::Named(NamedKey::Escape), state: ElementState::Pressed, .. }, .. } => {
                el.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => self.resize(size.width, size.height),
            WindowEvent::RedrawRequested => self.frame(),
            _ => Ok(()),
        };
        if let Err(e) = r {
            self.error = Some(e);
            el.exit();
        }
    }
}

fn has_display() -> bool {
    if cfg!(target_os = "linux") || cfg!(target_os = "freebsd") {
        return ["DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"].iter().any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()));
    }
    true
}

fn run() -> Result<()> {
    let arg = std::env::args().nth(1);
    if matches!(arg.as_deref(), Some("-h" | "--help")) {
        println!("usage: hush [SCENE.gltf|SCENE.glb]   (no argument: the built-in scene)");
        return Ok(());
    }
    if !has_display() {
        anyhow::bail!(NO_DISPLAY);
    }
    let mut scene = Scene::load(arg.as_deref().unwrap_or("default"))?;
    scene.add_sun_and_sky_if_unlit();
    let prepared = PreparedScene::new(&scene, BvhKind::DEFAULT)?;
    let event_loop = EventLoop::new().map_err(|e| anyhow::anyhow!("{NO_DISPLAY}\n({e})"))?;
    let mut viewer = Viewer { scene, prepared, state: None, error: None };
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
