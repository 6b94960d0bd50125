//! Tells the tests whether `../shared` (beside the checkout) holds the real scenes and the oracle.
//! Tests that need them are compiled with `#[cfg_attr(not(hush_shared_scenes), ignore = ...)]`,
//! so that a bare clone reports them as ignored, naming what is missing, instead of failing or
//! passing without running.

use std::path::Path;

fn main() {
    // Read when the script runs, not when it is compiled: a build script compiled for one
    // checkout may be reused for another (cargo hashes workspace paths relative to the root).
    let manifest = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| ".".into());
    let shared = Path::new(&manifest).join("../../shared");
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
