//! `hush-cli quality`: how close a denoised stream is to the converged image, frame by frame.
//! For every frame of a camera path (or a still camera) it renders the frame with the denoiser,
//! the same frame raw, and the reference (the real-time frame accumulated over many frames at
//! the same camera and time; the accumulation converges to the reference mode, tests/realtime.rs),
//! then writes quality.csv (FLIP, relMSE, SSIM and the temporal error of Schied et al. 2017: mean
//! absolute luminance change between consecutive frames; for the denoised stream also the FLIP
//! of the pixels lately disoccluded, `Uncovered`), quality.png, the last frames (PNG and
//! EXR) and FLIP heat maps of the last denoised frame and the 64-spp yardstick. `--ablations` repeats
//! the denoised stream with each stage off and writes ablations.csv.

use crate::cli::preset_settings;
use crate::cli::{bvh_kind, image_size, load_scene, parse_camera};
pub use crate::quality_args::QualityArgs;
use crate::reference::{new_renderer, reference};
use anyhow::{Context, Result, bail};
use glam::{Mat4, Vec3};
use hush_engine::frame::{FrameInput, Renderer};
use hush_engine::gpu::{Gpu, PreparedScene};
use hush_engine::quality::{
    DepthView, Image, compare, compare_with_flip_map, flip_over, luminance, region_mean,
    save_flip_heatmap, uncovered,
};
use hush_engine::scene::{Camera, CameraPath, Scene};
use hush_engine::settings::{Denoiser, FrameSettings};
use std::io::Write;
use std::path::Path;

/// One stream's per-frame scores against the reference.
#[derive(Default, Clone)]
pub struct Scores {
    pub flip: Vec<f64>,
    pub relmse: Vec<f64>,
    pub ssim: Vec<f64>,
    /// Mean |luminance(frame k) - luminance(frame k-1)| (0 for the first frame).
    pub temporal: Vec<f64>,
    /// GPU milliseconds of the frame (all passes).
    pub gpu_ms: Vec<f64>,
    /// Mean FLIP over the uncovered pixels (see `Uncovered`) and how many there are; NaN and 0
    /// where there are none (a still camera, or the raw stream).
    pub uncovered_flip: Vec<f64>,
    pub uncovered_pixels: Vec<usize>,
}

/// Pixels the previous frame did not see, within the last UNCOVERED_FRAMES frames, where they
/// were on screen: after a camera stops, the region a move uncovered, whose FLIP tells how fast
/// it recovers (it should reach a still view's FLIP within 10 frames; a whole frame's FLIP hides
/// a small region's lag). Decided from the depth buffers alone, so that every denoiser, and the
/// same denoiser with and without the radiance cache, is scored on the same pixels.
struct Uncovered {
    /// Frames since each pixel was last uncovered.
    age: Vec<u32>,
    /// The previous frame's depth buffer and unjittered view-projection.
    previous: Option<(Vec<f32>, Mat4)>,
}

const UNCOVERED_FRAMES: u32 = 10;

impl Uncovered {
    fn new(size: (u32, u32)) -> Uncovered {
        Uncovered { age: vec![u32::MAX; (size.0 * size.1) as usize], previous: None }
    }

    /// Age the pixels by a frame and restart those whose surface the previous frame did not
    /// see (hush_engine::quality::uncovered: the trace's and the radiance cache's test).
    fn update(&mut self, r: &Renderer, gpu: &Gpu, camera: &Camera) -> Result<Vec<bool>> {
        let (bytes, _) = r.read_texture(gpu, "gbuffer/depth").context("reading the depth")?;
        let depth: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
        let view_proj = r.camera_setup(camera).view_proj;
        if let Some((prev, prev_vp)) = &self.previous {
            let before = DepthView { depth: prev, view_proj: *prev_vp };
            let now = DepthView { depth: &depth, view_proj };
            for (age, new) in self.age.iter_mut().zip(uncovered(&before, &now, r.size())) {
                *age = if new { 0 } else { age.saturating_add(1) };
            }
        }
        self.previous = Some((depth, view_proj));
        Ok(self.age.iter().map(|a| *a <= UNCOVERED_FRAMES).collect())
    }
}

