//! `hush-cli conformance DIR`: every glTF file under a folder (a clone of the Khronos
//! glTF-Sample-Assets `Models` folder, or any collection) loaded under the default budgets and
//! rendered small in both modes. Each file is reported as loaded (with its warnings), refused
//! (with the loader's reason) or wrong: a render that failed, panicked, or left non-finite or no
//! light at all in a scene that has some. Writes conformance.csv and, per loaded file, the two
//! images (PNG) for a person to look over; prints the counts. What each sample model is built to
//! show is checked by the tests of the feature it exercises (tests/texcoords.rs,
//! tests/transparency.rs, tests/compressed.rs, tests/textures.rs, tests/import.rs).

use anyhow::{Context, Result, bail};
use clap::Args;
use hush_engine::accel::BvhKind;
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::passes::{ReferenceTracer, TraceView};
use hush_engine::quality::Image;
use hush_engine::scene::{LoadOptions, Scene, load_gltf_opts};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Args)]
pub struct ConformanceArgs {
    /// The folder to search for .gltf and .glb files (recursively; links are not followed).
    pub dir: PathBuf,
    /// Where conformance.csv and the images go.
    #[arg(long, default_value = "conformance")]
    pub out_dir: PathBuf,
    #[arg(long, default_value_t = 64)]
    pub width: u32,
    #[arg(long, default_value_t = 64)]
    pub height: u32,
    /// Reference samples per pixel.
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    /// Real-time frames (default denoiser).
    #[arg(long, default_value_t = 4)]
    pub frames: u32,
    /// At most this many files (the first in path order; 0: all).
    #[arg(long, default_value_t = 0)]
    pub limit: usize,
}

/// What became of one file.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    Loaded,
    Refused(String),
    Wrong(String),
}

struct Row {
    file: String,
    outcome: Outcome,
    warnings: Vec<String>,
    triangles: usize,
    seconds: f64,
}

/// .gltf and .glb files under `dir`, sorted, without following links.
fn scene_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = vec![];
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        let entries = std::fs::read_dir(&d).with_context(|| format!("reading {}", d.display()))?;
        for e in entries.flatten() {
            let Ok(t) = e.file_type() else { continue };
            let p = e.path();
            if t.is_dir() {
                todo.push(p);
            } else if t.is_file()
                && p.extension().is_some_and(|x| {
                    x.eq_ignore_ascii_case("gltf") || x.eq_ignore_ascii_case("glb")
                })
            {
                out.push(p);
            }
        }
    }
    out.sort();
    Ok(out)
}

fn first_line(e: &anyhow::Error) -> String {
    format!("{e:#}").lines().next().unwrap_or("").replace(',', ";")
}

/// Non-finite pixels, and whether any pixel has light.
fn inspect(img: &Image) -> (usize, bool) {
    let bad = img.data.iter().filter(|p| !p.is_finite()).count();
    let lit = img.data.iter().any(|p| p.is_finite() && p.max_element() > 0.0);
    (bad, lit)
}

fn reference(scene: &Scene, a: &ConformanceArgs) -> Result<Image> {
    let prepared = PreparedScene::new(scene, BvhKind::DEFAULT)?;
    let gpu = Gpu::headless(&prepared.requirements(a.width as u64 * a.height as u64, 32))?;
    let gscene = prepared.upload(&gpu);
    let view = TraceView::new(scene.camera_or_default(), (a.width, a.height), scene.max_depth, 0);
    let mut tracer = ReferenceTracer::new(&gpu, &prepared, &gscene, &view)?;
    tracer.dispatch(&gpu, a.spp.max(1));
    gpu.wait()?;
    Ok(tracer.readback(&gpu)?.mean)
}

fn realtime(scene: &Scene, a: &ConformanceArgs) -> Result<Image> {
    let (gpu, mut r) = Renderer::headless(scene.clone(), BvhKind::DEFAULT, (a.width, a.height))?;
    let input = FrameInput { camera: scene.camera_or_default(), time: 0.0, shutter: None };
    let settings = hush_engine::settings::FrameSettings::default();
    for _ in 0..a.frames.max(1) {
        r.render(&gpu, &input, &settings, None)?;
    }
    r.read_hdr(&gpu)
}

