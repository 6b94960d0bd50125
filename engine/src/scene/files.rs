//! The files a scene reads. URIs are relative paths that stay inside the scene's folder, or
//! embedded `data:` URIs; anything else is refused. On disk the path is resolved to its real
//! location first, so a symlink cannot lead a scene out of its folder, and only regular files
//! are opened (a FIFO would block, a device never end), each within the file-bytes budget.

use crate::limits::{over_budget, read_regular_file};
use anyhow::{Context, Result, anyhow, bail};
use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};

/// Where a scene's side files come from.
pub trait SceneFiles {
    /// The bytes of `rel`, a path inside the scene's folder as [`relative_path`] returns it,
    /// refusing a file of more than `limit` bytes.
    fn read(&self, rel: &Path, limit: u64) -> Result<Vec<u8>>;
}

/// A scene's folder on disk.
pub struct SceneFolder {
    /// Canonical (symlinks resolved).
    root: PathBuf,
}

impl SceneFolder {
    pub fn new(dir: &Path) -> Result<SceneFolder> {
        let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
        let root = std::fs::canonicalize(dir)
            .with_context(|| format!("resolving the scene's folder {}", dir.display()))?;
        Ok(SceneFolder { root })
    }
}

impl SceneFiles for SceneFolder {
    fn read(&self, rel: &Path, limit: u64) -> Result<Vec<u8>> {
        let path = self.root.join(rel);
        let real =
            std::fs::canonicalize(&path).map_err(|e| anyhow!("reading {}: {e}", path.display()))?;
        if !real.starts_with(&self.root) {
            bail!(
                "{} leads outside the scene's folder (to {}); refused",
                path.display(),
                real.display()
            );
        }
        read_regular_file(&real, limit)
    }
}

/// Files held in memory by their relative path (the fuzzer's scenes, tests).
#[derive(Clone, Debug, Default)]
pub struct MemoryFiles {
    files: HashMap<PathBuf, Vec<u8>>,
}

impl MemoryFiles {
    /// Add a file under `name` (normalised as a URI would be); a name a URI could not reach is
    /// ignored.
    pub fn insert(&mut self, name: &str, bytes: Vec<u8>) {
        if let Ok(rel) = relative_path(name) {
            self.files.insert(rel, bytes);
        }
    }
}

impl SceneFiles for MemoryFiles {
    fn read(&self, rel: &Path, limit: u64) -> Result<Vec<u8>> {
        let bytes = self
            .files
            .get(rel)
            .ok_or_else(|| anyhow!("reading {}: no such file", rel.display()))?;
        if bytes.len() as u64 > limit {
            return Err(over_budget("file-bytes", rel.display(), bytes.len() as u64, limit));
        }
        Ok(bytes.clone())
    }
}

/// The bytes behind `uri`: a `data:` URI's payload, or the file it names in `files`.
pub fn read_uri(files: &dyn SceneFiles, uri: &str, limit: u64) -> Result<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or_else(|| anyhow!("data URI {} has no base64 payload", short(uri)))?;
        let decoded_len = data.len() as u64 / 4 * 3;
        if decoded_len > limit {
            return Err(over_budget(
                "file-bytes",
                format_args!("data URI {}", short(uri)),
                decoded_len,
                limit,
            ));
        }
        return base64_decode(data).with_context(|| format!("data URI {}", short(uri)));
    }
    files.read(&relative_path(uri)?, limit)
}

/// The path a URI names inside the scene's folder, with `.` and `..` folded; refuses URIs that
/// are absolute, carry a scheme, or climb out of the folder.
pub fn relative_path(uri: &str) -> Result<PathBuf> {
    let decoded = percent_encoding::percent_decode_str(uri).decode_utf8_lossy().into_owned();
    if decoded.contains("://")
        || decoded.starts_with('/')
        || decoded.starts_with('\\')
        || decoded.contains('\0')
    {
        bail!("refusing URI {}: only paths relative to the scene's folder are allowed", short(uri));
    }
    let mut parts: Vec<&std::ffi::OsStr> = vec![];
    for c in Path::new(&decoded).components() {
        match c {
            Component::Normal(p) => parts.push(p),
            Component::CurDir => {}
            Component::ParentDir => {
                if parts.pop().is_none() {
                    bail!("refusing URI {}: it leaves the scene's folder", short(uri));
                }
            }
            Component::RootDir | Component::Prefix(_) => {
                bail!("refusing URI {}: absolute paths are not allowed", short(uri))
            }
        }
    }
    if parts.is_empty() {
        bail!("URI {} names no file", short(uri));
    }
    Ok(parts.iter().collect())
}

