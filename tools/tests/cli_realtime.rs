//! The command-line tools end to end: the real-time commands (render sequences, bench, quality,
//! sweep, reflections, presets, the governor, time to quality).

mod support;

use support::{hush_cli, temp_dir};

#[test]
fn realtime_sequences_are_deterministic_and_ordered() {
    let dir = temp_dir("realtime");
    let path = dir.join("path.json");
    // A three-key camera path with its own clock.
    let keys: Vec<serde_json::Value> = (0..3)
        .map(|k| serde_json::json!({"time": k as f64 * 0.1, "eye": [0.5 * k as f64, 1.6, 8.0], "target": [0.0, 1.4, -6.0], "yfov_degrees": 60.0}))
        .collect();
    std::fs::write(&path, serde_json::json!({ "keys": keys }).to_string()).unwrap();
    let mut runs = vec![];
    for run in ["a", "b"] {
        let out = dir.join(run);
        let o = hush_cli()
            .args([
                "render",
                "level",
                "--mode",
                "realtime",
                "--frames",
                "3",
                "--width",
                "40",
                "--height",
                "24",
                "--denoiser",
                "none",
                "--camera-path",
            ])
            .arg(&path)
            .arg("--out-dir")
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mut names: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["frame_00000.exr", "frame_00001.exr", "frame_00002.exr"]);
        runs.push(
            names
                .iter()
                .map(|n| hush_engine::quality::Image::load(&out.join(n)).unwrap())
                .collect::<Vec<_>>(),
        );
    }
    for (a, b) in runs[0].iter().zip(&runs[1]) {
        assert_eq!(a.data, b.data, "same scene, seed and path must give the same frames");
        assert!(a.data.iter().all(|p| p.is_finite()));
    }
    assert_ne!(runs[0][0].data, runs[0][2].data, "the camera moved");
}

#[test]
fn realtime_bench_reports_every_pass() {
    let profile = temp_dir("bench-profile").join("bench.puffin");
    let o = hush_cli()
        .args([
            "bench",
            "level",
            "--mode",
            "realtime",
            "--json",
            "--width",
            "32",
            "--height",
            "18",
            "--frames",
            "3",
            "--profile",
        ])
        .arg(&profile)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let passes: Vec<&str> =
        v["passes"].as_array().unwrap().iter().map(|p| p["pass"].as_str().unwrap()).collect();
    // The glossy prefilter feeds only the neighbourhood clipping, off by default: it does not run.
    assert_eq!(
        passes,
        [
            "gbuffer",
            "trace",
            "matte/temporal",
            "matte/history_bilateral",
            "matte/disocclusion_h",
            "matte/disocclusion_v",
            "matte/firefly",
            "matte/bilateral",
            "glossy/motion",
            "glossy/temporal",
            "glossy/bilateral_h",
            "glossy/bilateral_v",
            "composite",
            "taa",
            "converge/mean",
            "converge",
            "display",
        ]
    );
    for p in v["passes"].as_array().unwrap() {
        assert!(p["median_ms"].as_f64().unwrap() > 0.0, "{p}");
    }
    assert!(v["gpu_frame_median_ms"].as_f64().unwrap() > 0.0);
    assert!(v["bytes_per_pixel"].as_f64().unwrap() > 0.0);
    // The headless capture: every pass that ran has a CPU scope and a GPU scope with non-zero
    // time in each of the 3 frames, inside a frame scope.
    let scopes = hush_engine::profile::read_capture(&profile).unwrap();
    let find = |gpu: bool, name: &str| {
        scopes
            .iter()
            .find(|(t, n, _, _)| (t == hush_engine::profile::GPU_THREAD) == gpu && n == name)
    };
    for p in &passes {
        let (_, _, ns, count) =
            find(true, p).unwrap_or_else(|| panic!("no GPU scope for {p} in {scopes:?}"));
        assert!(*ns > 0 && *count == 3, "GPU {p}: {ns} ns over {count} frames");
        assert!(find(false, p).is_some_and(|s| s.3 == 3), "no CPU scope for {p} in {scopes:?}");
    }
    for cpu in ["frame", "Renderer::render", "animate", "upload", "encode", "submit"] {
        assert!(find(false, cpu).is_some(), "no CPU scope {cpu} in {scopes:?}");
    }
    assert!(find(true, hush_engine::profile::GPU_FRAME).is_some_and(|s| s.2 > 0));
}

