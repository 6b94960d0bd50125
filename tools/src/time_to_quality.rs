//! `hush-cli time-to-quality`: FLIP against wall-clock time since the camera stopped, the
//! number a person exploring a scene feels. For each run (a denoiser, its samples per pixel or
//! sample fraction, and optionally the frame-time governor) and each scenario, the camera
//! reaches a view and stays; every frame from then on is timed as the viewer would run it
//! (render and wait for the device; scoring is not timed) and scored against the view's
//! converged reference at full size, a frame at a lower resolution scale stretched bilinearly
//! as the display stretches it. The screen holds each frame until the next one finishes
//! ([`hush_engine::quality::Timeline`]), so a slow renderer is charged for the old image while
//! it works. Scenarios:
//! - `stop`: the camera strafes sideways at `--speed` for `--lead-in` seconds, then stops at
//!   the view (the history is of a moving camera; the screen shows the last moving frame);
//! - `cut`: the camera looks the opposite way for `--lead-in` seconds, then cuts to the view
//!   (nothing of the view is in the history; the screen shows the other view).
//!
//! Writes time_to_quality.csv (every frame), at_times.csv (the FLIP on screen at each `--at`
//! time), time_to_quality.png (the curves) and scale_floors.csv (the FLIP of the converged
//! image at each resolution a run ended at, stretched: what that scale alone costs).

use crate::cli::preset_settings;
use crate::cli::{Spp, bvh_kind, image_size, load_scene, parse_camera, parse_spp};
use crate::realtime::{GovernedFrame, governed_frame};
use crate::reference::{new_renderer, reference};
use anyhow::{Context, Result, bail};
use clap::Args;
use glam::{DMat4, DVec3};
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::governor::Governor;
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::quality::{Image, Timeline, compare};
use hush_engine::scene::{Camera, Scene};
use hush_engine::settings::{FrameSettings, SampleFraction};
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(Args)]
pub struct TimeToQualityArgs {
    /// A .gltf/.glb file, `default` or `level`.
    pub scene: String,
    /// The view the camera stops at, "eye=x,y,z;target=x,y,z;fov=deg" (default: the scene's).
    #[arg(long)]
    pub camera: Option<String>,
    /// What to run, repeatable: DENOISER[:SPP][@TARGET_MS], e.g. `mara`, `svgf:2`,
    /// `progressive:1/16`, `progressive@100` (the governor holding 100 ms; an SPP given with
    /// it pins the sample fraction). Fixed runs render at full size.
    #[arg(long = "run", required = true)]
    pub runs: Vec<String>,
    /// `stop`, `cut` or both (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "stop,cut")]
    pub scenarios: Vec<String>,
    /// Seconds of wall time to follow after the camera stops.
    #[arg(long, default_value_t = 5.0)]
    pub seconds: f64,
    /// Times (seconds after the stop) whose FLIP is reported and compared.
    #[arg(long, value_delimiter = ',', default_value = "0.5,1,2,5")]
    pub at: Vec<f64>,
    /// Seconds of wall time the camera moves (stop) or looks away (cut) before.
    #[arg(long, default_value_t = 2.0)]
    pub lead_in: f64,
    /// Strafe speed before a stop (meters per second).
    #[arg(long, default_value_t = 1.0)]
    pub speed: f64,
    #[arg(long, default_value_t = 320)]
    pub width: u32,
    #[arg(long)]
    pub height: Option<u32>,
    /// Frames accumulated for the reference.
    #[arg(long, default_value_t = 256)]
    pub reference_frames: u32,
    /// Keep and reuse references here (see `quality --reference-cache`).
    #[arg(long)]
    pub reference_cache: Option<PathBuf>,
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    #[arg(long)]
    pub out_dir: PathBuf,
    /// Settings every run starts from (TOML, as the viewer saves); each --run's denoiser
    /// replaces the preset's
    #[arg(long)]
    pub preset: Option<PathBuf>,
    #[command(flatten)]
    pub load: crate::cli::LoadArgs,
}

/// One `--run`.
#[derive(Clone, Debug, PartialEq)]
struct RunSpec {
    label: String,
    denoiser: String,
    spp: Option<Spp>,
    target_ms: Option<f64>,
}