impl Scores {
    fn push(
        &mut self,
        img: &Image,
        prev: Option<&Image>,
        reference: &Image,
        ms: f64,
        uncovered: Option<&[bool]>,
    ) -> Result<()> {
        // With a region to score, the frame's FLIP map is kept rather than computed again.
        let (m, region) = match uncovered {
            Some(mask) => {
                let (m, map) = compare_with_flip_map(img, reference)?;
                (m, region_mean(&map, mask))
            }
            None => (compare(img, reference)?, None),
        };
        let (flip, n) = region.unwrap_or((f64::NAN, 0));
        self.uncovered_flip.push(flip);
        self.uncovered_pixels.push(n);
        self.flip.push(m.flip);
        self.relmse.push(m.relmse);
        self.ssim.push(m.ssim);
        self.temporal.push(prev.map_or(0.0, |p| temporal_error(img, p)));
        self.gpu_ms.push(ms);
        Ok(())
    }

    /// Mean over the second half of the stream (after the history has filled).
    pub fn settled(v: &[f64]) -> f64 {
        let tail = &v[v.len() / 2..];
        tail.iter().sum::<f64>() / tail.len().max(1) as f64
    }
}

pub fn temporal_error(a: &Image, b: &Image) -> f64 {
    a.data
        .iter()
        .zip(&b.data)
        .map(|(x, y)| (luminance(*x) - luminance(*y)).abs() as f64)
        .sum::<f64>()
        / a.data.len() as f64
}

struct Setup {
    gpu: Gpu,
    scene: Scene,
    size: (u32, u32),
    inputs: Vec<FrameInput>,
}

fn renderer(s: &Setup) -> Result<Renderer> {
    new_renderer(&s.gpu, &s.scene, s.size)
}

/// Render the stream with `settings`, scoring every frame against `references`. Returns the
/// scores, the last frame, and the last frame's uncovered pixels where it has any.
fn stream(
    s: &Setup,
    settings: &FrameSettings,
    references: &[Image],
) -> Result<(Scores, Vec<Image>, Option<Vec<bool>>)> {
    let mut r = renderer(s)?;
    let mut scores = Scores::default();
    let mut prev: Option<Image> = None;
    let mut last = vec![];
    let mut uncovered = Uncovered::new(s.size);
    let mut last_mask = None;
    for (k, input) in s.inputs.iter().enumerate() {
        r.render(&s.gpu, input, settings, None)?;
        let ms: f64 = r.pass_times(&s.gpu)?.iter().map(|p| p.1).sum();
        let img = r.read_hdr(&s.gpu)?;
        // The raw stream is not scored on them.
        let tracked = settings.denoiser != Denoiser::NONE;
        let mask = if tracked { Some(uncovered.update(&r, &s.gpu, &input.camera)?) } else { None };
        scores.push(&img, prev.as_ref(), &references[k], ms, mask.as_deref())?;
        if k + 1 == s.inputs.len() {
            last.push(img.clone());
            last_mask = mask.clone().filter(|m| m.iter().any(|u| *u));
        }
        prev = Some(img);
    }
    Ok((scores, last, last_mask))
}