#[test]
fn quality_writes_scores_and_a_plot() {
    let dir = temp_dir("quality");
    let o = hush_cli()
        .args([
            "quality",
            "level",
            "--frames",
            "4",
            "--reference-frames",
            "4",
            "--width",
            "32",
            "--fps",
            "30",
            "--ablations",
            "--out-dir",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.join("quality.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 5, "{csv}");
    assert!(rows[0].starts_with("frame,time,flip,relmse,ssim,temporal_error"));
    assert!(rows[0].ends_with(",uncovered_flip,uncovered_pixels"), "{}", rows[0]);
    for r in &rows[1..] {
        let fields: Vec<&str> = r.split(',').collect();
        assert_eq!(fields.len(), 14, "{r}");
        let v: Vec<f64> = fields[..12].iter().map(|x| x.parse().unwrap()).collect();
        assert!(v.iter().all(|x| x.is_finite()) && v[2] > 0.0 && v[2] < 1.0, "{r}");
        // FLIP over the pixels the matte temporal flagged lately: blank when there are none.
        let pixels: usize = fields[13].parse().unwrap();
        assert_eq!(fields[12].is_empty(), pixels == 0, "{r}");
        assert!(
            fields[12].is_empty() || (0.0..=1.0).contains(&fields[12].parse::<f64>().unwrap()),
            "{r}"
        );
    }
    let ablations = std::fs::read_to_string(dir.join("ablations.csv")).unwrap();
    // Header, the full chain, and each of the 6 matte and 4 glossy stages and switches off.
    assert_eq!(ablations.lines().count(), 12, "{ablations}");
    let png = image_size(&dir.join("quality.png"));
    assert_eq!(png, (960, 720));
}

#[test]
fn quality_reuses_a_cached_reference() {
    let dir = temp_dir("quality-cache");
    let cache = dir.join("references");
    let run = |out: &str| {
        let o = hush_cli()
            .args([
                "quality",
                "level",
                "--frames",
                "3",
                "--reference-frames",
                "4",
                "--width",
                "32",
                "--reference-cache",
            ])
            .arg(&cache)
            .arg("--out-dir")
            .arg(dir.join(out))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        (
            String::from_utf8_lossy(&o.stderr).into_owned(),
            std::fs::read_to_string(dir.join(out).join("quality.csv")).unwrap(),
        )
    };
    let (first_log, first) = run("first");
    // A still camera has one reference, rendered once and kept.
    let kept: Vec<_> = std::fs::read_dir(&cache).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(kept.len(), 1, "{kept:?}");
    assert!(first_log.contains("rendering the reference"), "{first_log}");
    let (second_log, second) = run("second");
    assert!(!second_log.contains("rendering the reference"), "{second_log}");
    // The EXR holds the reference exactly (32-bit floats), so the scores repeat.
    let flips = |csv: &str| {
        csv.lines().skip(1).map(|r| r.split(',').nth(2).unwrap().to_string()).collect::<Vec<_>>()
    };
    assert_eq!(flips(&first), flips(&second));
}

#[test]
fn quality_convergence_scores_every_denoiser_beside_the_accumulation() {
    let dir = temp_dir("convergence");
    let oracle =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/oracle/cornell_diffuse");
    let o = hush_cli()
        .args(["quality"])
        .arg(oracle.join("cornell_diffuse.gltf"))
        .args(["--convergence", "--denoisers", "svgf,mara", "--frames", "8", "--width", "32"])
        .args(["--height", "32", "--reference"])
        .arg(oracle.join("reference.exr"))
        .arg("--out-dir")
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.join("convergence.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|r| r.split(',').collect()).collect();
    assert_eq!(csv.lines().next(), Some("stream,frame,flip,relmse,bias_r,bias_g,bias_b"));
    // Three streams at frames 1, 2, 4 and 8.
    assert_eq!(rows.len(), 12, "{csv}");
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[0], ["accumulation", "svgf", "mara"][k / 4], "{csv}");
        assert_eq!(r[1], ["1", "2", "4", "8"][k % 4], "{csv}");
        let v: Vec<f64> = r[2..].iter().map(|x| x.parse().unwrap()).collect();
        assert!(v.iter().all(|x| x.is_finite()) && v[0] > 0.0 && v[0] < 1.0, "{csv}");
    }
    // The mean of 8 frames against the Mitsuba reference (the reference box-downsampled 8x):
    // relMSE falls about as 1/n (measured 0.222 at 1 frame, 0.032 at 8: 6.9x); at least 3x
    // leaves room for the noise of one 32x32 run and fails if the frames were not accumulated.
    let relmse = |k: usize| rows[k][3].parse::<f64>().unwrap();
    assert!(relmse(0) > 3.0 * relmse(3), "{csv}");
    assert_eq!(image_size(&dir.join("convergence.png")), (960, 720));
    for stream in ["accumulation", "svgf", "mara"] {
        assert_eq!(image_size(&dir.join(format!("last_{stream}.exr"))), (32, 32));
        assert_eq!(image_size(&dir.join(format!("last_{stream}_flip.png"))), (32, 32));
    }
}

fn image_size(p: &std::path::Path) -> (u32, u32) {
    let img = hush_engine::quality::Image::load(p).unwrap();
    (img.width, img.height)
}

#[test]
fn sweep_marks_a_pareto_front() {
    let dir = temp_dir("sweep");
    let o = hush_cli()
        .args([
            "sweep",
            "level",
            "--width",
            "32",
            "--frames",
            "2",
            "--reference-frames",
            "2",
            "--out-dir",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    // 2 scales x 3 denoisers x 4 (paths, samples) x 2 path lengths.
    assert_eq!(rows.len(), 48, "{csv}");
    assert!(rows.iter().any(|r| r[7] == "true"), "no Pareto point: {csv}");
    for r in &rows {
        let ms: f64 = r[5].parse().unwrap();
        let flip: f64 = r[6].parse().unwrap();
        assert!(ms > 0.0 && flip > 0.0 && flip < 1.0, "{r:?}");
    }
    assert_eq!(image_size(&dir.join("pareto.png")), (960, 640));
}

#[test]
fn reflections_measures_every_reprojection() {
    let dir = temp_dir("reflections");
    let o = hush_cli()
        .args([
            "reflections",
            "reflections",
            "--width",
            "32",
            "--frames",
            "3",
            "--path-frames",
            "3",
            "--reference-frames",
            "2",
            "--search-radius",
            "4",
            "--out-dir",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.join("reflections.csv")).unwrap();
    // 4 configurations x (2 temporal errors + 2 FLIPs), 2 sphere kinds x 3 searches x 2 stats.
    assert_eq!(csv.lines().count(), 1 + 16 + 12, "{csv}");
    for name in ["diamond", "virtual", "primary", "no reprojection"] {
        assert!(csv.contains(&format!("still,{name},temporal_error_chain_output,")), "{csv}");
    }
    for row in csv.lines().skip(1) {
        let v: f64 = row.rsplit(',').next().unwrap().parse().unwrap();
        assert!(v.is_finite() && v >= 0.0, "{row}");
    }
}

#[test]
fn a_preset_sets_the_frame() {
    let dir = temp_dir("preset");
    // Direct light only: the indirect light of the level's courtyard and hall goes.
    let preset = dir.join("direct.toml");
    std::fs::write(&preset, "max_depth = 2\n").unwrap();
    let mean = |extra: &[&str], name: &str| {
        let out = dir.join(name);
        let o = hush_cli()
            .args(["render", "level", "--mode", "realtime", "--width", "32", "--height", "18"])
            .args(extra)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let img = image::open(&out).unwrap().to_rgb8();
        img.pixels().map(|p| p.0.iter().map(|&c| c as f64).sum::<f64>()).sum::<f64>()
            / img.pixels().len() as f64
    };
    let plain = mean(&[], "plain.png");
    let direct = mean(&["--preset", preset.to_str().unwrap()], "direct.png");
    assert!(direct < plain * 0.95, "max_depth 2 from the preset: mean {direct:.1} vs {plain:.1}");
}

/// `--target-ms` writes one row per frame with the governor's choices; a target far below what
/// the software driver can do drives it to its smallest choices within a few frames. The
/// target is 1 us: a still view's frames may take `still_ratio` (5) x the target, and at 1 ms a
/// fast machine traced the 32x18 frame at 1/4 spp within 5 ms, which the still view then took.
#[test]
fn governed_render_writes_frames_csv() {
    let dir = temp_dir("governed");
    let o = hush_cli()
        .args([
            "render",
            "level",
            "--mode",
            "realtime",
            "--target-ms",
            "0.001",
            "--frames",
            "8",
            "--width",
            "64",
            "--height",
            "36",
            "--min-scale",
            "0.5",
            // A denoiser that takes sample fractions (render's default, SVGF, does not).
            "--denoiser",
            "none",
            "--out-dir",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.join("frames.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(rows[0], ["frame", "wall_ms", "gpu_ms", "spp", "width", "height", "levels"]);
    assert_eq!(rows.len(), 9, "{csv}");
    for (k, r) in rows[1..].iter().enumerate() {
        assert_eq!(r[0], k.to_string());
        assert!(r[1].parse::<f64>().unwrap() > 0.0);
        let spp: f64 = r[3].parse().unwrap();
        assert!(spp > 0.0 && spp <= 1.0);
        let (w, h): (u32, u32) = (r[4].parse().unwrap(), r[5].parse().unwrap());
        assert!((32..=64).contains(&w) && (18..=36).contains(&h), "{r:?}");
    }
    // 1 us cannot be met, nor 5 us: from the second frame on, the smallest scale and fraction.
    let last = &rows[8];
    assert_eq!((last[3], last[4], last[5], last[6]), ("0.0078125", "32", "18", ""), "{csv}");

    // SVGF with its scale pinned: what cannot be met turns its a-trous levels down to one from
    // the second frame on (the first has nothing to predict from).
    let dir = temp_dir("governed-levels");
    let o = hush_cli()
        .args(["render", "level", "--mode", "realtime", "--target-ms", "1", "--frames", "3"])
        .args(["--width", "32", "--height", "18", "--min-scale", "1", "--denoiser", "svgf"])
        .arg("--out-dir")
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.join("frames.csv")).unwrap();
    let levels: Vec<&str> = csv.lines().skip(1).map(|l| l.rsplit(',').next().unwrap()).collect();
    assert_eq!(levels, ["5", "1", "1"], "{csv}");
}

#[test]
fn time_to_quality_follows_each_run_past_the_last_time() {
    let dir = temp_dir("time-to-quality");
    let o = hush_cli()
        .args([
            "time-to-quality",
            "level",
            "--width",
            "32",
            "--reference-frames",
            "4",
            "--seconds",
            "0.4",
            "--lead-in",
            "0.1",
            "--at",
            "0,0.2,0.4",
        ])
        .args(["--run", "none", "--run", "progressive@30"])
        .arg("--out-dir")
        .arg(&dir)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Two runs in two scenarios, at three times each.
    let at = std::fs::read_to_string(dir.join("at_times.csv")).unwrap();
    assert_eq!(at.lines().count(), 1 + 2 * 2 * 3, "{at}");
    let frames = std::fs::read_to_string(dir.join("time_to_quality.csv")).unwrap();
    for run in ["none", "progressive@30"] {
        for sc in ["stop", "cut"] {
            let rows: Vec<Vec<&str>> = frames
                .lines()
                .map(|l| l.split(',').collect::<Vec<_>>())
                .filter(|r| r[0] == run && r[1] == sc)
                .collect();
            // The image before the stop, then frames until the clock passes --seconds.
            assert!(rows.len() >= 2, "{run} {sc}: {frames}");
            let ends: Vec<f64> = rows[1..].iter().map(|r| r[3].parse().unwrap()).collect();
            assert!(
                ends.windows(2).all(|w| w[1] >= w[0]) && *ends.last().unwrap() >= 0.4,
                "{run} {sc}: {ends:?}"
            );
            assert!(rows.iter().all(|r| r[10].parse::<f64>().unwrap().is_finite()), "{frames}");
        }
    }
    assert!(
        stdout.contains("progressive@30 at or below none")
            || stdout.contains("progressive@30 above none"),
        "{stdout}"
    );
    assert_eq!(image_size(&dir.join("time_to_quality.png")), (960, 840));
}
