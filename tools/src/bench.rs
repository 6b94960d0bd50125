use crate::cli::load_scene;
use anyhow::{Context, Result};
use clap::Args;
use hush_engine::accel::{BvhKind, light_tree};
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::passes::{Raycaster, ReferenceTracer, TraceView};
use serde::Serialize;
use std::time::Instant;

#[derive(Args)]
pub struct BenchArgs {
    /// A .gltf/.glb file or a built-in scene: `default`, `level`, `reflections`, `spheres`, or
    /// `terrain:N` (a generated height field of about N triangles) or `crowd:N` (N moving
    /// instances of a 1,000-triangle figure).
    pub scene: String,
    /// `reference` (BVH build, rays/s, tracer samples/s), `realtime` (GPU time per pass of the
    /// real-time frame) or `animate` (what a frame of the scene's animation costs: posing, the
    /// BVH, the upload).
    #[arg(long, default_value = "reference")]
    pub mode: String,
    /// Real-time mode: frames measured (after two warm-up frames).
    #[arg(long, default_value_t = 32)]
    pub frames: u32,
    /// Real-time mode: the denoiser (`none`, `mara`, `svgf` or `progressive`); default mara, or
    /// the preset's.
    #[arg(long)]
    pub denoiser: Option<String>,
    /// Real-time mode: measure the settings of this preset file (TOML, as the viewer saves).
    #[arg(long)]
    pub preset: Option<std::path::PathBuf>,
    /// BVH layout to measure (bvh2, cwbvh); both when omitted.
    #[arg(long)]
    pub bvh: Option<String>,
    /// Whether a mesh that several objects draw is stored once, as instances of it: `auto`
    /// (where flattening would store at least twice the triangles), `never`, or `always`
    /// (every object that can be, which measures the two-level traversal on any scene).
    #[arg(long, default_value = "auto")]
    pub instancing: String,
    /// Real-time mode: pose deforming meshes and refit their BVH on the CPU instead of in the
    /// GPU's posing pass (the frame's CPU time then carries the pose, refit and upload).
    #[arg(long)]
    pub cpu_posing: bool,
    /// Real-time mode: every frame changes the size, between WIDTHxHEIGHT and 7/8 of it, so
    /// that each one resamples its histories to the new size (measures `frame/rescale`; the
    /// other passes then run at the two sizes in turn).
    #[arg(long)]
    pub rescale: bool,
    /// Real-time mode: trace at this resolution scale per side and show at WIDTHxHEIGHT through
    /// the temporal upscaler (`taa.upscale`).
    #[arg(long)]
    pub scale: Option<f32>,
    /// Image size of the tracer benchmark.
    #[arg(long, default_value_t = 128)]
    pub width: u32,
    #[arg(long, default_value_t = 128)]
    pub height: u32,
    /// Samples per pixel of the tracer benchmark.
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    /// Random rays for the traversal benchmark.
    #[arg(long, default_value_t = 262_144)]
    pub rays: u32,
    #[arg(long)]
    pub json: bool,
    /// Reference mode: also render the scene with Mitsuba 3 (scalar_rgb, path) at the same size
    /// and spp in this run and report its samples/s (needs python3 with `mitsuba` and `numpy`;
    /// the scene must follow the oracle scenes' conventions).
    #[arg(long)]
    pub mitsuba: bool,
    /// Real-time mode: write a puffin capture of the measured frames (CPU scopes and the GPU
    /// passes) to this `.puffin` file (open it with puffin_viewer).
    #[arg(long)]
    pub profile: Option<std::path::PathBuf>,
    /// Real-time mode: the camera, as `render --camera` takes it ("eye=x,y,z;target=x,y,z;fov=deg",
    /// with ";aperture=r;focus=d" for a thin lens); default the scene's.
    #[arg(long)]
    pub camera: Option<String>,
    #[command(flatten)]
    pub load: crate::cli::LoadArgs,
}

#[derive(Serialize)]
struct LayoutResult {
    bvh: &'static str,
    bvh_build_seconds: f64,
    bvh_nodes: usize,
    /// Node levels from the root to the deepest leaf.
    bvh_depth: usize,
    /// Incoherent closest-hit rays per second (random origins in the bounds, random directions).
    rays_per_second: f64,
    /// Reference-tracer paths (camera samples) per second.
    samples_per_second: f64,
    /// Scene + tracer buffers allocated on the GPU.
    gpu_bytes: u64,
}

