//! Small helpers for running commands with clear errors.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};

/// The workspace root (the folder holding the root `Cargo.toml`).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

/// Prints a section heading so long runs are easy to follow.
pub fn step(what: &str) {
    println!("\n==> {what}");
}

/// Runs a command to completion, inheriting stdio; errors name the command.
pub fn run(cmd: &mut Command) -> Result<()> {
    let shown = format!("{cmd:?}");
    let status = cmd
        .status()
        .with_context(|| format!("could not start {shown}"))?;
    if !status.success() {
        bail!("command failed ({status}): {shown}");
    }
    Ok(())
}

/// Runs a command and returns its stdout, or `None` if it could not start or failed.
pub fn output(cmd: &mut Command) -> Option<String> {
    let out = cmd.output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).into_owned())
}

/// True if `prog` can be found on `PATH`.
pub fn have(prog: &str) -> bool {
    output(Command::new("sh").args(["-c", &format!("command -v {prog}")])).is_some()
}

/// A `cargo` command for the workspace toolchain.
pub fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(root());
    // Tests that render in-process create Vulkan devices; without a runtime directory (CI
    // runners, containers) Mesa prints "XDG_RUNTIME_DIR is invalid" for each of them.
    let valid = std::env::var_os("XDG_RUNTIME_DIR")
        .map(std::path::PathBuf::from)
        .is_some_and(|p| p.is_dir());
    if !valid {
        let dir = root().join("target/runtime");
        if std::fs::create_dir_all(&dir).is_ok() {
            #[cfg(unix)]
            {
                use std::os::unix::fs::PermissionsExt;
                let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
            }
            c.env("XDG_RUNTIME_DIR", dir);
        }
    }
    c
}

/// Builds the release `figurine` binary (`target/release/figurine`).
pub fn build_figurine() -> Result<()> {
    run(cargo().args([
        "build",
        "--release",
        "-p",
        "figurine-host",
        "--bin",
        "figurine",
    ]))
}
