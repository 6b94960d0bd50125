//! The command-line tools end to end.

use std::process::Command;

fn bin(_: &str) -> Command {
    Command::new(env!("CARGO_BIN_EXE_hush-cli"))
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("hush-cli-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn render_then_compare_round_trips_through_files() {
    let dir = temp_dir("cli");
    let exr = dir.join("a.exr");
    let png = dir.join("a.png");
    for out in [&exr, &png] {
        let o = bin("hush-cli")
            .args(["render", "default", "--spp", "2", "--width", "33", "--height", "17", "--camera", "eye=0,1.4,4.8;target=0,1.1,0;fov=55", "--out"])
            .arg(out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let o = bin("hush-cli").args(["compare", "--json"]).arg(&exr).arg(&exr).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(m["rmse"].as_f64(), Some(0.0));
    assert_eq!(m["nonfinite_pixels"].as_u64(), Some(0));
    let img = hush_engine::quality::Image::load(&png).unwrap();
    assert_eq!((img.width, img.height), (33, 17));
}

#[test]
fn bad_arguments_are_clear_errors() {
    for (args, needle) in [
        (vec!["render", "default", "--camera", "eye=0,0,0;target=0,0,0", "--out", "x.exr"], "coincide"),
        (vec!["render", "default", "--spp", "0", "--out", "x.exr"], "--spp"),
        (vec!["render", "default", "--spp", "1", "--out", "x.bmp"], ".exr or .png"),
        (vec!["render", "/nonexistent.gltf", "--out", "x.exr"], "/nonexistent.gltf"),
        (vec!["render", "default", "--mode", "magic", "--out", "x.exr"], "--mode"),
    ] {
        let o = bin("hush-cli").args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn bench_reports_json() {
    let o = bin("hush-cli").args(["bench", "default", "--json", "--width", "16", "--height", "16", "--spp", "2", "--rays", "4096"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["layouts"].as_array().unwrap().len(), 2);
    for l in v["layouts"].as_array().unwrap() {
        assert!(l["rays_per_second"].as_f64().unwrap() > 0.0);
        assert!(l["samples_per_second"].as_f64().unwrap() > 0.0);
        assert!(l["gpu_bytes"].as_u64().unwrap() > 0);
    }
}