pub fn run(a: QualityArgs) -> Result<()> {
    crate::cli::check_output_dir(&a.out_dir, "--out-dir")?;
    if a.frames == 0 || a.reference_frames == 0 {
        bail!("--frames and --reference-frames must be at least 1");
    }
    let denoiser = a.denoiser.as_deref().or(if a.preset.is_none() {
        Some(Denoiser::MARA.name())
    } else {
        None
    });
    let chains =
        preset_settings(a.preset.as_deref(), denoiser, &a.disable, a.reflection_mv.as_deref())?;
    let denoiser = chains.denoiser.clone();
    let scene = load_scene(&a.scene, &a.load)?;
    let size = image_size(&scene, Some(a.width), a.height);
    let path = a.camera_path.as_deref().map(CameraPath::load).transpose()?;
    let camera = match &a.camera {
        Some(c) => parse_camera(c)?,
        None => scene.camera_or_default(),
    };
    let inputs: Vec<FrameInput> = (0..a.frames as usize)
        .map(|k| match &path {
            Some(p) => {
                FrameInput { camera: p.frame(k).camera(), time: p.frame(k).time, shutter: None }
            }
            None => FrameInput {
                camera,
                time: if a.fps > 0.0 { k as f64 / a.fps } else { 0.0 },
                shutter: None,
            },
        })
        .collect();
    std::fs::create_dir_all(&a.out_dir)
        .with_context(|| format!("creating {}", a.out_dir.display()))?;
    if a.convergence {
        return crate::convergence::run(&a, scene, size, inputs[0]);
    }
    if a.reference.is_some() {
        bail!("--reference is read by --convergence only");
    }
    let prepared = PreparedScene::new(&scene, bvh_kind(&None)?)?;
    let gpu = Gpu::headless(&prepared.realtime_requirements(size))?;
    let s = Setup { gpu, scene, size, inputs };

    // References: one accumulation per distinct (camera, time), with the path length of the
    // runs they score (a preset's, else the scene's).
    let max_depth = crate::cli::path_length(None, a.preset.as_deref(), s.scene.max_depth)?;
    let mut refr = renderer(&s)?;
    let acc = FrameSettings {
        accumulate: true,
        seed: a.seed.wrapping_add(7919),
        max_depth,
        ..Default::default()
    };
    let mut references: Vec<Image> = vec![];
    for (k, input) in s.inputs.iter().enumerate() {
        if k > 0 && s.inputs[k - 1] == *input {
            references.push(references[k - 1].clone());
            continue;
        }
        let img = reference(
            &s.gpu,
            &mut refr,
            &a.scene,
            input,
            a.reference_frames,
            &acc,
            a.reference_cache.as_deref(),
        )?;
        references.push(img);
    }
    // The yardstick: the last frame's view accumulated over 64 frames, raw, as the mean
    // FLIP of independent accumulations (the first one is the one saved).
    let last_input = s.inputs[s.inputs.len() - 1];
    // A renderer of its own: the accumulations' jitter and sample sequences follow the frame
    // index, which the references above advanced only where they were not in the cache, so the
    // same run's yardstick came out 0.1388 or 0.1403 (the living room at 160x90) by whether
    // its reference had to be rendered.
    drop(refr);
    let mut accumulator = renderer(&s)?;
    let mut flips64 = vec![];
    let mut accumulated64 = None;
    for j in 0..a.yardstick_seeds.max(1) {
        let yardstick = FrameSettings {
            seed: a.seed.wrapping_add(104729).wrapping_add(j.wrapping_mul(7)),
            ..acc.clone()
        };
        for _ in 0..64 {
            accumulator.render(&s.gpu, &last_input, &yardstick, None)?;
        }
        let img = accumulator.read_hdr(&s.gpu)?;
        flips64.push(compare(&img, &references[references.len() - 1])?.flip);
        accumulated64.get_or_insert(img);
    }
    let accumulated64 = accumulated64.expect("at least one yardstick accumulation");
    let flip64 = flips64.iter().sum::<f64>() / flips64.len() as f64;
    let (lo64, hi64) =
        flips64.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &f| (l.min(f), h.max(f)));
    drop(accumulator);

    let base = FrameSettings { seed: a.seed, max_depth, ..chains };
    let (den, last, last_mask) = stream(&s, &base, &references)?;
    if let Some(m) = &last_mask {
        // Which pixels the uncovered column scored in the last frame, white.
        let data = m.iter().map(|u| Vec3::splat(if *u { 1.0 } else { 0.0 })).collect();
        let img = Image { width: size.0, height: size.1, data };
        img.save(&a.out_dir.join("last_uncovered.png"))?;
    }
    let (raw, last_raw, _) =
        stream(&s, &FrameSettings { denoiser: Denoiser::NONE, ..base.clone() }, &references)?;
    if let (Some(d), Some(r), Some(f)) = (last.first(), last_raw.first(), references.last()) {
        // The last frame as seen and in linear HDR, and where FLIP sees the error (denoised and
        // the 64-spp yardstick side by side show whether the denoiser's error is noise or bias).
        for (name, img) in
            [("denoised", d), ("raw", r), ("reference", f), ("accumulated64", &accumulated64)]
        {
            img.save(&a.out_dir.join(format!("last_{name}.png")))?;
            img.save(&a.out_dir.join(format!("last_{name}.exr")))?;
        }
        save_flip_heatmap(d, f, &a.out_dir.join("last_flip_denoised.png"))?;
        save_flip_heatmap(&accumulated64, f, &a.out_dir.join("last_flip_accumulated64.png"))?;
    }
    write_csv(&a.out_dir.join("quality.csv"), &s.inputs, &den, &raw)?;
    plot(&a.out_dir.join("quality.png"), &den, &raw, &a.scene)?;
    println!(
        "{} at {}x{}, {} frames ({} reference frames each), on {}",
        a.scene, size.0, size.1, a.frames, a.reference_frames, s.gpu.info.name
    );
    println!(
        "  stream     mean FLIP  mean relMSE  mean SSIM  temporal error  GPU ms/frame   (second half of the stream)"
    );
    for (name, sc) in [("denoised", &den), ("raw", &raw)] {
        println!(
            "  {name:9}  {:9.4}  {:11.5}  {:9.4}  {:14.5}  {:12.2}",
            Scores::settled(&sc.flip),
            Scores::settled(&sc.relmse),
            Scores::settled(&sc.ssim),
            Scores::settled(&sc.temporal),
            Scores::settled(&sc.gpu_ms)
        );
    }

    let last_flip = den.flip.last().copied().unwrap_or(f64::NAN);
    println!(
        "  last frame ({}): denoised FLIP {last_flip:.4}; 64 accumulated frames of its view: FLIP {flip64:.4} (mean of {} seeds, {lo64:.4} to {hi64:.4})",
        den.flip.len(),
        flips64.len()
    );
    if let (Some(m), Some(r)) = (&last_mask, references.last()) {
        // The same pixels of the yardstick: how far 64 samples get where the region lies
        // (silhouettes and a room's far openings score high at any sample count).
        if let Some((f64_region, n)) = flip_over(&accumulated64, r, m) {
            let den_region = den.uncovered_flip.last().copied().unwrap_or(f64::NAN);
            println!(
                "  its uncovered pixels ({n}): denoised FLIP {den_region:.4}; 64 accumulated frames (first seed): FLIP {f64_region:.4}"
            );
        }
    }
    let per_seed: Vec<String> = flips64.iter().map(|f| format!("{f:.5}")).collect();
    std::fs::write(
        a.out_dir.join("accumulated64_flip.txt"),
        format!("{flip64:.5}\n{}\n", per_seed.join(",")),
    )?;

    if a.ablations && denoiser != Denoiser::NONE {
        let mut f = std::fs::File::create(a.out_dir.join("ablations.csv"))?;
        writeln!(f, "disabled,flip,relmse,ssim,temporal_error,gpu_ms")?;
        let mut row = |name: &str, sc: &Scores| -> Result<()> {
            writeln!(
                f,
                "{name},{:.5},{:.6},{:.5},{:.6},{:.3}",
                Scores::settled(&sc.flip),
                Scores::settled(&sc.relmse),
                Scores::settled(&sc.ssim),
                Scores::settled(&sc.temporal),
                Scores::settled(&sc.gpu_ms)
            )?;
            println!(
                "  without {name:24} FLIP {:.4} temporal error {:.5} GPU {:.2} ms",
                Scores::settled(&sc.flip),
                Scores::settled(&sc.temporal),
                Scores::settled(&sc.gpu_ms)
            );
            Ok(())
        };
        row("nothing", &den)?;
        // The stages the denoiser under test declares, and TAA.
        let own = hush_engine::settings::registry::denoiser(denoiser.name())?.stages;
        let taa = hush_engine::settings::TaaSettings::STAGE;
        for stage in own.iter().map(|s| s.name).chain([taa]) {
            let mut settings = base.clone();
            hush_engine::settings::disable_stage(&mut settings, stage);
            let (sc, _, _) = stream(&s, &settings, &references)?;
            row(stage, &sc)?;
        }
    }
    Ok(())
}

