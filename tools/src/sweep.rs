//! `hush-cli sweep`: the speed/accuracy trade. Presets over resolution scale, indirect paths per
//! pixel or samples per pixel, path length and denoiser (none, mara, svgf); each point's GPU milliseconds per frame (median of the
//! second half of its frames) and FLIP against the converged image after those frames (a still
//! camera). Writes sweep.csv and pareto.png and prints the table with the Pareto front marked.

use crate::cli::{bvh_kind, image_size, load_scene, parse_camera};
use anyhow::{Context, Result, bail};
use clap::Args;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::quality::compare;
use hush_engine::settings::{Denoiser, FrameSettings};
use std::io::Write;
use std::path::PathBuf;

#[derive(Args)]
pub struct SweepArgs {
    pub scene: String,
    #[arg(long)]
    pub camera: Option<String>,
    /// Full-resolution width (the reference's); scales 0.5 and 1 of it are swept.
    #[arg(long, default_value_t = 320)]
    pub width: u32,
    /// Frames rendered per point before it is scored.
    #[arg(long, default_value_t = 30)]
    pub frames: u32,
    #[arg(long, default_value_t = 256)]
    pub reference_frames: u32,
    #[arg(long)]
    pub out_dir: PathBuf,
    #[command(flatten)]
    pub load: crate::cli::LoadArgs,
}