#[derive(Serialize)]
struct BenchResult {
    scene: String,
    adapter: String,
    triangles: usize,
    width: u32,
    height: u32,
    spp: u32,
    layouts: Vec<LayoutResult>,
    /// Emissive triangles, and the light tree's nodes and depth over them.
    emitters: usize,
    light_tree_nodes: usize,
    light_tree_depth: usize,
    /// From the oracle's render_info.json beside the scene, when there is one.
    mitsuba_samples_per_second: Option<f64>,
    /// Mitsuba 3 timed in this run (`--mitsuba`), same size and spp.
    mitsuba_measured: Option<MitsubaRun>,
}

#[derive(Serialize, serde::Deserialize)]
struct MitsubaRun {
    /// Render time (scene loading excluded, as Hush's excludes its BVH build).
    seconds: f64,
    samples_per_second: f64,
    mean_rgb: Vec<f64>,
}

/// The script `--mitsuba` runs (tools/scripts/mitsuba_time.py), carried in the binary.
const MITSUBA_SCRIPT: &str = include_str!("../scripts/mitsuba_time.py");

/// Render `scene` with Mitsuba in a child python3 and read its timing.
fn time_mitsuba(scene: &str, width: u32, height: u32, spp: u32) -> Result<MitsubaRun> {
    let dir = std::env::temp_dir().join(format!("hush-mitsuba-{}", std::process::id()));
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let script = dir.join("mitsuba_time.py");
    std::fs::write(&script, MITSUBA_SCRIPT)
        .with_context(|| format!("writing {}", script.display()))?;
    let out = std::process::Command::new("python3")
        .arg(&script)
        .arg(scene)
        .args([
            "--width",
            &width.to_string(),
            "--height",
            &height.to_string(),
            "--spp",
            &spp.to_string(),
        ])
        .output()
        .context("running python3 for --mitsuba");
    let _ = std::fs::remove_dir_all(&dir);
    let out = out?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().last().unwrap_or("");
    if let Ok(v) = serde_json::from_str::<serde_json::Value>(line) {
        if let Some(e) = v.get("error") {
            anyhow::bail!("--mitsuba: {scene}: {}", e.as_str().unwrap_or_default());
        }
        if out.status.success() {
            return serde_json::from_value(v).context("--mitsuba: reading the script's result");
        }
    }
    let err = String::from_utf8_lossy(&out.stderr);
    anyhow::bail!(
        "--mitsuba: python3 failed ({}): {}",
        out.status,
        err.lines().last().unwrap_or("no output")
    )
}

/// Mitsuba's samples per second from `render_info.json` next to an oracle scene.
fn mitsuba_rate(scene: &str) -> Option<f64> {
    let dir = std::path::Path::new(scene).parent()?;
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("render_info.json")).ok()?).ok()?;
    let r = v.get("reference.exr")?;
    let res = r.get("resolution")?.as_array()?;
    let px = res[0].as_f64()? * res[1].as_f64()?;
    Some(px * r.get("spp")?.as_f64()? / r.get("seconds")?.as_f64()?)
}