fn write_csv(path: &Path, inputs: &[FrameInput], den: &Scores, raw: &Scores) -> Result<()> {
    let mut f =
        std::fs::File::create(path).with_context(|| format!("writing {}", path.display()))?;
    writeln!(
        f,
        "frame,time,flip,relmse,ssim,temporal_error,gpu_ms,raw_flip,raw_relmse,raw_ssim,raw_temporal_error,raw_gpu_ms,uncovered_flip,uncovered_pixels"
    )?;
    for (k, input) in inputs.iter().enumerate() {
        // The denoised stream's uncovered pixels; blank where there are none.
        let uncovered = if den.uncovered_pixels[k] > 0 {
            format!("{:.5}", den.uncovered_flip[k])
        } else {
            String::new()
        };
        writeln!(
            f,
            "{k},{:.4},{:.5},{:.6},{:.5},{:.6},{:.3},{:.5},{:.6},{:.5},{:.6},{:.3},{uncovered},{}",
            input.time,
            den.flip[k],
            den.relmse[k],
            den.ssim[k],
            den.temporal[k],
            den.gpu_ms[k],
            raw.flip[k],
            raw.relmse[k],
            raw.ssim[k],
            raw.temporal[k],
            raw.gpu_ms[k],
            den.uncovered_pixels[k]
        )?;
    }
    Ok(())
}

