//! What the `figurine track` tests share: running the binary, scratch folders, and checking
//! that a run failed with a clear message.

// Each test file that includes this uses only some of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use figurine_host::poselog::PoseLog;

pub fn figurine(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_figurine"))
        .args(args)
        .output()
        .expect("run figurine")
}

#[path = "../scratch/mod.rs"]
mod scratch;
pub use scratch::Scratch;

/// A scratch folder unique to one test, removed when it passes.
pub fn scratch(name: &str) -> Scratch {
    Scratch::new("track", name)
}

pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs `figurine ARGS` and asserts it succeeded (showing its stderr if not).
pub fn succeeds(args: &[&str]) -> Output {
    let out = figurine(args);
    assert!(
        out.status.success(),
        "figurine {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Writes `log` as `dir/NAME.csv` and renders it, already in the camera's frame
/// (`track render --as-is`, plus `extra`), to `dir/NAME.mp4`; returns the video's path.
pub fn render_as_is(dir: &Path, name: &str, log: &PoseLog, extra: &[&str]) -> PathBuf {
    let path = dir.join(format!("{name}.csv"));
    log.write_path(&path).unwrap();
    let video = dir.join(format!("{name}.mp4"));
    let mut args = vec![
        "track",
        "render",
        "--log",
        s(&path),
        "--out",
        s(&video),
        "--as-is",
    ];
    args.extend_from_slice(extra);
    succeeds(&args);
    video
}

/// A failed run that explains itself and did not panic.
pub fn fails_saying(out: &Output, words: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "should fail: {err}");
    assert!(!err.contains("panicked"), "panicked: {err}");
    for w in words {
        assert!(err.contains(w), "`{w}` not in: {err}");
    }
}
