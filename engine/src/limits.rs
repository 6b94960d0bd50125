//! Budgets on what a scene can make Hush read, decode and build, and reading a file within them.
//!
//! A scene file is a program of sorts: a few kilobytes can name a gigabyte accessor, a texture
//! whose header promises 10^10 pixels, or a node hierarchy that instances a mesh millions of
//! times. Every such quantity is checked against a budget before the memory or time is spent, and
//! an input over one is refused with an error that names the budget and how to raise it
//! (`--limit NAME=VALUE` on `hush` and `hush-cli`).

use anyhow::{Result, anyhow, bail};
use std::io::Read;
use std::path::Path;

/// The budgets, each with its `--limit` name. The defaults hold every real scene Hush is tested
/// on with room to spare (the largest, FlightHelmet, reads 32 MB of files and decodes 0.4 GB of
/// textures at full size) and keep the memory a hostile file can claim in the low gigabytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Bytes of any one file read (the scene, a buffer, an image, an environment map, a camera
    /// path or preset), checked against its size before it is read. Default 2 GiB.
    pub file_bytes: u64,
    /// Bytes of a glTF file's JSON (the .gltf file, or a .glb's JSON chunk). Parsed JSON takes up
    /// to about 16 times its size in memory (an array of one-digit numbers). Default 64 MiB; the
    /// largest JSON of the tested scenes is 0.2 MB.
    pub json_bytes: u64,
    /// Pixels of one image (texture or environment map), checked against its header before it
    /// is decoded. Default 67,108,864 (8192 x 8192, an 8K texture or a 16K x 8K environment map
    /// halved).
    pub image_pixels: u64,
    /// Bytes of everything decoded from the files together: buffers, accessors as read, and
    /// images at 4 bytes (textures) or 12 bytes (environment maps) per pixel. Default 4 GiB.
    pub decoded_bytes: u64,
    /// Nodes in a glTF file. Default 1,000,000.
    pub nodes: u64,
    /// Depth of the node hierarchy (a root node is at depth 1). Default 1024.
    pub hierarchy_depth: u64,
    /// Triangles after instancing (a mesh placed by n nodes counts n times). Default 16,777,215,
    /// the most the GPU's triangle slots address ([`MAX_TRIANGLES`] - 1).
    pub triangles: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            file_bytes: 2 << 30,
            json_bytes: 64 << 20,
            image_pixels: 8192 * 8192,
            decoded_bytes: 4 << 30,
            nodes: 1_000_000,
            hierarchy_depth: 1024,
            triangles: MAX_TRIANGLES as u64 - 1,
        }
    }
}

impl Limits {
    /// The `--limit` names.
    pub const NAMES: [&'static str; 7] = [
        "file-bytes",
        "json-bytes",
        "image-pixels",
        "decoded-bytes",
        "nodes",
        "hierarchy-depth",
        "triangles",
    ];

    fn slot(&mut self, name: &str) -> Option<&mut u64> {
        Some(match name {
            "file-bytes" => &mut self.file_bytes,
            "json-bytes" => &mut self.json_bytes,
            "image-pixels" => &mut self.image_pixels,
            "decoded-bytes" => &mut self.decoded_bytes,
            "nodes" => &mut self.nodes,
            "hierarchy-depth" => &mut self.hierarchy_depth,
            "triangles" => &mut self.triangles,
            _ => return None,
        })
    }

    /// Apply `NAME=VALUE[,NAME=VALUE...]` (the `--limit` flag's argument).
    pub fn apply(&mut self, assignments: &str) -> Result<()> {
        for a in assignments.split(',').map(str::trim).filter(|a| !a.is_empty()) {
            let (name, value) =
                a.split_once('=').ok_or_else(|| anyhow!("--limit {a:?}: expected NAME=VALUE"))?;
            let value: u64 = value
                .trim()
                .replace('_', "")
                .parse()
                .map_err(|_| anyhow!("--limit {a:?}: the value must be a whole number"))?;
            if value == 0 {
                bail!("--limit {a:?}: a budget must be at least 1");
            }
            let slot = self.slot(name.trim()).ok_or_else(|| {
                anyhow!("--limit {a:?}: unknown budget; the budgets are {}", Self::NAMES.join(", "))
            })?;
            *slot = value;
        }
        if self.triangles >= MAX_TRIANGLES as u64 {
            bail!(
                "--limit triangles={}: the GPU addresses at most {} triangles",
                self.triangles,
                MAX_TRIANGLES - 1
            );
        }
        Ok(())
    }
}

/// The error for `what` needing `need` of the budget `name` whose value is `limit`
/// ([`crate::Error::OverBudget`]). Callers that fall back on bad input (a texture that cannot be
/// read) still refuse an overrun: find it in an error's chain with [`is_over_budget`].
pub fn over_budget(
    name: &'static str,
    what: impl std::fmt::Display,
    need: u64,
    limit: u64,
) -> anyhow::Error {
    crate::Error::OverBudget { budget: name, what: what.to_string(), need, limit }.into()
}

