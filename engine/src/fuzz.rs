//! What the fuzz targets (`fuzz/`, run with `cargo fuzz`) feed Hush, here so that the tests replay
//! every seed of the corpus and every input a fuzzer ever crashed on (`fuzz/corpus`,
//! `fuzz/regressions`) on each `cargo test`, without the fuzzer.
//!
//! A scene input is an archive of the scene file and the side files it names:
//! the scene's bytes (.gltf JSON or .glb), then for each side file [`FILE_MARK`], its name, a
//! newline and its bytes. An image input is one file's bytes: an EXR (by its magic number) or a
//! PNG/JPEG, decoded as textures and environment maps are.

use crate::limits::{Budget, Limits};
use crate::scene::{LoadOptions, MemoryFiles, Scene, load_gltf_from};
use anyhow::Result;

/// Separates the files of a scene archive.
pub const FILE_MARK: &[u8] = b"\n--hush-file:";

/// Budgets small enough that every input finishes in milliseconds and well inside libFuzzer's
/// memory limit; the code paths are those of the default budgets.
pub const FUZZ_LIMITS: Limits = Limits {
    file_bytes: 1 << 20,
    json_bytes: 1 << 20,
    image_pixels: 1 << 20,
    decoded_bytes: 64 << 20,
    nodes: 10_000,
    hierarchy_depth: 64,
    triangles: 100_000,
};

/// Split an archive into the scene's bytes and its side files.
pub fn unpack(data: &[u8]) -> (&[u8], MemoryFiles) {
    let mut parts = split(data, FILE_MARK);
    let scene = parts.next().unwrap_or_default();
    let mut files = MemoryFiles::default();
    for part in parts {
        let (name, bytes) = match part.iter().position(|&b| b == b'\n') {
            Some(i) => (&part[..i], &part[i + 1..]),
            None => (part, &[][..]),
        };
        files.insert(&String::from_utf8_lossy(name), bytes.to_vec());
    }
    (scene, files)
}

/// The inverse of [`unpack`].
pub fn pack(scene: &[u8], files: &[(&str, &[u8])]) -> Vec<u8> {
    let mut out = scene.to_vec();
    for (name, bytes) in files {
        out.extend_from_slice(FILE_MARK);
        out.extend_from_slice(name.as_bytes());
        out.push(b'\n');
        out.extend_from_slice(bytes);
    }
    out
}

fn split<'a>(data: &'a [u8], mark: &'a [u8]) -> impl Iterator<Item = &'a [u8]> + 'a {
    let mut rest = Some(data);
    std::iter::from_fn(move || {
        let r = rest?;
        match r.windows(mark.len()).position(|w| w == mark) {
            Some(i) => {
                rest = Some(&r[i + mark.len()..]);
                Some(&r[..i])
            }
            None => {
                rest = None;
                Some(r)
            }
        }
    })
}

/// The scene target: load the archive's scene as `hush` would, then prepare it for the GPU
/// (flattening, both BVH layouts, materials, lights, environment, textures), which needs no
/// device. Any error is fine; a panic, a hang or a runaway allocation is the bug.
pub fn scene(data: &[u8]) -> Result<Scene> {
    let (bytes, files) = unpack(data);
    let opts = LoadOptions { max_texture_size: 64, limits: FUZZ_LIMITS, animation: None };
    let mut scene = match load_gltf_from(bytes, "fuzz", &files, &opts) {
        // The fuzzer records panics: an import panic caught at the boundary is re-raised so
        // that it counts as the bug it is.
        #[allow(clippy::panic)]
        Err(e) if matches!(crate::Error::find(&e), Some(crate::Error::ImportPanic(_))) => {
            panic!("{e:#}")
        }
        r => r?,
    };
    scene.add_sun_and_sky_if_unlit();
    for kind in [crate::accel::BvhKind::Cwbvh, crate::accel::BvhKind::Bvh2] {
        crate::gpu::PreparedScene::new(&scene, kind)?;
    }
    Ok(scene)
}

/// The image target: decode as a texture (PNG, JPEG) or as an environment map (EXR).
pub fn image(data: &[u8]) -> Result<()> {
    let mut budget = Budget::new(FUZZ_LIMITS);
    if data.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        let map = crate::scene::EnvMap::from_exr("fuzz.exr", data, 1.0, 0.0, &mut budget)?;
        // The environment's importance-sampling tables, as the GPU scene builds them.
        let scene =
            Scene { environment: crate::scene::Environment::Map(map), ..Default::default() };
        crate::gpu::PreparedScene::new(&scene, crate::accel::BvhKind::DEFAULT)?;
    } else {
        crate::scene::Texture::decode("fuzz.png", data, true, 64, &mut budget)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn archives_round_trip() {
        let a = pack(b"{}", &[("a.bin", b"\x00\x01"), ("tex/b.png", b"")]);
        let (scene, files) = unpack(&a);
        assert_eq!(scene, b"{}");
        use crate::scene::SceneFiles;
        assert_eq!(files.read(Path::new("a.bin"), 10).unwrap(), b"\x00\x01");
        assert_eq!(files.read(Path::new("tex/b.png"), 10).unwrap(), b"");
    }

    /// Every seed of the corpus and every input a fuzzer crashed on, replayed: none may panic.
    /// The seeds' outcomes are pinned too, so a seed that stops loading is noticed.
    #[test]
    fn fuzz_corpus_and_regressions_replay_without_panics() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz");
        let mut replayed = 0;
        for (dir, target) in [
            ("corpus/scene", 0),
            ("regressions/scene", 0),
            ("corpus/image", 1),
            ("regressions/image", 1),
        ] {
            let Ok(entries) = std::fs::read_dir(root.join(dir)) else { continue };
            for e in entries {
                let path = e.unwrap().path();
                let data = std::fs::read(&path).unwrap();
                let outcome = std::panic::catch_unwind(|| {
                    if target == 0 { scene(&data).map(|_| ()) } else { image(&data) }
                });
                let name = path.file_name().unwrap().to_string_lossy().to_string();
                let r = outcome.unwrap_or_else(|_| panic!("{dir}/{name} panics"));
                eprintln!(
                    "{dir}/{name}: {:?}",
                    r.as_ref().map(|_| ()).map_err(|e| format!("{e:#}"))
                );
                // Seeds named ok-* load; the others are refused.
                if dir.starts_with("corpus") {
                    assert_eq!(r.is_ok(), name.starts_with("ok-"), "{dir}/{name}: {r:?}");
                }
                replayed += 1;
            }
        }
        assert!(replayed >= 20, "only {replayed} fuzz inputs found under {}", root.display());
    }
}
