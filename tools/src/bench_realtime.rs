//! `hush-cli bench --mode realtime`: GPU time per pass of the real-time frame from timestamp
//! queries (median over frames), the frame total, and the CPU time of a frame.

use crate::bench::BenchArgs;
use crate::cli::{bvh_kind, load_scene};
use anyhow::{Result, bail};
use hush_engine::frame::{DisplayTarget, FrameInput, Renderer};
use hush_engine::profile::puffin;
use hush_engine::settings::{Denoiser, FrameSettings};
use serde::Serialize;
use std::time::Instant;

#[derive(Serialize)]
struct PassTime {
    pass: &'static str,
    median_ms: f64,
    min_ms: f64,
}

#[derive(Serialize)]
struct RealtimeResult {
    scene: String,
    adapter: String,
    triangles: usize,
    width: u32,
    height: u32,
    frames: u32,
    passes: Vec<PassTime>,
    /// Median over frames of the sum of the passes' GPU time.
    gpu_frame_median_ms: f64,
    /// Median wall time of a frame on the CPU, submit to finished (includes BVH rebuilds of
    /// animated scenes and the timestamp readback).
    cpu_frame_median_ms: f64,
    /// Median CPU time to record and submit a frame and close its profile frame (what the
    /// CPU spends besides waiting for the GPU; with --profile it includes puffin's scopes and
    /// the GPU timeline's report).
    cpu_record_median_ms: f64,
    /// Per-pixel buffers and textures of the frame, bytes per pixel: in all, and of them the
    /// histories and frame targets that outlive a frame (persistent) and the transient pools'
    /// peak (textures that live within a frame, sharing memory where their lives do not
    /// overlap).
    bytes_per_pixel: f64,
    persistent_bytes_per_pixel: f64,
    transient_bytes_per_pixel: f64,
    /// The upscaler's shown-size targets (0 where it does not run).
    upscale_bytes: u64,
    /// Every per-pixel target of the frame, the scene's tables and the upscaler's, in bytes.
    total_bytes: u64,
    allocations: Vec<(String, u64)>,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    if v.is_empty() { 0.0 } else { v[v.len() / 2] }
}

