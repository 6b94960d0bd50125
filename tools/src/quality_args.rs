//! `hush-cli quality`'s arguments, shared by its stream scoring (quality.rs) and its still-view
//! convergence (convergence.rs).

use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct QualityArgs {
    /// A .gltf/.glb file, `default` or `level`.
    pub scene: String,
    #[arg(long)]
    pub camera_path: Option<PathBuf>,
    /// A still camera, "eye=x,y,z;target=x,y,z;fov=deg" (default: the scene's).
    #[arg(long)]
    pub camera: Option<String>,
    #[arg(long, default_value_t = 60)]
    pub frames: u32,
    /// `none`, `mara`, `svgf` or `progressive`; default mara, or the preset's.
    #[arg(long)]
    pub denoiser: Option<String>,
    /// Start from the settings of this preset file (TOML); --denoiser, --disable and
    /// --reflection-mv then override it.
    #[arg(long)]
    pub preset: Option<PathBuf>,
    /// Stages to switch off (see `render --disable`).
    #[arg(long, value_delimiter = ',')]
    pub disable: Vec<String>,
    /// Reflection motion vectors of the glossy chain (see `render --reflection-mv`).
    /// Default diamond, or the preset's.
    #[arg(long)]
    pub reflection_mv: Option<String>,
    /// Frames accumulated for each frame's reference.
    #[arg(long, default_value_t = 256)]
    pub reference_frames: u32,
    #[arg(long, default_value_t = 320)]
    pub width: u32,
    #[arg(long)]
    pub height: Option<u32>,
    /// Animation clock rate for a still camera (frame k is at k / fps seconds); 0 freezes it.
    #[arg(long, default_value_t = 0.0)]
    pub fps: f64,
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Also run the stream with each denoiser stage off.
    #[arg(long)]
    pub ablations: bool,
    /// Instead of the stream: run each of --denoisers and the plain accumulation of the same
    /// frames over --frames frames of the still view, and write convergence.csv and
    /// convergence.png (FLIP and relMSE against frames on log axes, 1 to --frames).
    #[arg(long)]
    pub convergence: bool,
    /// The denoisers --convergence compares with the accumulation.
    #[arg(long, value_delimiter = ',', default_value = "svgf,mara,progressive")]
    pub denoisers: Vec<String>,
    /// With --convergence: score against this image (an EXR, e.g. a Mitsuba render of the
    /// scene) instead of the accumulated real-time frame.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    #[arg(long)]
    pub out_dir: PathBuf,
    /// Keep each reference as an EXR in this folder, named by what it depends on (scene file,
    /// size, camera, time, reference frames, seed, path length), and reuse it when a later run
    /// asks for the same one: a converged reference of an interior takes thousands of frames,
    /// and comparing settings needs it only once.
    #[arg(long)]
    pub reference_cache: Option<PathBuf>,
    /// Independent 64-frame accumulations (different seeds) averaged into the yardstick's FLIP.
    /// One accumulation is a poor yardstick where rare bright paths dominate the error:
    /// FlightHelmet at 160x90 measured 0.0055 to 0.0089 over five seeds.
    #[arg(long, default_value_t = 4)]
    pub yardstick_seeds: u32,
    #[command(flatten)]
    pub load: crate::cli::LoadArgs,
}
