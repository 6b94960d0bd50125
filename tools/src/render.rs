use crate::cli::{
    LoadArgs, Spp, bvh_kind, check_output, check_sides, image_size, load_scene, parse_camera,
    parse_spp,
};
use anyhow::{Context, Result, bail};
use clap::Args;
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::passes::{ReferenceTracer, TraceView};
use std::io::IsTerminal;
use std::path::PathBuf;

#[derive(Args)]
pub struct RenderArgs {
    /// A .gltf/.glb file, `default` for the built-in room or `level` for the default level.
    pub scene: String,
    /// `reference` (progressive path tracing) or `realtime` (the hybrid frame).
    #[arg(long, default_value = "reference")]
    pub mode: String,
    /// Real-time mode: frames to render (default 1).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Real-time mode: a camera path (JSON, as the viewer records); frame k uses key k.
    #[arg(long)]
    pub camera_path: Option<PathBuf>,
    /// Real-time mode: the denoiser, `none`, `mara` (Mara et al. 2017: matte and glossy
    /// chains), `svgf` (SVGF with Voorhuis's extensions) or `progressive` (Dundr's filter, for
    /// sample fractions below 1), each followed by TAA; default svgf, or the preset's.
    #[arg(long)]
    pub denoiser: Option<String>,
    /// Real-time mode: start from the settings of this preset file (TOML, as the viewer saves);
    /// --denoiser, --disable and --reflection-mv then override it.
    #[arg(long)]
    pub preset: Option<PathBuf>,
    /// Real-time mode: stages to switch off, comma-separated, by their names (matte/temporal,
    /// matte/history_bilateral, matte/disocclusion, matte/firefly, matte/bilateral, taa,
    /// glossy/temporal, glossy/bilateral; svgf/temporal, svgf/temporal_glossy, svgf/variance,
    /// svgf/atrous; progressive/temporal, progressive/atrous), and switches that cover several
    /// stages or part of one by their settings (glossy.clipping, glossy.hit_test;
    /// svgf.accumulated_moments, svgf.bandwidth_boost, svgf.firefly,
    /// svgf.reflection_reprojection, svgf.clipping, svgf.mirror_features, svgf.hit_test). An
    /// unknown name's error lists them all.
    #[arg(long, value_delimiter = ',')]
    pub disable: Vec<String>,
    /// Real-time mode: how the glossy chain reprojects reflections: diamond (Voorhuis's search),
    /// virtual (Mara's virtual position) or primary (surface motion only).
    /// Default diamond, or the preset's.
    #[arg(long)]
    pub reflection_mv: Option<String>,
    /// Real-time mode: sum all frames with a still camera and write their mean.
    #[arg(long)]
    pub accumulate: bool,
    /// Real-time mode with a thin-lens camera: primary rays traced per pixel for the G-buffer
    /// (default 4, or the preset's; at most 256).
    #[arg(long)]
    pub primary_samples: Option<u32>,
    /// Real-time mode with a thin-lens camera: leave the traced G-buffer unfiltered (no Moon et
    /// al. 2017 pre-filter).
    #[arg(long)]
    pub no_prefilter: bool,
    /// Real-time mode: pose deforming meshes (skins, morph targets) and refit their BVH on the
    /// CPU, uploading their triangles every frame, instead of in the GPU's posing pass.
    #[arg(long)]
    pub cpu_posing: bool,
    /// Real-time mode: hold this frame time (ms) with the governor, which picks the resolution
    /// scale and (for denoisers that fill untraced pixels) the sample fraction each frame, and
    /// where nothing else fits, fewer a-trous levels; with --out-dir, writes frames.csv (frame,
    /// wall_ms, gpu_ms, spp, width, height, levels). --spp pins the fraction.
    #[arg(long)]
    pub target_ms: Option<f64>,
    /// Real-time mode with --target-ms: the smallest resolution scale per side (default 0.25).
    #[arg(long)]
    pub min_scale: Option<f32>,
    /// Real-time mode: trace at this resolution scale per side (0.1 to 1) and show the frame at
    /// --width x --height, reconstructed by the temporal upscaler (`taa.upscale`; off, or with
    /// --denoiser none, the image is stretched). The images written are at the shown size.
    #[arg(long)]
    pub scale: Option<f32>,
    /// Frames per second of the animation clock when no camera path gives times (default 60);
    /// the frame interval the shutter is a fraction of.
    #[arg(long)]
    pub fps: Option<f64>,
    /// Motion blur: the shutter stays open for this fraction of the frame interval (0 to 1,
    /// default 0: an instant), ending at the frame's time; each sample sees the camera and the
    /// scene's animation at a random time in it. Both modes (real-time mode then traces its
    /// primaries).
    #[arg(long)]
    pub shutter: Option<f64>,
    /// Reference mode: the scene's animation time (seconds) of the image (default 0).
    #[arg(long)]
    pub time: Option<f64>,
    /// Real-time mode: write what the display shows for this view (final, gbuffer/normal,
    /// trace/matte, ...; see the viewer's list) to the --out PNG instead of the HDR image.
    #[arg(long)]
    pub view: Option<String>,
    /// Real-time mode: write every frame as linear HDR EXR into this folder (frame_00000.exr, ...).
    #[arg(long)]
    pub out_dir: Option<PathBuf>,
    /// Samples per pixel. Reference mode: the progressive tracer's (default 64). Real-time mode:
    /// per frame, the raster's guide and k - 1 traced samples mixed into their most similar
    /// guides (Voorhuis §5; default 1, at most 16), or a fraction 1/N (N = 2, 4, ... 128): each
    /// frame traces one pixel in N (Dundr §5).
    #[arg(long, value_parser = parse_spp)]
    pub spp: Option<Spp>,
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub width: Option<u32>,
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub height: Option<u32>,
    /// Path length as Mitsuba counts it (2 = direct light only, -1 = unbounded).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(i32).range(-1..=65536))]
    pub max_depth: Option<i32>,
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// "eye=x,y,z;target=x,y,z;fov=deg" (fov is vertical, in degrees); add ";aperture=r;focus=d"
    /// (meters) for a thin lens (depth of field in both modes).
    #[arg(long)]
    pub camera: Option<String>,
    /// BVH layout: bvh2 or cwbvh.
    #[arg(long)]
    pub bvh: Option<String>,
    #[command(flatten)]
    pub load: LoadArgs,
    /// Output: .exr (linear HDR RGB float) or .png (tone-mapped sRGB). In real-time mode, the
    /// last frame.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// `--shutter` as a fraction of the frame interval (0 if not given).
pub fn shutter(a: &RenderArgs) -> Result<f64> {
    match a.shutter {
        None => Ok(0.0),
        Some(s) if (0.0..=1.0).contains(&s) => Ok(s),
        Some(s) => bail!(
            "--shutter {s}: give the fraction of the frame interval the shutter is open, 0 to 1"
        ),
    }
}

/// `--fps` (60 if not given).
pub fn fps(a: &RenderArgs) -> Result<f64> {
    let fps = a.fps.unwrap_or(60.0);
    if !(fps > 0.0 && fps.is_finite()) {
        bail!("--fps must be a positive number");
    }
    Ok(fps)
}

pub fn run(a: RenderArgs) -> Result<()> {
    a.load.options()?;
    match a.mode.as_str() {
        "reference" => {}
        m => bail!("--mode {m:?} is not available; use reference or realtime"),
    }
    let realtime_only = [
        ("--frames", a.frames.is_some()),
        ("--camera-path", a.camera_path.is_some()),
        ("--denoiser", a.denoiser.is_some()),
        ("--preset", a.preset.is_some()),
        ("--disable", !a.disable.is_empty()),
        ("--reflection-mv", a.reflection_mv.is_some()),
        ("--accumulate", a.accumulate),
        ("--target-ms", a.target_ms.is_some()),
        ("--min-scale", a.min_scale.is_some()),
        ("--scale", a.scale.is_some()),
        ("--view", a.view.is_some()),
        ("--out-dir", a.out_dir.is_some()),
    ];
    let given: Vec<&str> = realtime_only.iter().filter(|(_, on)| *on).map(|(f, _)| *f).collect();
    if !given.is_empty() {
        let verb = if given.len() == 1 { "applies" } else { "apply" };
        bail!(
            "{} only {verb} to --mode realtime; reference mode path-traces --spp samples with no settings to set",
            given.join(", ")
        );
    }
    let out = a.out.clone().context("--out is required in reference mode")?;
    check_output(&out, &["exr", "png"], "--out")?;
    check_sides(a.width, a.height, hush_engine::passes::reference::MAX_SIDE, "reference mode")?;
    let spp = match a.spp {
        None => 64,
        Some(Spp::Samples(n)) => n,
        Some(Spp::Fraction(f)) => bail!(
            "--spp {f}: reference mode traces whole samples per pixel; fractions are for --mode realtime"
        ),
    };
    let kind = bvh_kind(&a.bvh)?;
    let camera = a.camera.as_deref().map(parse_camera).transpose()?;
    let scene = load_scene(&a.scene, &a.load)?;
    let (w, h) = image_size(&scene, a.width, a.height);
    let camera = camera.unwrap_or_else(|| scene.camera_or_default());
    let view = TraceView::new(camera, (w, h), a.max_depth.unwrap_or(scene.max_depth), a.seed);
    let mut prepared = PreparedScene::new(&scene, kind)?;
    let time = a.time.unwrap_or(0.0);
    let open = time - shutter(&a)? / fps(&a)?;
    if !time.is_finite() {
        bail!("--time must be a finite number of seconds");
    }
    prepared.expose(&scene, time, (open < time).then_some(open));
    let gpu = Gpu::headless(&prepared.requirements(w as u64 * h as u64, 32))?;
    let gscene = prepared.upload(&gpu);
    let mut tracer = ReferenceTracer::new(&gpu, &prepared, &gscene, &view)?;
    let bar = if std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(spp as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{elapsed_precise} [{bar:40}] {pos}/{len} spp {per_sec} eta {eta}",
            )?
            .progress_chars("=> "),
        );
        Some(b)
    } else {
        None
    };
    let start = std::time::Instant::now();
    let mut done = 0;
    while done < spp {
        let n = (spp - done).min(hush_engine::passes::reference::BATCH);
        tracer.dispatch(&gpu, n);
        gpu.wait()?;
        done += n;
        if let Some(b) = &bar {
            b.set_position(done as u64);
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let acc = tracer.readback(&gpu)?;
    let secs = start.elapsed().as_secs_f64();
    if acc.nonfinite_samples > 0 {
        log::warn!("{} NaN/Inf samples were dropped", acc.nonfinite_samples);
    }
    acc.mean.save(&out)?;
    eprintln!(
        "{}: {}x{} {} spp in {:.2} s ({:.3} M samples/s) on {} -> {}",
        scene.name,
        w,
        h,
        spp,
        secs,
        (w as f64 * h as f64 * spp as f64) / secs / 1e6,
        gpu.info.name,
        out.display()
    );
    Ok(())
}