/// `s` for an error message: a URI can be a 20 MB `data:` payload.
pub fn short(s: &str) -> String {
    const KEEP: usize = 64;
    if s.len() <= KEEP + 16 {
        return format!("{s:?}");
    }
    let head: String = s.chars().take(KEEP).collect();
    format!("{head:?}... ({} bytes)", s.len())
}

fn base64_decode(s: &str) -> Result<Vec<u8>> {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD
        .decode(s.trim())
        .map_err(|e| anyhow!("invalid base64: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_escaping_and_absolute_uris() {
        assert_eq!(relative_path("tex/x.png").unwrap(), Path::new("tex/x.png"));
        assert_eq!(relative_path("tex/../x.png").unwrap(), Path::new("x.png"));
        assert_eq!(relative_path("./a%20b.png").unwrap(), Path::new("a b.png"));
        for bad in [
            "../b/x.png",
            "tex/../../x.png",
            "/etc/passwd",
            "file:///etc/passwd",
            "%2E%2E/x.png",
            "tex/..",
            "a%00b",
        ] {
            assert!(relative_path(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn decodes_base64_and_keeps_long_uris_out_of_messages() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        let files = MemoryFiles::default();
        assert_eq!(
            read_uri(&files, "data:application/octet-stream;base64,AAECAw==", 100).unwrap(),
            vec![0, 1, 2, 3]
        );
        let huge = format!("data:image/png;base64,{}", "!".repeat(1 << 20));
        let e = format!("{:#}", read_uri(&files, &huge, 1 << 30).unwrap_err());
        assert!(e.len() < 300 && e.contains("invalid base64"), "{e}");
        let e = format!("{:#}", read_uri(&files, &huge, 1000).unwrap_err());
        assert!(e.len() < 300 && e.contains("file-bytes"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn symlinks_out_of_the_folder_and_special_files_are_refused() {
        let dir = std::env::temp_dir().join(format!("hush-files-{}", std::process::id()));
        let scene = dir.join("scene");
        std::fs::create_dir_all(scene.join("tex")).unwrap();
        std::fs::write(dir.join("secret.txt"), b"secret").unwrap();
        std::fs::write(scene.join("tex/a.bin"), b"abc").unwrap();
        let link = |target: &Path, name: &str| {
            let _ = std::fs::remove_file(scene.join(name));
            std::os::unix::fs::symlink(target, scene.join(name)).unwrap();
        };
        link(&dir.join("secret.txt"), "out.bin");
        link(Path::new("/dev/zero"), "zero.bin");
        link(&scene.join("tex/a.bin"), "in.bin");
        let folder = SceneFolder::new(&scene).unwrap();
        assert_eq!(read_uri(&folder, "in.bin", 100).unwrap(), b"abc");
        let e = format!("{:#}", read_uri(&folder, "out.bin", 100).unwrap_err());
        assert!(e.contains("outside the scene's folder"), "{e}");
        let e = format!("{:#}", read_uri(&folder, "zero.bin", 100).unwrap_err());
        assert!(e.contains("outside the scene's folder"), "{e}");
        let e = format!("{:#}", read_regular_file(Path::new("/dev/zero"), 100).unwrap_err());
        assert!(e.contains("a device, not a regular file"), "{e}");
        let e = format!("{:#}", read_uri(&folder, "tex", 100).unwrap_err());
        assert!(e.contains("a folder, not a regular file"), "{e}");
        let e = format!("{:#}", read_uri(&folder, "tex/a.bin", 2).unwrap_err());
        assert!(e.contains("file-bytes"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
