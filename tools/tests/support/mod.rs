//! Support for the command-line suites: writing bad scenes, and running `hush-cli` on them with
//! a time limit while measuring its peak memory. Each suite uses a part of it.
#![allow(dead_code)]

use serde_json::{Value, json};
use std::ffi::OsStr;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How a run of `hush-cli` ended.
#[derive(Debug)]
pub struct Outcome {
    /// The exit code; None if a signal ended it.
    pub code: Option<i32>,
    pub stderr: String,
    /// Peak resident memory (VmHWM, as the child reports it), MiB; NaN where it did not report
    /// (an argument error exits before).
    pub peak_mib: f64,
    pub secs: f64,
}

impl Outcome {
    /// Exited 1 with an error that says `needle`, and no panic.
    pub fn refused(&self, needle: &str) -> bool {
        self.code == Some(1) && self.stderr.contains(needle) && !self.panicked()
    }

    pub fn panicked(&self) -> bool {
        self.stderr.contains("panicked") || self.stderr.contains("internal error")
    }
}

/// Run `hush-cli args`, killing it after `limit`. Its peak memory is what it reports of itself
/// with `HUSH_PEAK_MEMORY` set (VmHWM): a child's rusage maxrss starts from this (large, parallel)
/// test process's resident size at spawn.
pub fn run<S: AsRef<OsStr>>(args: &[S], limit: Duration) -> Outcome {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hush-cli"))
        .args(args)
        .env("HUSH_PEAK_MEMORY", "1")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starting hush-cli");
    let mut pipe = child.stderr.take().expect("stderr");
    let reader = std::thread::spawn(move || {
        let mut s = vec![];
        let _ = pipe.read_to_end(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("waiting for hush-cli") {
            break status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            let stderr = String::from_utf8_lossy(&reader.join().unwrap_or_default()).into_owned();
            panic!(
                "hush-cli {:?} ran past {limit:?}: {}",
                args.iter().map(|a| a.as_ref().to_owned()).collect::<Vec<_>>(),
                tail(&stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let secs = start.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&reader.join().unwrap_or_default()).into_owned();
    let kib: f64 = stderr
        .lines()
        .find_map(|l| l.strip_prefix("peak memory: ")?.strip_suffix(" kB")?.parse().ok())
        .unwrap_or(f64::NAN);
    Outcome { code: status.code(), stderr, peak_mib: kib / 1024.0, secs }
}

/// The end of a long text, for a failure message.
pub fn tail(s: &str) -> &str {
    let start = s.char_indices().rev().nth(1500).map_or(0, |(i, _)| i);
    &s[start..]
}

/// A folder for this test process's cases.
pub fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hush-hostile-{}", std::process::id())).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A unit quad lying in y = 0, facing up: positions, normals, texture coordinates and u32
/// indices (152 bytes), the layout of [`quad_doc`]'s buffer.
pub fn quad_bin() -> Vec<u8> {
    let mut b = vec![];
    for p in [[-1.0f32, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]] {
        p.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
    }
    for _ in 0..4 {
        [0.0f32, 1.0, 0.0].iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
    }
    for uv in [[0.0f32, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]] {
        uv.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
    }
    for i in [0u32, 2, 1, 0, 3, 2] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

/// A scene of one emissive quad seen from above through a perspective camera, its buffer in
/// `scene.bin`: every hostile case starts from it and breaks one thing.
pub fn quad_doc() -> Value {
    // Looking straight down: a -90 degree turn about +X.
    let s = std::f64::consts::FRAC_1_SQRT_2;
    json!({
        "asset": {"version": "2.0"},
        "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 3, 0.01], "rotation": [-s, 0, 0, s]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0}, "emissiveFactor": [1, 1, 1]}],
        "buffers": [{"uri": "scene.bin", "byteLength": 152}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": 32}, {"buffer": 0, "byteOffset": 128, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5125, "count": 6, "type": "SCALAR"}
        ]
    })
}

/// Write `doc` as `scene.gltf` in a fresh folder `name` with the quad's `scene.bin` and `files`.
pub fn write_case(name: &str, doc: &Value, files: &[(&str, &[u8])]) -> PathBuf {
    let d = dir(name);
    std::fs::write(d.join("scene.bin"), quad_bin()).unwrap();
    for (f, bytes) in files {
        std::fs::write(d.join(f), bytes).unwrap();
    }
    let path = d.join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec(doc).unwrap()).unwrap();
    path
}

/// `doc` with a base-colour texture whose image is `image`.
pub fn textured(mut doc: Value, image: Value) -> Value {
    doc["images"] = json!([image]);
    doc["textures"] = json!([{"source": 0}]);
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
    doc
}

/// Replace `path` (a file or nothing) with a symlink to `target`.
pub fn symlink(target: &Path, path: &Path) {
    let _ = std::fs::remove_file(path);
    std::os::unix::fs::symlink(target, path).unwrap();
}

/// Replace `path` with a named pipe nobody writes to: opening it for reading blocks forever.
pub fn fifo(path: &Path) {
    let _ = std::fs::remove_file(path);
    let made = Command::new("mkfifo").arg(path).status().is_ok_and(|s| s.success());
    assert!(made, "mkfifo {}", path.display());
}

/// A grayscale PNG of `w` x `h` black pixels, streamed so that the test never holds the image:
/// a few hundred kilobytes that decode to w x h bytes (x4 as RGBA).
pub fn png_bomb(w: u32, h: u32) -> Vec<u8> {
    let mut out = vec![];
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Fast);
    let mut writer = enc.write_header().unwrap();
    let mut stream = writer.stream_writer().unwrap();
    let row = vec![0u8; w as usize];
    for _ in 0..h {
        std::io::Write::write_all(&mut stream, &row).unwrap();
    }
    stream.finish().unwrap();
    drop(writer);
    out
}

/// The header of a scanline EXR of `w` x `h` RGB half pixels, and no pixels.
pub fn exr_header(w: i32, h: i32) -> Vec<u8> {
    fn attr(out: &mut Vec<u8>, name: &str, ty: &str, data: &[u8]) {
        out.extend_from_slice(name.as_bytes());
        out.push(0);
        out.extend_from_slice(ty.as_bytes());
        out.push(0);
        out.extend_from_slice(&(data.len() as i32).to_le_bytes());
        out.extend_from_slice(data);
    }
    let ints = |v: &[i32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let mut channels = vec![];
    for c in ["B", "G", "R"] {
        channels.extend_from_slice(c.as_bytes());
        channels.push(0);
        channels.extend_from_slice(&ints(&[1, 0, 1, 1]));
    }
    channels.push(0);
    let mut out = ints(&[20000630, 2]);
    attr(&mut out, "channels", "chlist", &channels);
    attr(&mut out, "compression", "compression", &[0]);
    attr(&mut out, "dataWindow", "box2i", &ints(&[0, 0, w - 1, h - 1]));
    attr(&mut out, "displayWindow", "box2i", &ints(&[0, 0, w - 1, h - 1]));
    attr(&mut out, "lineOrder", "lineOrder", &[0]);
    attr(&mut out, "pixelAspectRatio", "float", &1f32.to_le_bytes());
    attr(&mut out, "screenWindowCenter", "v2f", &[0; 8]);
    attr(&mut out, "screenWindowWidth", "float", &1f32.to_le_bytes());
    out.push(0);
    out
}

/// `hush-cli`, built for these tests.
pub fn hush_cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hush-cli"))
}

/// A fresh folder for one test's files.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hush-cli-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Long enough for any case on a loaded 2-core CI machine; the hangs these cases caught ran
/// until killed.
pub const LIMIT: Duration = Duration::from_secs(60);
/// Peak memory of a run refused while loading: the process itself takes about 10 MiB.
pub const REFUSED_MIB: f64 = 64.0;

/// `hush-cli render SCENE --width 8 --height 8 --spp 1 --out OUT.png` plus `extra` flags.
pub fn render(scene: &Path, extra: &[&str]) -> (Outcome, PathBuf) {
    let out = scene.with_file_name("out.png");
    let _ = std::fs::remove_file(&out);
    let mut args: Vec<String> = vec![
        "render".into(),
        scene.display().to_string(),
        "--width".into(),
        "8".into(),
        "--height".into(),
        "8".into(),
    ];
    if !extra.contains(&"realtime") {
        args.extend(["--spp".into(), "1".into()]);
    }
    args.extend(extra.iter().map(|s| s.to_string()));
    args.extend(["--out".into(), out.display().to_string()]);
    (run(&args, LIMIT), out)
}

/// Refused with `needle` in the error, nothing written, little memory spent.
#[track_caller]
pub fn assert_refused(name: &str, scene: &Path, extra: &[&str], needle: &str) -> Outcome {
    let (o, out) = render(scene, extra);
    assert!(
        o.refused(needle),
        "{name}: expected exit 1 with {needle:?}, got {:?}: {}",
        o.code,
        tail(&o.stderr)
    );
    assert!(!out.exists(), "{name}: an output was written");
    assert!(o.peak_mib < REFUSED_MIB, "{name}: {:.1} MiB to refuse a file", o.peak_mib);
    o
}

/// Rendered (exit 0, an image written) with `needle` among the warnings, if one is given.
#[track_caller]
pub fn assert_renders(name: &str, scene: &Path, extra: &[&str], needle: &str) -> Outcome {
    let (o, out) = render(scene, extra);
    assert!(
        o.code == Some(0) && out.exists() && !o.panicked(),
        "{name}: expected a render, got {:?}: {}",
        o.code,
        tail(&o.stderr)
    );
    assert!(o.stderr.contains(needle), "{name}: expected {needle:?} in: {}", tail(&o.stderr));
    o
}

pub fn case(name: &str, mutate: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let mut doc = quad_doc();
    mutate(&mut doc);
    write_case(name, &doc, &[])
}