struct Point {
    scale: f32,
    paths: u32,
    /// Samples per pixel (guide rays, Voorhuis §5).
    samples: u32,
    max_depth: i32,
    denoiser: Denoiser,
    ms: f64,
    flip: f64,
    pareto: bool,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

pub fn run(a: SweepArgs) -> Result<()> {
    crate::cli::check_output_dir(&a.out_dir, "--out-dir")?;
    if a.frames < 2 || a.reference_frames == 0 {
        bail!("--frames must be at least 2 and --reference-frames at least 1");
    }
    let scene = load_scene(&a.scene, &a.load)?;
    let full = image_size(&scene, Some(a.width & !1), None);
    let full = (full.0, full.1 & !1);
    let camera = match &a.camera {
        Some(c) => parse_camera(c)?,
        None => scene.camera_or_default(),
    };
    let input = FrameInput { camera, time: 0.0, shutter: None };
    std::fs::create_dir_all(&a.out_dir)
        .with_context(|| format!("creating {}", a.out_dir.display()))?;
    let prepared = PreparedScene::new(&scene, bvh_kind(&None)?)?;
    let gpu = Gpu::headless(&prepared.realtime_requirements(full))?;
    let depth = scene.max_depth;
    let mut reference_r = Renderer::new(&gpu, scene.clone(), prepared, full)?;
    let acc =
        FrameSettings { accumulate: true, seed: 7919, max_depth: depth, ..Default::default() };
    for _ in 0..a.reference_frames {
        reference_r.render(&gpu, &input, &acc, None)?;
    }
    let reference = reference_r.read_hdr(&gpu)?;
    drop(reference_r);

    let mut points = vec![];
    for scale in [0.5f32, 1.0] {
        let size = ((full.0 as f32 * scale) as u32, (full.1 as f32 * scale) as u32);
        let mut r = Renderer::new(
            &gpu,
            scene.clone(),
            PreparedScene::new(&scene, bvh_kind(&None)?)?,
            size,
        )?;
        // A lower resolution is scored against the reference box-filtered to its size.
        let target = if size == full {
            reference.clone()
        } else {
            reference.box_downsample(full.0 / size.0)?
        };
        for denoiser in [Denoiser::NONE, Denoiser::MARA, Denoiser::SVGF] {
            // More paths at one primary hit, or (one path) more samples per pixel.
            for (paths, samples) in [(1u32, 1u32), (2, 1), (4, 1), (1, 4)] {
                for max_depth in [3, depth] {
                    let s = FrameSettings {
                        denoiser: denoiser.clone(),
                        paths_per_pixel: paths,
                        samples_per_pixel: samples,
                        max_depth,
                        ..Default::default()
                    };
                    // One raw frame between points: the denoiser's history starts over.
                    r.render(&gpu, &input, &FrameSettings::default(), None)?;
                    let mut ms = vec![];
                    for k in 0..a.frames {
                        r.render(&gpu, &input, &s, None)?;
                        let t: f64 = r.pass_times(&gpu)?.iter().map(|p| p.1).sum();
                        if k >= a.frames / 2 {
                            ms.push(t);
                        }
                    }
                    let flip = compare(&r.read_hdr(&gpu)?, &target)?.flip as f64;
                    points.push(Point {
                        scale,
                        paths,
                        samples,
                        max_depth,
                        denoiser: denoiser.clone(),
                        ms: median(ms),
                        flip,
                        pareto: false,
                    });
                }
            }
        }
    }
    // Pareto front: no other point is both faster and more accurate.
    for i in 0..points.len() {
        points[i].pareto = !points.iter().any(|q| {
            q.ms <= points[i].ms && q.flip < points[i].flip
                || q.ms < points[i].ms && q.flip <= points[i].flip
        });
    }
    let mut f = std::fs::File::create(a.out_dir.join("sweep.csv"))?;
    writeln!(
        f,
        "resolution_scale,paths_per_pixel,samples_per_pixel,max_depth,denoiser,gpu_ms,flip,pareto"
    )?;
    println!(
        "{} at {}x{} full resolution, {} frames per point, on {}",
        a.scene, full.0, full.1, a.frames, gpu.info.name
    );
    println!("  scale  paths  spp  depth  denoiser   GPU ms   FLIP    Pareto");
    points.sort_by(|p, q| p.ms.total_cmp(&q.ms));
    for p in &points {
        let d = p.denoiser.name();
        writeln!(
            f,
            "{},{},{},{},{d},{:.3},{:.5},{}",
            p.scale, p.paths, p.samples, p.max_depth, p.ms, p.flip, p.pareto
        )?;
        println!(
            "  {:5.2}  {:5}  {:3}  {:5}  {d:8} {:8.2}  {:.4}  {}",
            p.scale,
            p.paths,
            p.samples,
            p.max_depth,
            p.ms,
            p.flip,
            if p.pareto { "*" } else { "" }
        );
    }
    plot(&a.out_dir.join("pareto.png"), &points, &a.scene)
}

fn plot(path: &std::path::Path, points: &[Point], title: &str) -> Result<()> {
    use plotters::prelude::*;
    let _ = plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    );
    let e = |e: &dyn std::fmt::Display| anyhow::anyhow!("plot: {e}");
    let root = BitMapBackend::new(path, (960, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let xmax = points.iter().map(|p| p.ms).fold(1.0, f64::max) * 1.1;
    let ymax = points.iter().map(|p| p.flip).fold(0.01, f64::max) * 1.1;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{title}: speed against accuracy"), ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..xmax, 0.0..ymax)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("GPU ms per frame")
        .y_desc("FLIP against the converged image")
        .draw()
        .map_err(|x| e(&x))?;
    for (den, color) in [(Denoiser::NONE, RED), (Denoiser::MARA, BLUE), (Denoiser::SVGF, GREEN)] {
        let name = format!("denoiser: {}", den.name());
        chart
            .draw_series(points.iter().filter(|p| p.denoiser == den).map(|p| {
                Circle::new((p.ms, p.flip), 4 + 2 * (p.scale >= 1.0) as i32, color.filled())
            }))
            .map_err(|x| e(&x))?
            .label(name)
            .legend(move |(x, y)| Circle::new((x + 10, y), 4, color.filled()));
    }
    let mut front: Vec<(f64, f64)> =
        points.iter().filter(|p| p.pareto).map(|p| (p.ms, p.flip)).collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart
        .draw_series(LineSeries::new(front, &BLACK))
        .map_err(|x| e(&x))?
        .label("Pareto front")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))?;
    Ok(())
}
