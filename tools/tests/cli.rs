//! The command-line tools end to end.

mod support;

use support::{hush_cli, temp_dir};

#[test]
fn render_then_compare_round_trips_through_files() {
    let dir = temp_dir("cli");
    let exr = dir.join("a.exr");
    let png = dir.join("a.png");
    for out in [&exr, &png] {
        let o = hush_cli()
            .args([
                "render",
                "default",
                "--spp",
                "2",
                "--width",
                "33",
                "--height",
                "17",
                "--camera",
                "eye=0,1.4,4.8;target=0,1.1,0;fov=55",
                "--out",
            ])
            .arg(out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let o = hush_cli().args(["compare", "--json"]).arg(&exr).arg(&exr).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(m["rmse"].as_f64(), Some(0.0));
    assert_eq!(m["nonfinite_pixels"].as_u64(), Some(0));
    let img = hush_engine::quality::Image::load(&png).unwrap();
    assert_eq!((img.width, img.height), (33, 17));
}

#[test]
fn bad_arguments_are_clear_errors() {
    let bad_preset = temp_dir("bad-preset").join("bad.toml");
    std::fs::write(&bad_preset, "[matte]\nhysteresis = 2.0\n").unwrap();
    let bad_preset = bad_preset.to_str().unwrap().to_string();
    let ttq = temp_dir("bad-ttq").to_str().unwrap().to_string();
    for (args, needle) in [
        (
            vec![
                "render",
                "level",
                "--mode",
                "realtime",
                "--preset",
                &bad_preset,
                "--out",
                "x.exr",
            ],
            "matte.hysteresis",
        ),
        (
            vec!["bench", "level", "--mode", "realtime", "--preset", "/nonexistent.toml"],
            "/nonexistent.toml",
        ),
        (
            vec!["render", "default", "--camera", "eye=0,0,0;target=0,0,0", "--out", "x.exr"],
            "coincide",
        ),
        (
            vec![
                "render",
                "default",
                "--camera",
                "eye=0,1,4;target=0,1,0;aperture=0.1",
                "--out",
                "x.exr",
            ],
            "focus",
        ),
        (
            vec![
                "render",
                "default",
                "--camera",
                "eye=0,1,4;target=0,1,0;aperture=0;focus=3",
                "--out",
                "x.exr",
            ],
            "aperture radius",
        ),
        (vec!["render", "default", "--spp", "0", "--out", "x.exr"], "--spp"),
        (vec!["render", "default", "--spp", "1", "--out", "x.bmp"], ".exr or .png"),
        (vec!["render", "/nonexistent.gltf", "--out", "x.exr"], "/nonexistent.gltf"),
        (vec!["render", "default", "--mode", "magic", "--out", "x.exr"], "--mode"),
        (
            vec![
                "render", "level", "--mode", "realtime", "--view", "nope", "--width", "8",
                "--height", "8", "--out", "x.png",
            ],
            "--view",
        ),
        (
            vec!["render", "level", "--mode", "realtime", "--frames", "0", "--out", "x.exr"],
            "--frames",
        ),
        (
            vec![
                "render",
                "level",
                "--mode",
                "realtime",
                "--denoiser",
                "mara",
                "--reflection-mv",
                "sideways",
                "--out",
                "x.exr",
            ],
            "--reflection-mv",
        ),
        (
            vec![
                "render",
                "level",
                "--mode",
                "realtime",
                "--denoiser",
                "mara",
                "--disable",
                "glossy.nothing",
                "--out",
                "x.exr",
            ],
            "glossy/bilateral",
        ),
        (
            vec![
                "render",
                "level",
                "--mode",
                "realtime",
                "--denoiser",
                "svgf",
                "--disable",
                "svgf.nothing",
                "--out",
                "x.exr",
            ],
            "svgf.bandwidth_boost",
        ),
        (
            vec!["render", "level", "--mode", "realtime", "--spp", "17", "--out", "x.exr"],
            "at most 16",
        ),
        (
            vec!["render", "level", "--mode", "realtime", "--spp", "1/3", "--out", "x.exr"],
            "power of two",
        ),
        (vec!["render", "default", "--spp", "1/4", "--out", "x.exr"], "--mode realtime"),
        (
            vec![
                "render",
                "level",
                "--mode",
                "realtime",
                "--spp",
                "1/4",
                "--denoiser",
                "mara",
                "--width",
                "8",
                "--height",
                "8",
                "--out",
                "x.exr",
            ],
            "fills untraced pixels",
        ),
        (
            vec!["render", "level", "--mode", "realtime", "--denoiser", "oidn", "--out", "x.exr"],
            "svgf",
        ),
        (vec!["time-to-quality", "level", "--run", "oidn", "--out-dir", &ttq], "--run \"oidn\""),
        (vec!["time-to-quality", "level", "--run", "mara@0", "--out-dir", &ttq], "positive"),
        (
            vec![
                "time-to-quality",
                "level",
                "--run",
                "mara:1/4",
                "--width",
                "8",
                "--height",
                "8",
                "--reference-frames",
                "1",
                "--out-dir",
                &ttq,
            ],
            "sample fractions below 1",
        ),
        (
            vec![
                "time-to-quality",
                "level",
                "--run",
                "mara",
                "--scenarios",
                "pan",
                "--out-dir",
                &ttq,
            ],
            "stop or cut",
        ),
        (vec!["level", "--scene", "terrain:1", "--out", "x.gltf"], "terrain:N"),
        (vec!["render", "level", "--shutter", "1.5", "--out", "x.exr"], "--shutter 1.5"),
        (vec!["render", "level", "--shutter", "0.5", "--fps", "0", "--out", "x.exr"], "--fps"),
        (vec!["render", "level", "--mode", "realtime", "--time", "1", "--out", "x.exr"], "--time"),
        (
            vec![
                "render",
                "level",
                "--mode",
                "realtime",
                "--primary-samples",
                "0",
                "--out",
                "x.exr",
            ],
            "--primary-samples 0",
        ),
        // Guide rays need the raster's G-buffer; an open shutter on the moving cube replaces it.
        (
            vec![
                "render",
                "level",
                "--mode",
                "realtime",
                "--shutter",
                "1",
                "--spp",
                "2",
                "--width",
                "8",
                "--height",
                "8",
                "--out",
                "x.exr",
            ],
            "samples per pixel to 1",
        ),
        (vec!["level", "--scene", "nope", "--out", "x.gltf"], "no such built-in scene"),
        // A built-in scene has no file for Mitsuba to read (and CI has no Mitsuba either way).
        (
            vec![
                "bench",
                "default",
                "--mitsuba",
                "--width",
                "8",
                "--height",
                "8",
                "--spp",
                "1",
                "--rays",
                "64",
                "--bvh",
                "cwbvh",
            ],
            "--mitsuba",
        ),
    ] {
        let o = hush_cli().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn bench_reports_json() {
    let o = hush_cli()
        .args([
            "bench", "default", "--json", "--width", "16", "--height", "16", "--spp", "2",
            "--rays", "4096",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["layouts"].as_array().unwrap().len(), 2);
    for l in v["layouts"].as_array().unwrap() {
        assert!(l["rays_per_second"].as_f64().unwrap() > 0.0);
        assert!(l["samples_per_second"].as_f64().unwrap() > 0.0);
        assert!(l["gpu_bytes"].as_u64().unwrap() > 0);
        assert!(l["bvh_depth"].as_u64().unwrap() >= 2);
    }
}

#[test]
fn terrain_is_generated_and_written() {
    let dir = temp_dir("terrain");
    let out = dir.join("t.gltf");
    let o = hush_cli()
        .args(["level", "--scene", "terrain:5000", "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = hush_cli()
        .args([
            "bench",
            out.to_str().unwrap(),
            "--json",
            "--width",
            "8",
            "--height",
            "8",
            "--spp",
            "1",
            "--rays",
            "1024",
            "--bvh",
            "cwbvh",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let t = v["triangles"].as_u64().unwrap();
    assert!((4900..=5100).contains(&t), "{t} triangles");
}

#[test]
fn conformance_reports_loaded_refused_and_why() {
    let dir = temp_dir("conformance-in");
    let good = dir.join("Room/glTF/room.gltf");
    let o = hush_cli().args(["level", "--scene", "default", "--out"]).arg(&good).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::create_dir_all(dir.join("Draco/glTF")).unwrap();
    std::fs::write(
        dir.join("Draco/glTF/draco.gltf"),
        r#"{"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"]}"#,
    )
    .unwrap();
    std::fs::write(dir.join("broken.glb"), b"glTF\x02\x00\x00\x00\x08\x00\x00\x00").unwrap();
    std::fs::write(dir.join("notes.txt"), "not a scene").unwrap();
    let out = temp_dir("conformance-out");
    let o = hush_cli()
        .args(["conformance"])
        .arg(&dir)
        .args(["--width", "16", "--height", "16", "--spp", "2", "--frames", "2", "--out-dir"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("conformance.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3, "{csv}");
    let row = |name: &str| {
        rows.iter().find(|r| r[0].ends_with(name)).unwrap_or_else(|| panic!("{name}: {csv}"))
    };
    assert_eq!(row("room.gltf")[1], "loaded", "{csv}");
    assert!(
        row("draco.gltf")[1] == "refused"
            && row("draco.gltf")[2].contains("KHR_draco_mesh_compression"),
        "{csv}"
    );
    assert!(row("broken.glb")[1] == "refused" && row("broken.glb")[2].contains("GLB"), "{csv}");
    assert!(out.join("Room_glTF_room.gltf.reference.png").exists());
    assert!(out.join("Room_glTF_room.gltf.realtime.png").exists());
    assert!(String::from_utf8_lossy(&o.stdout).contains("3 files: 1 loaded, 2 refused, 0 wrong"));
}
