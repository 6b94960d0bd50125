//! `hush-cli quality --convergence`: whether each denoiser keeps improving in a still view.
//! Every denoiser named by `--denoisers` and the plain accumulation of the same real-time frames
//! (same seed, so the same samples) render `--frames` frames of one still view; at frames 1, 2,
//! 4, ... (and 60 and 240, the frames the targets name) each is scored against the reference:
//! FLIP, relMSE and the mean bias per channel. A denoiser converges when its relMSE stays within
//! a small factor of the accumulation's as the frames grow and its bias stays near zero; one
//! whose spatial reach does not fall with the variance flattens out on the log-log plot.
//! Writes convergence.csv, convergence.png (log frame axis, FLIP and relMSE) and each stream's
//! last frame (`last_<stream>.exr`, and its FLIP heat map against the reference, `.png`).

use crate::cli::preset_settings;
use crate::quality_args::QualityArgs;
use anyhow::{Context, Result, bail};
use hush_engine::frame::FrameInput;
use hush_engine::gpu::Gpu;
use hush_engine::quality::{Image, compare, save_flip_heatmap};
use hush_engine::scene::Scene;
use hush_engine::settings::FrameSettings;
use std::io::Write;
use std::path::Path;

/// One stream's scores at the checkpoints.
struct Curve {
    name: String,
    /// (frame, FLIP, relMSE, mean relative bias per channel).
    points: Vec<(u32, f64, f64, [f64; 3])>,
}

/// The frames scored: powers of two up to `frames`, the targets' 60 and 240, and the last.
pub fn checkpoints(frames: u32) -> Vec<u32> {
    let mut v: Vec<u32> = (0..32).map(|i| 1u32 << i).take_while(|f| *f <= frames).collect();
    v.extend([60, 240, frames].into_iter().filter(|f| *f <= frames));
    v.sort_unstable();
    v.dedup();
    v
}

pub fn run(a: &QualityArgs, scene: Scene, size: (u32, u32), input: FrameInput) -> Result<()> {
    if a.camera_path.is_some() || a.fps > 0.0 {
        bail!("--convergence measures a still view: leave out --camera-path and --fps");
    }
    let names: Vec<&str> = a.denoisers.iter().map(String::as_str).collect();
    if names.is_empty() {
        bail!("--denoisers names no denoiser");
    }
    let prepared = hush_engine::gpu::PreparedScene::new(&scene, crate::cli::bvh_kind(&None)?)?;
    let gpu = Gpu::headless(&prepared.realtime_requirements(size))?;
    let max_depth = crate::cli::path_length(None, a.preset.as_deref(), scene.max_depth)?;
    let reference = match &a.reference {
        Some(path) => external_reference(path, size)?,
        None => {
            if a.reference_frames < 4 * a.frames {
                eprintln!(
                    "warning: the reference accumulates {} frames, fewer than 4x the {} measured: \
                     its own noise will show as a floor (pass --reference-frames or --reference)",
                    a.reference_frames, a.frames
                );
            }
            let mut r = crate::reference::new_renderer(&gpu, &scene, size)?;
            let acc = FrameSettings {
                accumulate: true,
                seed: a.seed.wrapping_add(7919),
                max_depth,
                ..Default::default()
            };
            crate::reference::reference(
                &gpu,
                &mut r,
                &a.scene,
                &input,
                a.reference_frames,
                &acc,
                a.reference_cache.as_deref(),
            )?
        }
    };
    let marks = checkpoints(a.frames);
    let accumulation =
        FrameSettings { accumulate: true, seed: a.seed, max_depth, ..Default::default() };
    let mut curves = vec![curve(
        "accumulation",
        &gpu,
        &scene,
        size,
        &input,
        &accumulation,
        &marks,
        &reference,
        &a.out_dir,
    )?];
    for name in names {
        let chains = preset_settings(
            a.preset.as_deref(),
            Some(name),
            &a.disable,
            a.reflection_mv.as_deref(),
        )?;
        let settings = FrameSettings { seed: a.seed, max_depth, ..chains };
        curves.push(curve(
            name, &gpu, &scene, size, &input, &settings, &marks, &reference, &a.out_dir,
        )?);
    }
    write_csv(&a.out_dir.join("convergence.csv"), &curves)?;
    plot(&a.out_dir.join("convergence.png"), &curves, &a.scene)?;
    report(&curves, &a.scene, size, &gpu);
    Ok(())
}

/// A reference image from a file (a Mitsuba render), box-downsampled when the run is at an
/// integer fraction of its size (`compare::at_render_size`).
fn external_reference(path: &Path, size: (u32, u32)) -> Result<Image> {
    let y = Image::load(path).with_context(|| format!("reference image {}", path.display()))?;
    let (y, _) = crate::compare::at_render_size(y, size)?;
    if (y.width, y.height) != size {
        bail!(
            "reference {} is {}x{}: render at its size or an integer fraction of it (asked {}x{})",
            path.display(),
            y.width,
            y.height,
            size.0,
            size.1
        );
    }
    Ok(y)
}