pub fn run(a: BenchArgs) -> Result<()> {
    match a.mode.as_str() {
        "reference" => {}
        m => anyhow::bail!("--mode {m:?}: use reference, realtime or animate"),
    }
    let scene = load_scene(&a.scene, &a.load)?;
    let kinds = match &a.bvh {
        Some(s) => vec![BvhKind::parse(s).with_context(|| format!("--bvh {s:?}"))?],
        None => vec![BvhKind::Bvh2, BvhKind::Cwbvh],
    };
    let mut layouts = vec![];
    let mut adapter = String::new();
    let (mut triangles, mut lights) = (0, (0, 0, 0));
    for kind in kinds {
        let prepared = PreparedScene::with_instancing(&scene, kind, instancing(&a.instancing)?)?;
        triangles = prepared.triangle_count();
        let tree = &prepared.emitters;
        lights = (prepared.emitter_slots.len(), tree.len(), light_tree::depth(tree));
        let gpu = Gpu::headless(&prepared.requirements(a.width as u64 * a.height as u64, 32))?;
        adapter = gpu.info.name.clone();
        let gscene = prepared.upload(&gpu);
        // Traversal: random rays from inside the bounds in uniformly random directions.
        let caster = Raycaster::new(&gpu, &gscene)?;
        let half =
            (scene.bounds().map(|(lo, hi)| (hi - lo) * 0.5).unwrap_or(glam::DVec3::ONE)).as_vec3();
        let mut rng = 0x9e3779b9u32;
        let mut r = move || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            rng as f32 / u32::MAX as f32
        };
        let rays: Vec<_> = (0..a.rays)
            .map(|_| {
                let o = glam::Vec3::new(r() * 2.0 - 1.0, r() * 2.0 - 1.0, r() * 2.0 - 1.0) * half;
                let z = r() * 2.0 - 1.0;
                let phi = r() * std::f32::consts::TAU;
                let s = (1.0 - z * z).max(0.0).sqrt();
                (o, glam::Vec3::new(s * phi.cos(), s * phi.sin(), z), f32::MAX)
            })
            .collect();
        caster.cast(&gpu, &gscene, &rays[..rays.len().min(4096)], false)?; // warm-up (pipeline compile)
        let (_, t) = caster.cast(&gpu, &gscene, &rays, false)?;
        let rays_per_second = a.rays as f64 / t.as_secs_f64();
        let view =
            TraceView::new(scene.camera_or_default(), (a.width, a.height), scene.max_depth, 0);
        let mut tracer = ReferenceTracer::new(&gpu, &prepared, &gscene, &view)?;
        tracer.dispatch(&gpu, 1);
        gpu.wait()?;
        let start = Instant::now();
        tracer.dispatch(&gpu, a.spp);
        gpu.wait()?;
        let secs = start.elapsed().as_secs_f64();
        layouts.push(LayoutResult {
            bvh: kind.name(),
            bvh_build_seconds: prepared.accel.build_time.as_secs_f64(),
            bvh_nodes: prepared.accel.node_count,
            bvh_depth: prepared.accel.depth,
            rays_per_second,
            samples_per_second: (a.width * a.height * a.spp) as f64 / secs,
            gpu_bytes: gscene.memory.total_bytes() + tracer.memory.total_bytes(),
        });
    }
    let res = BenchResult {
        scene: a.scene.clone(),
        adapter,
        triangles,
        width: a.width,
        height: a.height,
        spp: a.spp,
        layouts,
        emitters: lights.0,
        light_tree_nodes: lights.1,
        light_tree_depth: lights.2,
        mitsuba_samples_per_second: mitsuba_rate(&a.scene),
        mitsuba_measured: if a.mitsuba {
            Some(time_mitsuba(&a.scene, a.width, a.height, a.spp)?)
        } else {
            None
        },
    };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&res)?);
    } else {
        println!("{} ({} triangles) on {}", res.scene, res.triangles, res.adapter);
        for l in &res.layouts {
            println!(
                "  {:6} build {:.3} s, {} nodes (depth {}), {:.2} M rays/s, {:.3} M samples/s, {:.1} MiB",
                l.bvh,
                l.bvh_build_seconds,
                l.bvh_nodes,
                l.bvh_depth,
                l.rays_per_second / 1e6,
                l.samples_per_second / 1e6,
                l.gpu_bytes as f64 / 1048576.0
            );
        }
        if res.emitters > 0 {
            println!(
                "  light tree over {} emissive triangles: {} nodes, depth {}",
                res.emitters, res.light_tree_nodes, res.light_tree_depth
            );
        }
        if let Some(m) = res.mitsuba_samples_per_second {
            println!(
                "  Mitsuba 3 (scalar_rgb, CPU): {:.3} M samples/s (render_info.json)",
                m / 1e6
            );
        }
        if let Some(m) = &res.mitsuba_measured {
            let ours = res.layouts.iter().map(|l| l.samples_per_second).fold(0.0, f64::max);
            println!(
                "  Mitsuba 3 (scalar_rgb, CPU) in this run: {:.3} M samples/s ({:.2} s); Hush / Mitsuba {:.2}",
                m.samples_per_second / 1e6,
                m.seconds,
                ours / m.samples_per_second
            );
        }
    }
    Ok(())
}

/// `--instancing`'s value.
pub fn instancing(s: &str) -> Result<hush_engine::gpu::Instancing> {
    hush_engine::gpu::Instancing::parse(s)
        .with_context(|| format!("--instancing {s:?}: use auto, never or always"))
}