/// Whether `e` (or an error it wraps) is a budget overrun.
pub fn is_over_budget(e: &anyhow::Error) -> bool {
    matches!(crate::Error::find(e), Some(crate::Error::OverBudget { .. }))
}

/// Triangle slots the GPU scene addresses: triangle slots and node indices share 24 bits in the
/// BVH2 traversal stack.
pub const MAX_TRIANGLES: usize = 1 << 24;

/// A running count of decoded bytes against [`Limits::decoded_bytes`].
#[derive(Debug)]
pub struct Budget {
    pub limits: Limits,
    decoded: u64,
}

impl Budget {
    pub fn new(limits: Limits) -> Budget {
        Budget { limits, decoded: 0 }
    }

    /// Count `bytes` about to be decoded for `what`, or refuse them.
    pub fn decode(&mut self, bytes: u64, what: impl std::fmt::Display) -> Result<()> {
        let total = self.decoded.saturating_add(bytes);
        if total > self.limits.decoded_bytes {
            return Err(over_budget(
                "decoded-bytes",
                format_args!("{what} (with what was decoded before it)"),
                total,
                self.limits.decoded_bytes,
            ));
        }
        self.decoded = total;
        Ok(())
    }

    /// Refuse an image of `w` x `h` pixels before it is decoded.
    pub fn image(
        &mut self,
        w: u64,
        h: u64,
        bytes_per_pixel: u64,
        what: impl std::fmt::Display,
    ) -> Result<()> {
        let px = w.saturating_mul(h);
        if px > self.limits.image_pixels {
            return Err(over_budget(
                "image-pixels",
                format_args!("{what} ({w}x{h})"),
                px,
                self.limits.image_pixels,
            ));
        }
        self.decode(px * bytes_per_pixel, what)
    }
}

/// Read `path` if it is a regular file (after following symlinks) of at most `limit` bytes: a
/// FIFO or a device is refused before it is opened (a FIFO would block, `/dev/zero` never end),
/// and the file is read no further than the limit even if it grows meanwhile.
pub fn read_regular_file(path: &Path, limit: u64) -> Result<Vec<u8>> {
    let meta = std::fs::metadata(path).map_err(|e| anyhow!("reading {}: {e}", path.display()))?;
    if !meta.is_file() {
        bail!(
            "{} is {}, not a regular file; refused",
            path.display(),
            file_kind(&meta.file_type())
        );
    }
    if meta.len() > limit {
        return Err(over_budget("file-bytes", path.display(), meta.len(), limit));
    }
    let file = std::fs::File::open(path).map_err(|e| anyhow!("reading {}: {e}", path.display()))?;
    // What was opened may not be what was checked (a file swapped in between).
    let opened = file.metadata().map_err(|e| anyhow!("reading {}: {e}", path.display()))?;
    if !opened.is_file() {
        bail!(
            "{} is {}, not a regular file; refused",
            path.display(),
            file_kind(&opened.file_type())
        );
    }
    let mut bytes = Vec::with_capacity(opened.len().min(limit) as usize);
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| anyhow!("reading {}: {e}", path.display()))?;
    if bytes.len() as u64 > limit {
        return Err(over_budget("file-bytes", path.display(), bytes.len() as u64, limit));
    }
    Ok(bytes)
}

/// A text file (preset, camera path) read as [`read_regular_file`] does, within the default
/// json-bytes budget (it is parsed whole, at several times its size).
pub fn read_text_file(path: &Path) -> Result<String> {
    let bytes = read_regular_file(path, Limits::default().json_bytes)?;
    String::from_utf8(bytes).map_err(|_| anyhow!("{} is not UTF-8 text", path.display()))
}

fn file_kind(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a named pipe";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() { "a folder" } else { "a special file" }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budgets_are_set_by_name_and_refused_with_their_name() {
        let mut l = Limits::default();
        l.apply("triangles=1000, image-pixels=4_096").unwrap();
        assert_eq!((l.triangles, l.image_pixels), (1000, 4096));
        for (bad, needle) in [
            ("triangle=3", "unknown budget"),
            ("nodes", "NAME=VALUE"),
            ("nodes=-1", "whole number"),
            ("nodes=0", "at least 1"),
            ("triangles=16777216", "at most"),
        ] {
            let e = Limits::default().apply(bad).unwrap_err().to_string();
            assert!(e.contains(needle), "{bad}: {e}");
        }
        let mut b = Budget::new(l);
        let e = b.image(100, 100, 4, "texture a.png").unwrap_err().to_string();
        assert!(
            e.contains("image-pixels")
                && e.contains("--limit image-pixels=10000")
                && e.contains("100x100"),
            "{e}"
        );
    }
}
