//! `hush`: the viewer. Opens a window on a scene (the default level without an argument) and
//! shows the real-time frame, with a fly camera and a side panel of settings and debug views.

mod fly;
mod profiler;
mod running;
mod settings_ui;
mod ui;

use anyhow::{Context, Result};
use hush_engine::accel::BvhKind;
use hush_engine::frame::{DisplayTarget, FrameInput, Renderer};
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::profile::puffin;
use hush_engine::scene::{CameraKey, CameraPath, Scene};
use hush_engine::shader::{ShaderLibrary, ShaderWatcher, source_tree_dir};
use running::Running;
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
            [--limit NAME=VALUE[,NAME=VALUE...]] [--animation INDEX] [--paused]
  no scene: the default level. Keys: WASD move, Q/E down/up, right-drag look, wheel speed,
  shift run, middle-click focus the depth of field there, F12 screenshot (PNG + EXR),
  R record a camera path, P play it, F9 profiler,
  F10 capture frames to a .puffin file, Esc quit. Drop a .gltf/.glb on the window to load it.
  Shaders reload when their files change: debug builds read the source tree's shaders/,
  release builds embed them unless --shaders DIR or $HUSH_SHADERS names a folder.
  --profiler opens the profiler window at start; --puffin-http serves profiles to puffin_viewer on 127.0.0.1 (default port 8585).
  --limit sets a budget on what a scene file may make Hush read and build (file-bytes, json-bytes,
  image-pixels, decoded-bytes, nodes, hierarchy-depth, triangles); a file over one is refused.
  --animation plays only that one of the file's animations (by index); without it all play.
  --paused starts with the animation paused at its first frame (a still view to compare with a
  reference rendered at --time 0).";

struct Args {
    scene: String,
    camera_path: Option<PathBuf>,
    preset: Option<PathBuf>,
    shaders: Option<PathBuf>,
    puffin_http: Option<u16>,
    profiler: bool,
    /// Start with the animation paused at time 0.
    paused: bool,
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
            // A software rasterizer draws the upscaler's raster at the window's size as slowly
            // as sixteen of the frame's at scale 0.25.
            taa: hush_engine::settings::TaaSettings {
                upscale_materials: gpu.info.device_type != wgpu::DeviceType::Cpu,
                ..Default::default()
            },
            ..Default::default()
        },
        resolution_scale: 1.0,
        sun: r.scene.sun_direction().map(ui::sun_angles),
        paused: false,
        time: 0.0,
        animation_length: r.scene.animation_length(),
        animations: r.scene.animations.clone(),
        animation: None,
        animation_request: None,
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
            still_ratio: hush_engine::governor::STILL_RATIO,
            pin_scale: false,
            pin_fraction: false,
            choice: String::new(),
        },
        lens: ui::LensPanel::new(r.scene.camera_or_default().lens, r.prepared.extent),
    }
}

/// The denoiser the viewer starts with: on a software rasterizer the progressive filter, whose
/// sample fractions below 1 let the governor hold its target at a larger scale than a filter
/// that needs every pixel each frame; on a GPU SVGF, which measures best in a still view
/// (docs/decisions.md, "Default denoiser").
fn default_denoiser(gpu: &Gpu) -> hush_engine::settings::Denoiser {
    if gpu.info.device_type == wgpu::DeviceType::Cpu {
        hush_engine::settings::Denoiser::PROGRESSIVE
    } else {
        hush_engine::settings::Denoiser::SVGF
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
        panel.animation = self.args.load.animation;
        panel.paused = self.args.paused;
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
            source: self.args.scene.clone(),
        });
        Ok(())
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
    let mut paused = false;
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
            "--paused" => paused = true,
            "--limit" => load.limits.apply(&it.next().context("--limit needs NAME=VALUE")?)?,
            "--animation" => {
                let i = it.next().context("--animation needs an index")?;
                load.animation = Some(i.parse().with_context(|| {
                    format!("--animation {i}: an animation's index (0, 1, ...)")
                })?);
            }
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
        paused,
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
