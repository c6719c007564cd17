//! `cargo xtask setup`: everything a fresh Debian machine with rustup needs, idempotently.
//!
//! * Rust: the `thumbv7em-none-eabihf` target and `llvm-tools` for the pinned toolchain.
//! * Debian packages, installed only when missing: `qemu-system-arm` (firmware end-to-end
//!   tests), `mesa-vulkan-drivers` + `libvulkan1` (lavapipe, headless rendering), `ffmpeg`
//!   (MP4 output), `python3-venv`, `nodejs` + `npm` (independent BVH and glTF validators),
//!   `g++` (libFuzzer, which cargo-fuzz builds from C++ sources), `slurm-wlm` + `munge` (the
//!   Slurm job array of the distributed graph build, tests/graph_tiles.rs and the bench). The
//!   AprilTag detector behind `figurine track` needs none: `apriltag-sys` compiles its bundled
//!   source with the C compiler (`.cargo/config.toml`).
//! * Validators used by tests: Python's `bvh` package in `target/tools/pyenv`, Khronos'
//!   `gltf-validator` from npm in `target/tools/node`.
//! * cargo-fuzz from crates.io when missing (the fuzz smoke of `cargo xtask test`).
//! * Real data from the package registries (see `data.rs`).

use std::process::Command;

use anyhow::{bail, Result};

use crate::util::{have, output, root, run, step};

/// Debian packages the project needs, with the command that proves each is present.
const APT_PACKAGES: &[(&str, &str)] = &[
    ("qemu-system-arm", "qemu-system-arm"),
    ("mesa-vulkan-drivers", ""),
    ("libvulkan1", ""),
    ("ffmpeg", "ffmpeg"),
    ("python3-venv", ""),
    ("nodejs", "node"),
    ("npm", "npm"),
    ("g++", "g++"),
    // A single-node Slurm cluster for the distributed graph build's test and benchmark (each
    // starts its own munged, slurmctld and slurmd in a temporary folder; no system service is
    // configured or needed).
    ("slurm-wlm", ""),
    ("munge", ""),
];

fn dpkg_installed(pkg: &str) -> bool {
    output(Command::new("dpkg-query").args(["-W", "-f=${Status}", pkg]))
        .is_some_and(|s| s.contains("install ok installed"))
}

/// The Rust target and components the firmware build and its size report need (rustup
/// skips what is already installed).
pub fn rust_target() -> Result<()> {
    step("setup: Rust target and components");
    run(Command::new("rustup").current_dir(root()).args([
        "target",
        "add",
        "thumbv7em-none-eabihf",
    ]))?;
    run(Command::new("rustup").current_dir(root()).args([
        "component",
        "add",
        "llvm-tools",
        "rustfmt",
        "clippy",
    ]))
}

/// Installs what is missing; returns an error with a clear message when it cannot.
pub fn setup() -> Result<()> {
    rust_target()?;

    step("setup: Debian packages");
    let missing: Vec<&str> = APT_PACKAGES
        .iter()
        .filter(|(pkg, prog)| {
            let present = if prog.is_empty() {
                dpkg_installed(pkg)
            } else {
                have(prog) || dpkg_installed(pkg)
            };
            !present
        })
        .map(|(pkg, _)| *pkg)
        .collect();
    if missing.is_empty() {
        println!("all present");
    } else {
        println!("missing: {}", missing.join(" "));
        let is_root = output(Command::new("id").arg("-u")).is_some_and(|s| s.trim() == "0");
        let prefix: Vec<&str> = if is_root {
            vec![]
        } else if have("sudo") {
            vec!["sudo", "-n"]
        } else {
            bail!(
                "these Debian packages are missing and I am not root and have no sudo: {}\n\
                 install them with: apt-get install -y {}",
                missing.join(" "),
                missing.join(" ")
            );
        };
        let apt = |args: &[&str]| {
            let mut all = prefix.clone();
            all.extend_from_slice(args);
            let mut c = Command::new(all[0]);
            c.args(&all[1..]).env("DEBIAN_FRONTEND", "noninteractive");
            run(&mut c)
        };
        apt(&["apt-get", "update", "-q"])?;
        let mut args = vec!["apt-get", "install", "-y", "-q", "--no-install-recommends"];
        args.extend(missing.iter().copied());
        apt(&args)?;
    }

    step("setup: validators (Python bvh, Khronos gltf-validator)");
    let tools = root().join("target/tools");
    std::fs::create_dir_all(&tools)?;
    let py = tools.join("pyenv/bin/python");
    if !py.exists() {
        run(Command::new("python3")
            .args(["-m", "venv"])
            .arg(tools.join("pyenv")))?;
    }
    if output(Command::new(&py).args(["-c", "import bvh"])).is_none() {
        run(Command::new(&py).args(["-m", "pip", "install", "-q", "bvh==0.3"]))?;
    }
    let node = tools.join("node");
    if !node
        .join("node_modules/gltf-validator/package.json")
        .exists()
    {
        std::fs::create_dir_all(&node)?;
        run(Command::new("npm")
            .args(["install", "--silent", "--no-audit", "--no-fund", "--prefix"])
            .arg(&node)
            .arg("gltf-validator@2.0.0-dev.3.10"))?;
    }
    println!("validators ready in {}", tools.display());

    step("setup: cargo-fuzz");
    crate::fuzz::install()?;

    crate::data::fetch()?;
    Ok(())
}