fn parse_run(s: &str) -> Result<RunSpec> {
    let (rest, target_ms) = match s.split_once('@') {
        Some((r, t)) => {
            let t: f64 = t
                .trim()
                .parse()
                .with_context(|| format!("--run {s:?}: {t:?} is not a frame time in ms"))?;
            if !(t > 0.0 && t.is_finite()) {
                bail!("--run {s:?}: the target frame time must be a positive number of ms");
            }
            (r, Some(t))
        }
        None => (s, None),
    };
    let (denoiser, spp) = match rest.split_once(':') {
        Some((d, spp)) => (d, Some(parse_spp(spp).with_context(|| format!("--run {s:?}"))?)),
        None => (rest, None),
    };
    if denoiser.trim().is_empty() {
        let names = hush_engine::settings::denoiser_names().join(", ");
        bail!("--run {s:?}: name a denoiser ({names})");
    }
    Ok(RunSpec { label: s.to_string(), denoiser: denoiser.trim().to_string(), spp, target_ms })
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scenario {
    Stop,
    Cut,
}

impl Scenario {
    fn parse(s: &str) -> Result<Scenario> {
        match s.trim() {
            "stop" => Ok(Scenario::Stop),
            "cut" => Ok(Scenario::Cut),
            other => bail!("--scenarios: {other:?} is not stop or cut"),
        }
    }

    fn name(self) -> &'static str {
        match self {
            Scenario::Stop => "stop",
            Scenario::Cut => "cut",
        }
    }

    /// Where the camera is `elapsed` seconds into the lead-in of `lead_in` seconds.
    fn lead_camera(self, view: &Camera, elapsed: f64, lead_in: f64, speed: f64) -> Camera {
        match self {
            Scenario::Stop => {
                let right = view.world.x_axis.truncate().normalize_or(DVec3::X);
                let offset = speed * (lead_in - elapsed).max(0.0);
                Camera { world: DMat4::from_translation(right * offset) * view.world, ..*view }
            }
            // Turned about its own up axis: the view behind the camera.
            Scenario::Cut => {
                Camera { world: view.world * DMat4::from_rotation_y(std::f64::consts::PI), ..*view }
            }
        }
    }
}

/// One run in one scenario: its timeline and the frames behind it.
struct Curve {
    run: RunSpec,
    scenario: Scenario,
    timeline: Timeline,
    frames: Vec<GovernedFrame>,
}

/// A run's renderer and its governor (a fixed run's pins both knobs: full size, its fraction).
struct Runner {
    renderer: Renderer,
    settings: FrameSettings,
    governor: Governor,
    last_camera: Option<Camera>,
    full: (u32, u32),
}

impl Runner {
    fn frame(&mut self, gpu: &Gpu, input: &FrameInput) -> Result<GovernedFrame> {
        governed_frame(
            gpu,
            &mut self.renderer,
            &mut self.governor,
            &self.settings,
            input,
            self.full,
            &mut self.last_camera,
        )
    }

    /// The frame on screen, at full size.
    fn shown(&self, gpu: &Gpu) -> Result<Image> {
        self.renderer.read_hdr(gpu)?.resized(self.full.0, self.full.1)
    }
}

