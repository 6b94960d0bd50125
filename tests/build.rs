//! Tells the tests whether `../shared` (beside the checkout) holds the real scenes and the oracle.
//! Tests that need them are compiled with `#[cfg_attr(not(hush_shared_scenes), ignore = ...)]`,
//! so that a bare clone reports them as ignored, naming what is missing, instead of failing or
//! passing without running.

use std::path::Path;

fn main() {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared");
    for (cfg, dir) in [("hush_shared_scenes", "scenes"), ("hush_shared_oracle", "oracle")] {
        let path = shared.join(dir);
        println!("cargo::rustc-check-cfg=cfg({cfg})");
        // Rerun when the folder appears or disappears (a missing path always counts as changed).
        println!("cargo::rerun-if-changed={}", path.display());
        if path.is_dir() {
            println!("cargo::rustc-cfg={cfg}");
        }
    }
}