/// Load and render one file; every failure is an outcome, a panic included.
fn check(path: &Path, name: &str, a: &ConformanceArgs) -> Row {
    let start = Instant::now();
    let mut row = Row {
        file: name.to_string(),
        outcome: Outcome::Loaded,
        warnings: vec![],
        triangles: 0,
        seconds: 0.0,
    };
    let scene = match load_gltf_opts(path, &LoadOptions::default()) {
        Ok(mut s) => {
            // As the viewer and the other tools show a file: lit by the sun and sky if unlit.
            s.add_sun_and_sky_if_unlit();
            s
        }
        Err(e) => {
            row.outcome = Outcome::Refused(first_line(&e));
            row.seconds = start.elapsed().as_secs_f64();
            return row;
        }
    };
    row.warnings = scene.warnings.clone();
    row.triangles = scene.triangle_count();
    let stem = name.replace(['/', '\\'], "_");
    let rendered = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| -> Result<Outcome> {
        let mut problems = vec![];
        for (mode, img) in
            [("reference", reference(&scene, a)?), ("realtime", realtime(&scene, a)?)]
        {
            let (bad, lit) = inspect(&img);
            if bad > 0 {
                problems.push(format!("{mode}: {bad} non-finite pixels"));
            }
            if !lit && scene.has_any_light() {
                problems.push(format!("{mode}: no light reaches the camera"));
            }
            hush_engine::quality::write_png(&a.out_dir.join(format!("{stem}.{mode}.png")), &img)?;
        }
        Ok(if problems.is_empty() { Outcome::Loaded } else { Outcome::Wrong(problems.join("; ")) })
    }));
    row.outcome = match rendered {
        Ok(Ok(o)) => o,
        Ok(Err(e)) => Outcome::Wrong(format!("render failed: {}", first_line(&e))),
        Err(p) => Outcome::Wrong(format!(
            "render panicked: {}",
            hush_engine::error::panic_message(p.as_ref())
        )),
    };
    row.seconds = start.elapsed().as_secs_f64();
    row
}

pub fn run(a: ConformanceArgs) -> Result<()> {
    if !a.dir.is_dir() {
        bail!("{} is not a folder", a.dir.display());
    }
    crate::cli::check_sides(Some(a.width), Some(a.height), 4096, "conformance")?;
    std::fs::create_dir_all(&a.out_dir)
        .with_context(|| format!("creating {}", a.out_dir.display()))?;
    let mut files = scene_files(&a.dir)?;
    if a.limit > 0 {
        files.truncate(a.limit);
    }
    let mut csv = String::from("file,outcome,reason,warnings,first_warning,triangles,seconds\n");
    let (mut loaded, mut refused, mut wrong) = (0, 0, 0);
    for path in &files {
        let name = path.strip_prefix(&a.dir).unwrap_or(path).to_string_lossy().into_owned();
        let row = check(path, &name, &a);
        let (outcome, reason) = match &row.outcome {
            Outcome::Loaded => {
                loaded += 1;
                ("loaded", String::new())
            }
            Outcome::Refused(r) => {
                refused += 1;
                ("refused", r.clone())
            }
            Outcome::Wrong(r) => {
                wrong += 1;
                ("wrong", r.clone())
            }
        };
        eprintln!("{outcome:8} {name} {reason}");
        let first = row.warnings.first().map(|w| w.replace(',', ";")).unwrap_or_default();
        csv.push_str(&format!(
            "{},{outcome},{},{},{},{},{:.2}\n",
            row.file.replace(',', ";"),
            reason,
            row.warnings.len(),
            first,
            row.triangles,
            row.seconds
        ));
    }
    let out = a.out_dir.join("conformance.csv");
    std::fs::write(&out, csv).with_context(|| format!("writing {}", out.display()))?;
    println!(
        "{} files: {loaded} loaded, {refused} refused, {wrong} wrong; {}",
        files.len(),
        out.display()
    );
    Ok(())
}