pub fn run(a: TimeToQualityArgs) -> Result<()> {
    crate::cli::check_output_dir(&a.out_dir, "--out-dir")?;
    let runs: Vec<RunSpec> = a.runs.iter().map(|r| parse_run(r)).collect::<Result<_>>()?;
    let scenarios: Vec<Scenario> =
        a.scenarios.iter().map(|s| Scenario::parse(s)).collect::<Result<_>>()?;
    // Before any reference is rendered: a misspelt denoiser is a clear error at once.
    for r in &runs {
        preset_settings(a.preset.as_deref(), Some(&r.denoiser), &[], None)
            .with_context(|| format!("--run {:?}", r.label))?;
    }
    if !(a.seconds > 0.0 && a.seconds <= 600.0 && a.lead_in >= 0.0 && a.lead_in <= 600.0) {
        bail!("--seconds must be in (0, 600] and --lead-in in [0, 600]");
    }
    if !a.speed.is_finite()
        || a.at.iter().any(|t| !(t.is_finite() && *t >= 0.0))
        || a.reference_frames == 0
    {
        bail!("--speed must be finite, --at times non-negative and --reference-frames at least 1");
    }
    let scene = load_scene(&a.scene, &a.load)?;
    let full = image_size(&scene, Some(a.width), a.height);
    let view = match &a.camera {
        Some(c) => parse_camera(c)?,
        None => scene.camera_or_default(),
    };
    std::fs::create_dir_all(&a.out_dir)
        .with_context(|| format!("creating {}", a.out_dir.display()))?;
    let prepared = PreparedScene::new(&scene, bvh_kind(&None)?)?;
    let gpu = Gpu::headless(&prepared.realtime_requirements(full))?;
    let input = FrameInput { camera: view, time: 0.0, shutter: None };
    let acc = FrameSettings {
        accumulate: true,
        seed: a.seed.wrapping_add(7919),
        max_depth: scene.max_depth,
        ..Default::default()
    };
    let converged = {
        let mut r = new_renderer(&gpu, &scene, full)?;
        reference(
            &gpu,
            &mut r,
            &a.scene,
            &input,
            a.reference_frames,
            &acc,
            a.reference_cache.as_deref(),
        )?
    };

    let mut curves = vec![];
    for run in &runs {
        for &scenario in &scenarios {
            let c = follow(&a, &gpu, &scene, full, run, scenario, &view, &converged)?;
            eprintln!(
                "{} {}: {} frames in {:.2} s, FLIP {:.4} -> {:.4}",
                run.label,
                scenario.name(),
                c.frames.len(),
                c.timeline.span(),
                c.timeline.before,
                c.timeline.shown_at(a.seconds)
            );
            curves.push(c);
        }
    }
    write_outputs(&a, &curves, full)?;
    report(&a, &curves, &scenarios, full, &gpu);
    // What a lower resolution costs by itself: the converged image at each scale the runs
    // ended at, stretched to full size, is the best FLIP a run at that scale can reach.
    let mut sizes: Vec<(u32, u32)> = curves
        .iter()
        .filter_map(|c| c.frames.last())
        .map(|f| f.size)
        .filter(|s| *s != full)
        .collect();
    sizes.sort();
    sizes.dedup();
    let mut floors = String::from("width,height,flip\n");
    for size in sizes {
        let mut r = new_renderer(&gpu, &scene, size)?;
        let img = reference(
            &gpu,
            &mut r,
            &a.scene,
            &input,
            a.reference_frames,
            &acc,
            a.reference_cache.as_deref(),
        )?;
        let flip = compare(&img.resized(full.0, full.1)?, &converged)?.flip;
        println!(
            "  converged at {}x{} and stretched to {}x{}: FLIP {flip:.4}",
            size.0, size.1, full.0, full.1
        );
        writeln!(floors, "{},{},{flip:.5}", size.0, size.1)?;
    }
    let path = a.out_dir.join("scale_floors.csv");
    std::fs::write(&path, floors).with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// Lead in, stop, and follow the view for `--seconds`.
#[allow(clippy::too_many_arguments)]
fn follow(
    a: &TimeToQualityArgs,
    gpu: &Gpu,
    scene: &Scene,
    full: (u32, u32),
    run: &RunSpec,
    scenario: Scenario,
    view: &Camera,
    reference: &Image,
) -> Result<Curve> {
    let base = preset_settings(a.preset.as_deref(), Some(&run.denoiser), &[], None)
        .with_context(|| format!("--run {:?}", run.label))?;
    let (samples_per_pixel, sample_fraction) = match run.spp {
        None => (1, SampleFraction::ONE),
        Some(Spp::Samples(n)) => (n, SampleFraction::ONE),
        Some(Spp::Fraction(f)) => (1, f),
    };
    let settings = FrameSettings {
        seed: a.seed,
        max_depth: scene.max_depth,
        samples_per_pixel,
        sample_fraction,
        ..base
    };
    let mut renderer = new_renderer(gpu, scene, full)?;
    if sample_fraction != SampleFraction::ONE && !renderer.fills_untraced_pixels(gpu, &settings)? {
        bail!(
            "--run {:?}: the {} denoiser does not take sample fractions below 1",
            run.label,
            run.denoiser
        );
    }
    let governor = match run.target_ms {
        Some(t) => {
            let mut g = Governor::new(t);
            g.fractions_allowed = renderer.fills_untraced_pixels(gpu, &settings)?;
            g.keeps_history = settings.resample_history_frames > 0.0;
            g.filter_levels = hush_engine::settings::filter_levels(&settings).unwrap_or(0);
            g.pinned_fraction = run.spp.map(|_| sample_fraction);
            g
        }
        None => {
            let mut g = Governor::new(f64::INFINITY);
            (g.pinned_scale, g.pinned_fraction) = (Some(1.0), Some(sample_fraction));
            g
        }
    };
    // One frame before the clock starts: it compiles the pipelines, which a viewer does once.
    let first = FrameInput {
        camera: scenario.lead_camera(view, 0.0, a.lead_in, a.speed),
        time: 0.0,
        shutter: None,
    };
    renderer.render(gpu, &first, &settings, None)?;
    renderer.pass_times(gpu)?;
    let mut runner = Runner { renderer, settings, governor, last_camera: Some(first.camera), full };

    let (mut elapsed, mut lead_frames) = (0.0, 0);
    while elapsed < a.lead_in || lead_frames < 2 {
        let lead = FrameInput {
            camera: scenario.lead_camera(view, elapsed, a.lead_in, a.speed),
            time: 0.0,
            shutter: None,
        };
        elapsed += runner.frame(gpu, &lead)?.wall_ms / 1e3;
        lead_frames += 1;
    }
    let mut timeline = Timeline::new(compare(&runner.shown(gpu)?, reference)?.flip);
    let mut frames = vec![];
    let stopped = FrameInput { camera: *view, time: 0.0, shutter: None };
    let mut t = 0.0;
    while t < a.seconds {
        let f = runner.frame(gpu, &stopped)?;
        t += f.wall_ms / 1e3;
        let shown = runner.shown(gpu)?;
        if shown.nonfinite_pixels() > 0 {
            bail!(
                "--run {:?} {}: {} non-finite pixels on screen",
                run.label,
                scenario.name(),
                shown.nonfinite_pixels()
            );
        }
        timeline.push(t, compare(&shown, reference)?.flip);
        frames.push(f);
    }
    Ok(Curve { run: run.clone(), scenario, timeline, frames })
}

fn write_outputs(a: &TimeToQualityArgs, curves: &[Curve], full: (u32, u32)) -> Result<()> {
    let mut csv =
        String::from("run,scenario,frame,end_s,wall_ms,gpu_ms,spp,width,height,levels,flip\n");
    let mut at = String::from("run,scenario,seconds,flip\n");
    for c in curves {
        let (run, sc) = (&c.run.label, c.scenario.name());
        writeln!(csv, "{run},{sc},-1,0,0,0,0,{},{},,{:.5}", full.0, full.1, c.timeline.before)?;
        for (k, (f, (end, flip))) in c.frames.iter().zip(&c.timeline.frames).enumerate() {
            let levels = f.levels.map_or(String::new(), |l| l.to_string());
            writeln!(
                csv,
                "{run},{sc},{k},{end:.4},{:.3},{:.3},{},{},{},{levels},{flip:.5}",
                f.wall_ms, f.gpu_ms, f.spp, f.size.0, f.size.1
            )?;
        }
        for &t in &a.at {
            writeln!(at, "{run},{sc},{t},{:.5}", c.timeline.shown_at(t))?;
        }
    }
    for (name, text) in [("time_to_quality.csv", csv), ("at_times.csv", at)] {
        let path = a.out_dir.join(name);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
    }
    plot(&a.out_dir.join("time_to_quality.png"), curves, a.seconds, &a.scene)
}

/// The table of FLIP at each `--at` time, and whether each governed run lies at or below every
/// fixed run there.
fn report(
    a: &TimeToQualityArgs,
    curves: &[Curve],
    scenarios: &[Scenario],
    full: (u32, u32),
    gpu: &Gpu,
) {
    println!(
        "{} at {}x{} on {}: FLIP on screen after the camera stops",
        a.scene, full.0, full.1, gpu.info.name
    );
    for &sc in scenarios {
        let times: Vec<String> = a.at.iter().map(|t| format!("{t:>7} s")).collect();
        println!("  {:<10} {:<24} {}   frames", sc.name(), "run", times.join(" "));
        let of = |c: &&Curve| c.scenario == sc;
        for c in curves.iter().filter(of) {
            let flips: Vec<String> =
                a.at.iter().map(|&t| format!("{:9.4}", c.timeline.shown_at(t))).collect();
            println!("  {:<10} {:<24} {}   {}", "", c.run.label, flips.join(" "), c.frames.len());
        }
        for g in curves.iter().filter(of).filter(|c| c.run.target_ms.is_some()) {
            for f in curves.iter().filter(of).filter(|c| c.run.target_ms.is_none()) {
                let worse: Vec<String> =
                    a.at.iter()
                        .filter(|&&t| g.timeline.shown_at(t) > f.timeline.shown_at(t))
                        .map(|t| format!("{t} s"))
                        .collect();
                match worse.is_empty() {
                    true => println!(
                        "  {:<10} {} at or below {} at every time",
                        "", g.run.label, f.run.label
                    ),
                    false => println!(
                        "  {:<10} {} above {} at {}",
                        "",
                        g.run.label,
                        f.run.label,
                        worse.join(", ")
                    ),
                }
            }
        }
    }
}

/// FLIP on screen against seconds since the stop, one panel per scenario.
fn plot(path: &std::path::Path, curves: &[Curve], seconds: f64, title: &str) -> Result<()> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| anyhow::anyhow!("plot {}: {e}", path.display());
    let _ = plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    );
    let mut scenarios: Vec<Scenario> = vec![];
    for c in curves {
        if !scenarios.contains(&c.scenario) {
            scenarios.push(c.scenario);
        }
    }
    let root =
        BitMapBackend::new(path, (960, 420 * scenarios.len().max(1) as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let panels = root.split_evenly((scenarios.len().max(1), 1));
    for (area, sc) in panels.iter().zip(&scenarios) {
        let mine: Vec<&Curve> = curves.iter().filter(|c| c.scenario == *sc).collect();
        let hi = mine
            .iter()
            .flat_map(|c| {
                std::iter::once(c.timeline.before).chain(c.timeline.frames.iter().map(|f| f.1))
            })
            .fold(0.0f64, f64::max)
            .max(1e-3)
            * 1.05;
        let mut chart = ChartBuilder::on(area)
            .caption(format!("{title}: FLIP after a {}", sc.name()), ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..seconds, 0.0..hi)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("seconds since the camera stopped")
            .y_desc("FLIP")
            .draw()
            .map_err(|e| err(&e))?;
        for (i, c) in mine.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            // A staircase: each value holds until the next frame finishes.
            let mut pts = vec![(0.0, c.timeline.before)];
            let mut last = c.timeline.before;
            for &(t, f) in &c.timeline.frames {
                let t = t.min(seconds);
                pts.push((t, last));
                pts.push((t, f));
                last = f;
            }
            pts.push((seconds, last));
            chart
                .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(c.run.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_parse() {
        let r = parse_run("progressive:1/16@100").unwrap();
        assert_eq!((r.denoiser.as_str(), r.target_ms), ("progressive", Some(100.0)));
        assert!(matches!(r.spp, Some(Spp::Fraction(f)) if f.period() == 16));
        let r = parse_run("svgf:2").unwrap();
        assert_eq!(r.spp, Some(Spp::Samples(2)));
        assert_eq!(parse_run("mara").unwrap().target_ms, None);
        for bad in ["", "@100", "mara@-1", "mara@x", "svgf:0", "mara:1/3"] {
            assert!(parse_run(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn the_stop_lead_in_ends_at_the_view() {
        let view = Camera::look_at(DVec3::new(1.0, 2.0, 3.0), DVec3::ZERO, 60.0);
        let start = Scenario::Stop.lead_camera(&view, 0.0, 2.0, 1.0);
        assert!((start.eye() - view.eye()).length() > 1.99);
        let end = Scenario::Stop.lead_camera(&view, 2.0, 2.0, 1.0);
        assert!((end.eye() - view.eye()).length() < 1e-9);
        let away = Scenario::Cut.lead_camera(&view, 0.0, 2.0, 1.0);
        assert!((away.eye() - view.eye()).length() < 1e-9);
        assert!(away.world.z_axis.truncate().dot(view.world.z_axis.truncate()) < -0.99);
    }
}
