//! `hush-cli`: headless rendering, image comparison and benchmarks.

mod bench;
mod bench_animate;
mod bench_realtime;
mod cli;
mod compare;
mod conformance;
mod convergence;
mod quality;
mod quality_args;
mod realtime;
mod reference;
mod reflections;
mod render;
mod sweep;
mod time_to_quality;

use anyhow::Result;
use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "hush-cli", version, about = "Hush: render, compare and benchmark headless")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene (a .gltf/.glb file, or `default`) to EXR (linear HDR) or PNG (tone-mapped).
    Render(render::RenderArgs),
    /// Compare an image with a reference: RMSE, relMSE, SSIM, FLIP, non-finite pixels.
    Compare(compare::CompareArgs),
    /// Load and render every glTF file under a folder (e.g. the Khronos sample models) in both
    /// modes: which load, which are refused and why, which render wrong; CSV and images.
    Conformance(conformance::ConformanceArgs),
    /// Score a denoised stream against per-frame references: CSV, plot, ablations.
    Quality(quality::QualityArgs),
    /// Time to quality: FLIP on screen against wall-clock seconds since the camera stopped
    /// (after a strafe, and after a cut), per denoiser, sample rate and governor: CSV, plot.
    TimeToQuality(time_to_quality::TimeToQualityArgs),
    /// Reflection reprojection: temporal error, FLIP and ghosting under a strafe, motion vector
    /// accuracy against a brute-force search (Voorhuis §7.3-7.4).
    Reflections(reflections::ReflectionsArgs),
    /// The speed/accuracy sweep: resolution scale, paths per pixel, path length, denoiser.
    Sweep(sweep::SweepArgs),
    /// Write the default level (built in code) as glTF: LEVEL.gltf, .bin, PNG textures, EXR sky.
    Level(LevelArgs),
    /// Measure BVH build, rays/s and reference samples/s, or (--mode realtime) GPU time per pass.
    Bench(bench::BenchArgs),
    /// Print SVGF's frame graph as Markdown: its passes with what each reads and writes, the
    /// transient pool's slots with the textures each holds in turn, and the histories.
    Graph(GraphArgs),
}

#[derive(clap::Args)]
struct GraphArgs {
    /// The graph of a scene without a specular lobe (the matte signal alone).
    #[arg(long)]
    matte_only: bool,
}

fn graph(a: GraphArgs) -> Result<()> {
    let g = hush_engine::denoise::svgf::frame_graph(!a.matte_only);
    print!("{}", g.describe(&g.plan()?));
    Ok(())
}

#[derive(clap::Args)]
struct LevelArgs {
    /// Output .gltf (side files are written beside it).
    #[arg(long, default_value = "assets/level/level.gltf")]
    out: std::path::PathBuf,
    /// The built-in scene to write instead of the level (`default`, `reflections`, `spheres`,
    /// `terrain:N`), e.g. to load the same geometry into another renderer or an older build.
    #[arg(long, default_value = "level")]
    scene: String,
}

fn level(a: LevelArgs) -> Result<()> {
    if let Some(dir) = a.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("creating {}: {e}", dir.display()))?;
    }
    let scene = hush_engine::scene::builtin_scene(&a.scene).ok_or_else(|| {
        anyhow::anyhow!(
            "--scene {:?}: no such built-in scene (one of {:?}, terrain:N with N from 2 to {} or crowd:N with N from 1 to {})",
            a.scene,
            hush_engine::scene::BUILTIN_SCENES,
            hush_engine::scene::MAX_TERRAIN_TRIANGLES,
            hush_engine::scene::MAX_CROWD
        )
    })?;
    hush_engine::scene::save_gltf(&scene, &a.out)?;
    eprintln!(
        "wrote {} ({} triangles, {} objects)",
        a.out.display(),
        scene.triangle_count(),
        scene.objects.len()
    );
    Ok(())
}

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let r: Result<()> = match cli.command {
        Command::Render(a) if a.mode == "realtime" => realtime::run(a),
        Command::Render(a) => render::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Conformance(a) => conformance::run(a),
        Command::Bench(a) if a.mode == "realtime" => bench_realtime::run(&a),
        Command::Bench(a) if a.mode == "animate" => bench_animate::run(&a),
        Command::Bench(a) => bench::run(a),
        Command::Level(a) => level(a),
        Command::Graph(a) => graph(a),
        Command::Quality(a) => quality::run(a),
        Command::TimeToQuality(a) => time_to_quality::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Reflections(a) => reflections::run(a),
    };
    if let Err(e) = r {
        eprintln!("error: {e:#}");
        report_peak_memory();
        std::process::exit(1);
    }
    report_peak_memory();
}

/// With `HUSH_PEAK_MEMORY` set, print the process's peak resident memory (Linux's VmHWM) on
/// exit: how the hostile-input tests bound what a file can make Hush claim. A parent's rusage
/// cannot tell it, as a child's maxrss starts from the parent's resident size at spawn.
fn report_peak_memory() {
    if std::env::var_os("HUSH_PEAK_MEMORY").is_none() {
        return;
    }
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    match status.lines().find_map(|l| l.strip_prefix("VmHWM:")) {
        Some(kib) => eprintln!("peak memory: {} kB", kib.trim().trim_end_matches("kB").trim()),
        None => eprintln!("peak memory: unknown"),
    }
}
