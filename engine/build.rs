//! Embeds every WGSL file of `shaders/` (release builds compose from these texts; debug builds
//! and `--shaders` read the folder): `$OUT_DIR/shaders.rs` holds `SOURCES`, one
//! `(path relative to shaders/, text)` per file, found by walking the folder so that a shader
//! added there needs no list kept by hand.

use std::path::{Path, PathBuf};

fn wgsl_files(dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            wgsl_files(&path, out)?;
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            out.push(path);
        }
    }
    Ok(())
}

fn main() -> std::io::Result<()> {
    let manifest =
        PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").map_err(std::io::Error::other)?);
    let shaders = manifest.join("../shaders").canonicalize()?;
    println!("cargo:rerun-if-changed={}", shaders.display());
    let mut files = vec![];
    wgsl_files(&shaders, &mut files)?;
    files.sort();
    let mut code = String::from(
        "/// Every WGSL file under `shaders/`, by path relative to that folder.\n\
         pub const SOURCES: &[(&str, &str)] = &[\n",
    );
    for f in &files {
        let rel = f.strip_prefix(&shaders).map_err(std::io::Error::other)?;
        let rel = rel.to_string_lossy().replace('\\', "/");
        code += &format!("    ({rel:?}, include_str!({:?})),\n", f.display().to_string());
    }
    code += "];\n";
    let out = PathBuf::from(std::env::var("OUT_DIR").map_err(std::io::Error::other)?);
    std::fs::write(out.join("shaders.rs"), code)
}