/// FLIP and temporal error per frame, denoised against raw, as a PNG.
fn plot(path: &Path, den: &Scores, raw: &Scores, title: &str) -> Result<()> {
    use plotters::prelude::*;
    // Text needs a font; egui's default font is a crate away and always the same.
    let _ = plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    );
    let root = BitMapBackend::new(path, (960, 720)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| anyhow::anyhow!("plot: {e}"))?;
    let panels = root.split_evenly((2, 1));
    let series = [
        ("FLIP", &den.flip, &raw.flip),
        ("temporal error (mean |dY|)", &den.temporal, &raw.temporal),
    ];
    for (area, (name, d, r)) in panels.iter().zip(series) {
        let n = d.len().max(2);
        let hi = d.iter().chain(r.iter()).cloned().fold(0.0f64, f64::max).max(1e-6) * 1.05;
        let mut chart = ChartBuilder::on(area)
            .caption(format!("{title}: {name}"), ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(0..n, 0.0..hi)
            .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
        chart.configure_mesh().x_desc("frame").draw().map_err(|e| anyhow::anyhow!("plot: {e}"))?;
        chart
            .draw_series(LineSeries::new(d.iter().enumerate().map(|(i, v)| (i, *v)), &BLUE))
            .map_err(|e| anyhow::anyhow!("plot: {e}"))?
            .label("denoised")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE));
        chart
            .draw_series(LineSeries::new(r.iter().enumerate().map(|(i, v)| (i, *v)), &RED))
            .map_err(|e| anyhow::anyhow!("plot: {e}"))?
            .label("raw")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
    }
    root.present().map_err(|e| anyhow::anyhow!("plot: {e}"))?;
    Ok(())
}
