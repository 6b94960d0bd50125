//! Resolving URIs inside a glTF file: relative paths that stay inside the scene's folder, or
//! embedded `data:` URIs. Anything else is refused, so a scene cannot read arbitrary files.

use anyhow::{Result, anyhow, bail};
use std::path::{Component, Path, PathBuf};

/// Bytes behind `uri`, which is relative to `base_dir`.
pub fn read_uri(base_dir: &Path, uri: &str) -> Result<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or_else(|| anyhow!("data URI without base64 payload"))?;
        return base64_decode(data);
    }
    let path = resolve(base_dir, uri)?;
    std::fs::read(&path).map_err(|e| anyhow!("reading {}: {e}", path.display()))
}

/// `base_dir/uri`, refusing URIs that are absolute, carry a scheme, or climb out of `base_dir`.
pub fn resolve(base_dir: &Path, uri: &str) -> Result<PathBuf> {
    let decoded = percent_decode(uri);
    if decoded.contains("://") || decoded.starts_with('/') || decoded.starts_with('\\') {
        bail!("refusing URI {uri:?}: only paths relative to the scene's folder are allowed");
    }
    let rel = Path::new(&decoded);
    let mut depth = 0i32;
    for c in rel.components() {
        match c {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => {
                depth -= 1;
                if depth < 0 {
                    bail!("refusing URI {uri:?}: it leaves the scene's folder");
                }
            }
            Component::RootDir | Component::Prefix(_) => {
                bail!("refusing URI {uri:?}: absolute paths are not allowed")
            }
        }
    }
    Ok(base_dir.join(rel))
}

fn percent_decode(s: &str) -> String {
    percent_encoding::percent_decode_str(s).decode_utf8_lossy().into_owned()
}

fn base64_decode(s: &str) -> Result<Vec<u8>> {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD
        .decode(s.trim())
        .map_err(|e| anyhow!("invalid base64 in data URI: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_escaping_and_absolute_uris() {
        let base = Path::new("/scenes/a");
        assert!(resolve(base, "tex/x.png").is_ok());
        assert!(resolve(base, "tex/../x.png").is_ok());
        assert!(resolve(base, "../b/x.png").is_err());
        assert!(resolve(base, "tex/../../x.png").is_err());
        assert!(resolve(base, "/etc/passwd").is_err());
        assert!(resolve(base, "file:///etc/passwd").is_err());
        assert!(resolve(base, "%2E%2E/x.png").is_err());
        assert_eq!(resolve(base, "a%20b.png").unwrap(), base.join("a b.png"));
    }

    #[test]
    fn decodes_base64() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64_decode("AAECAw==").unwrap(), vec![0, 1, 2, 3]);
    }
}