pub fn run(a: &BenchArgs) -> Result<()> {
    if a.frames == 0 {
        bail!("--frames must be at least 1");
    }
    if let Some(p) = &a.profile {
        crate::cli::check_output(p, &["puffin"], "--profile")?;
    }
    let scene = load_scene(&a.scene, &a.load)?;
    let shown = (a.width, a.height);
    let size = match a.scale {
        None => shown,
        Some(s) if (0.1..=1.0).contains(&s) => crate::realtime::scaled(shown, s),
        Some(s) => bail!("--scale {s}: use 0.1 to 1"),
    };
    let instancing = crate::bench::instancing(&a.instancing)?;
    let (gpu, mut r) = Renderer::headless_with(scene, bvh_kind(&a.bvh)?, instancing, size)?;
    if a.cpu_posing {
        r.set_gpu_posing(&gpu, false)?;
    }
    r.show_at(Some(shown))?;
    if !gpu.timestamps {
        bail!(
            "adapter {} has no timestamp queries; per-pass GPU times are not available",
            gpu.info.name
        );
    }
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let tex = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("bench display target"),
        size: wgpu::Extent3d { width: shown.0, height: shown.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let view = tex.create_view(&Default::default());
    let target = DisplayTarget { view: &view, format, size: shown };
    let settings = match &a.preset {
        Some(p) => FrameSettings {
            max_depth: crate::cli::path_length(None, Some(p), r.scene.max_depth)?,
            ..crate::cli::preset_settings(Some(p), a.denoiser.as_deref(), &[], None)?
        },
        None => FrameSettings {
            max_depth: r.scene.max_depth,
            ..crate::cli::denoiser_settings(
                a.denoiser.as_deref().unwrap_or(Denoiser::MARA.name()),
                &[],
                "diamond",
            )?
        },
    };
    let camera = match &a.camera {
        Some(c) => crate::cli::parse_camera(c)?,
        None => r.scene.camera_or_default(),
    };
    let mut per_pass: Vec<(&'static str, Vec<f64>)> = vec![];
    let (mut totals, mut cpu, mut record) = (vec![], vec![], vec![]);
    let mut capture = None;
    // Two warm-up frames compile pipelines and fill caches.
    for k in 0..a.frames + 2 {
        if k == 2 && a.profile.is_some() {
            capture = Some(hush_engine::profile::Capture::start(a.frames as usize));
        }
        let input = FrameInput { camera, time: k as f64 / 60.0, shutter: None };
        if a.rescale {
            let shrunk = ((size.0 * 7 / 8).max(1), (size.1 * 7 / 8).max(1));
            r.resize(&gpu, if k % 2 == 0 { size } else { shrunk })?;
        }
        let start = Instant::now();
        {
            puffin::profile_scope!("frame");
            r.render(&gpu, &input, &settings, Some(&target))?;
        }
        let recorded = start.elapsed();
        let spans = r.pass_spans(&gpu)?;
        if r.untimed_passes() > 0 {
            bail!(
                "{} passes of the frame found no timestamp slot; their time would be missing from the totals",
                r.untimed_passes()
            );
        }
        let closing = Instant::now();
        hush_engine::profile::end_frame();
        let recorded = (recorded + closing.elapsed()).as_secs_f64() * 1e3;
        // One time per label and frame: an a-trous stage's levels share its label.
        let times = hush_engine::profile::per_label(&spans);
        let wall = start.elapsed().as_secs_f64() * 1e3;
        if k < 2 {
            continue;
        }
        cpu.push(wall);
        record.push(recorded);
        totals.push(times.iter().map(|t| t.1).sum());
        for (name, ms) in times {
            match per_pass.iter_mut().find(|p| p.0 == name) {
                Some(p) => p.1.push(ms),
                None => per_pass.push((name, vec![ms])),
            }
        }
    }
    let passes = per_pass
        .into_iter()
        .map(|(pass, mut v)| PassTime {
            pass,
            min_ms: v.iter().cloned().fold(f64::MAX, f64::min),
            median_ms: median(&mut v),
        })
        .collect();
    if let (Some(c), Some(path)) = (capture, &a.profile) {
        let n = c.write(path)?;
        eprintln!("wrote {n} profiled frames to {}", path.display());
    }
    let res = RealtimeResult {
        scene: a.scene.clone(),
        adapter: gpu.info.name.clone(),
        triangles: r.prepared.triangle_count(),
        width: size.0,
        height: size.1,
        frames: a.frames,
        passes,
        gpu_frame_median_ms: median(&mut totals),
        cpu_frame_median_ms: median(&mut cpu),
        cpu_record_median_ms: median(&mut record),
        bytes_per_pixel: r.bytes_per_pixel(),
        persistent_bytes_per_pixel: r.bytes_per_pixel() - r.transient_bytes_per_pixel(),
        transient_bytes_per_pixel: r.transient_bytes_per_pixel(),
        upscale_bytes: r.upscale_bytes(),
        total_bytes: r.allocations().iter().map(|(_, b)| b).sum(),
        allocations: r.allocations(),
    };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&res)?);
    } else {
        println!(
            "{} ({} triangles) at {}x{} on {}, median of {} frames",
            res.scene, res.triangles, res.width, res.height, res.adapter, res.frames
        );
        for p in &res.passes {
            println!("  {:10} {:8.3} ms (min {:.3})", p.pass, p.median_ms, p.min_ms);
        }
        println!(
            "  GPU frame  {:8.3} ms; CPU frame {:.3} ms (recording {:.3} ms); {:.0} bytes/pixel",
            res.gpu_frame_median_ms,
            res.cpu_frame_median_ms,
            res.cpu_record_median_ms,
            res.bytes_per_pixel
        );
        println!(
            "  memory     {:.0} bytes/pixel persistent + {:.0} transient peak = {:.0} in all",
            res.persistent_bytes_per_pixel, res.transient_bytes_per_pixel, res.bytes_per_pixel
        );
        if res.upscale_bytes > 0 {
            println!(
                "  upscaler   {:.0} bytes per shown pixel ({}x{} shown); frame and scene {:.1} MB in all",
                res.upscale_bytes as f64 / (shown.0 as f64 * shown.1 as f64),
                shown.0,
                shown.1,
                res.total_bytes as f64 / 1e6
            );
        }
    }
    Ok(())
}
