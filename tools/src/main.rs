//! `hush-cli`: headless rendering, image comparison and benchmarks.

mod bench;
mod compare;
mod realtime;
mod render;

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
    /// Measure BVH build, rays per second and reference-tracer samples per second.
    Bench(bench::BenchArgs),
}

fn main() {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let r: Result<()> = match cli.command {
        Command::Render(a) => render::run(a),
        Command::Compare(a) => compare::run(a),
        Command::Bench(a) => bench::run(a),
    };
    if let Err(e) = r {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
