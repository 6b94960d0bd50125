//! The viewer on a machine without a display.

use std::process::Command;

#[test]
fn viewer_without_a_display_points_to_the_cli() {
    let o = Command::new(env!("CARGO_BIN_EXE_hush"))
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("hush-cli render"), "{err}");
}