#[allow(clippy::too_many_arguments)]
fn curve(
    name: &str,
    gpu: &Gpu,
    scene: &Scene,
    size: (u32, u32),
    input: &FrameInput,
    settings: &FrameSettings,
    marks: &[u32],
    reference: &Image,
    out_dir: &Path,
) -> Result<Curve> {
    let mut r = crate::reference::new_renderer(gpu, scene, size)?;
    let start = std::time::Instant::now();
    let mut points = vec![];
    let last = marks.last().copied().unwrap_or(0);
    for frame in 1..=last {
        r.render(gpu, input, settings, None).with_context(|| format!("{name}, frame {frame}"))?;
        if marks.contains(&frame) {
            let img = r.read_hdr(gpu)?;
            let m = compare(&img, reference)?;
            points.push((frame, m.flip, m.relmse, m.mean_rel_bias));
            if frame == last {
                img.save(&out_dir.join(format!("last_{name}.exr")))?;
                save_flip_heatmap(&img, reference, &out_dir.join(format!("last_{name}_flip.png")))?;
            }
        }
    }
    eprintln!("{name}: {last} frames in {:.1} s", start.elapsed().as_secs_f64());
    Ok(Curve { name: name.to_string(), points })
}

fn write_csv(path: &Path, curves: &[Curve]) -> Result<()> {
    let mut f =
        std::fs::File::create(path).with_context(|| format!("writing {}", path.display()))?;
    writeln!(f, "stream,frame,flip,relmse,bias_r,bias_g,bias_b")?;
    for c in curves {
        for (frame, flip, relmse, b) in &c.points {
            writeln!(
                f,
                "{},{frame},{flip:.5},{relmse:.7},{:.5},{:.5},{:.5}",
                c.name, b[0], b[1], b[2]
            )?;
        }
    }
    Ok(())
}

/// Each stream's last scores, its relMSE over the accumulation's and whether FLIP at 240 is
/// below FLIP at 60 (the convergence targets).
fn report(curves: &[Curve], scene: &str, size: (u32, u32), gpu: &Gpu) {
    println!("{scene} at {}x{}, still view, on {}", size.0, size.1, gpu.info.name);
    println!("  stream        frame  FLIP     relMSE     relMSE/acc  max |bias|  FLIP 240 < 60");
    let acc_last = curves.first().and_then(|c| c.points.last()).map(|p| p.2);
    for c in curves {
        let Some(&(frame, flip, relmse, bias)) = c.points.last() else { continue };
        let at = |f: u32| c.points.iter().find(|p| p.0 == f).map(|p| p.1);
        let falls = match (at(60), at(240)) {
            (Some(a), Some(b)) => {
                if b < a {
                    "yes"
                } else {
                    "no"
                }
            }
            _ => "-",
        };
        let ratio = acc_last.map_or(f64::NAN, |acc| relmse / acc);
        let worst = bias.iter().fold(0.0f64, |m, b| m.max(b.abs()));
        println!(
            "  {:12}  {frame:5}  {flip:.4}  {relmse:.7}  {ratio:10.2}  {:9.2}%  {falls}",
            c.name,
            100.0 * worst
        );
    }
}

/// FLIP and relMSE against frames, both axes logarithmic, one line per stream.
fn plot(path: &Path, curves: &[Curve], title: &str) -> Result<()> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| anyhow::anyhow!("plot: {e}");
    let _ = plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    );
    let root = BitMapBackend::new(path, (960, 720)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let panels = root.split_evenly((2, 1));
    let last = curves.iter().flat_map(|c| c.points.last()).map(|p| p.0).max().unwrap_or(1);
    let colours = [BLACK, BLUE, RED, GREEN, MAGENTA, CYAN];
    for (k, area) in panels.iter().enumerate() {
        let value = |p: &(u32, f64, f64, [f64; 3])| if k == 0 { p.1 } else { p.2 };
        let values: Vec<f64> =
            curves.iter().flat_map(|c| c.points.iter().map(value)).filter(|v| *v > 0.0).collect();
        let lo = values.iter().cloned().fold(f64::INFINITY, f64::min).min(1.0) * 0.9;
        let hi = values.iter().cloned().fold(0.0f64, f64::max).max(lo * 2.0) * 1.1;
        let name = if k == 0 { "FLIP" } else { "relMSE" };
        let mut chart = ChartBuilder::on(area)
            .caption(format!("{title}: {name} against frames (still view)"), ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(70)
            .build_cartesian_2d((1f64..last.max(2) as f64).log_scale(), (lo..hi).log_scale())
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .light_line_style(RGBColor(240, 240, 240))
            .x_desc("frame")
            .draw()
            .map_err(|e| err(&e))?;
        for (c, colour) in curves.iter().zip(colours.iter().cycle()) {
            let line: Vec<(f64, f64)> = c
                .points
                .iter()
                .filter(|p| value(p) > 0.0)
                .map(|p| (p.0 as f64, value(p)))
                .collect();
            let colour = *colour;
            chart
                .draw_series(LineSeries::new(line, colour.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(c.name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
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
    use super::checkpoints;

    #[test]
    fn checkpoints_are_log_spaced_with_the_targets_frames() {
        assert_eq!(checkpoints(1), vec![1]);
        assert_eq!(checkpoints(6), vec![1, 2, 4, 6]);
        assert_eq!(checkpoints(1024), vec![1, 2, 4, 8, 16, 32, 60, 64, 128, 240, 256, 512, 1024]);
    }
}
