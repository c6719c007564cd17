//! Helpers of the motion-graph integration tests: the fetched DeepMimic clips and the
//! `figurine` binary under test.

#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Command;

use figurine_host::data::data_dir;

/// The folder of the fetched DeepMimic clips, or `None` (with a note) when they are missing.
pub fn deepmimic_dir() -> Option<PathBuf> {
    let d = data_dir().join("deepmimic");
    if d.join("humanoid.urdf").is_file() && d.join("humanoid3d_walk.txt").is_file() {
        Some(d)
    } else {
        eprintln!("skipping: DeepMimic data not found; run `cargo xtask setup`");
        None
    }
}

/// Runs `figurine ARGS`: whether it succeeded, its stdout and its stderr.
pub fn figurine(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_figurine"))
        .args(args)
        .output()
        .expect("run figurine");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
