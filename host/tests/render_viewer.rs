//! Smoke test of the window viewer: opens `figurine view` on a real display for two seconds and
//! checks that it presented frames. Needs X11 or Wayland; without one it is skipped with a
//! message. On a headless machine run it under Xvfb:
//! `xvfb-run -a cargo test -p figurine-host --test render_viewer`.

use std::process::Command;

#[test]
fn viewer_opens_plays_and_closes() {
    if std::env::var_os("DISPLAY").is_none() && std::env::var_os("WAYLAND_DISPLAY").is_none() {
        eprintln!(
            "skipping: no DISPLAY/WAYLAND_DISPLAY; run under `xvfb-run -a` (Debian package xvfb) \
             to exercise the window viewer"
        );
        return;
    }
    let out = Command::new(env!("CARGO_BIN_EXE_figurine"))
        .args([
            "view",
            "procedural",
            "--size",
            "320x180",
            "--quit-after",
            "2",
        ])
        .output()
        .expect("run figurine view");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "figurine view failed: {stderr}");
    let frames: u64 = stderr
        .lines()
        .find_map(|l| {
            l.strip_prefix("figurine view: ")?
                .strip_suffix(" frames presented")?
                .parse()
                .ok()
        })
        .unwrap_or_else(|| panic!("no frame count in: {stderr}"));
    assert!(frames >= 3, "only {frames} frames presented in 2 s");
}
