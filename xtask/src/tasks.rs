//! The composite tasks: test, firmware, end-to-end, soak.

use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result};

use crate::util::{cargo, root, run, step};

/// A firmware board.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Board {
    /// The emulated Cortex-M4F board (QEMU mps2-an386) used by the end-to-end tests.
    Qemu,
    /// The nRF52840 that goes inside a figurine.
    Nrf52840,
}

impl Board {
    /// Cargo target folder of this board's build (inside `firmware/app/`): the QEMU image stays
    /// at cargo's default place, where the end-to-end tests look; the nRF52840 build gets its
    /// own folder so building one board never overwrites the other's image.
    fn target_dir(self) -> &'static str {
        match self {
            Board::Qemu => "target",
            Board::Nrf52840 => "target/nrf52840",
        }
    }

    fn feature(self) -> &'static str {
        match self {
            Board::Qemu => "qemu",
            Board::Nrf52840 => "nrf52840",
        }
    }
}

/// Crates that must build for the MCU, with the features to check.
const NO_STD_CRATES: &[(&str, &str)] = &[
    ("figurine-protocol", "defmt"),
    ("figurine-recognizer", "defmt"),
    ("figurine-store", "defmt"),
];

/// `cargo` in `firmware/app`, with the firmware's rustflags ([`firmware_rustflags`]).
fn firmware_cargo() -> Command {
    let mut cmd = Command::new("cargo");
    cmd.current_dir(root().join("firmware/app"))
        .env("CARGO_ENCODED_RUSTFLAGS", firmware_rustflags());
    cmd
}

/// The rustflags of a firmware build: the caller's, plus short source paths. Panic locations
/// name their source files, and under cargo's registry and this checkout those names are long
/// and depend on the machine; written relative to them (`--remap-path-prefix`) they take
/// ≈ 0.6 KiB less flash, and the image no longer depends on where it was built.
fn firmware_rustflags() -> String {
    let mut flags: Vec<String> = match std::env::var("CARGO_ENCODED_RUSTFLAGS") {
        Ok(f) if !f.is_empty() => f.split('\x1f').map(String::from).collect(),
        _ => std::env::var("RUSTFLAGS")
            .map(|f| f.split_whitespace().map(String::from).collect())
            .unwrap_or_default(),
    };
    let cargo_home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")));
    let mut prefixes = Vec::new();
    if let Some(home) = cargo_home {
        // One folder per registry (`index.crates.io-<hash>`), each holding the crates.
        if let Ok(dirs) = std::fs::read_dir(home.join("registry/src")) {
            prefixes.extend(dirs.flatten().map(|d| d.path()));
        }
        prefixes.push(home.join("git/checkouts"));
    }
    prefixes.push(root());
    for p in prefixes {
        flags.push(format!("--remap-path-prefix={}=", p.display()));
    }
    flags.join("\x1f")
}

/// Builds the firmware for one board.
pub fn firmware(board: Board, release: bool) -> Result<()> {
    step(&format!("firmware: build for {board:?}"));
    let mut cmd = firmware_cargo();
    cmd.args([
        "build",
        "--no-default-features",
        "--features",
        board.feature(),
        "--target-dir",
        board.target_dir(),
    ]);
    if release {
        cmd.arg("--release");
    }
    run(&mut cmd)
}

/// The end-to-end tests: the real firmware in QEMU against the host.
pub fn e2e() -> Result<()> {
    crate::setup::setup()?;
    firmware(Board::Qemu, true)?;
    step("end-to-end tests (figurine-e2e)");
    let (passed, failed) =
        run_tests(cargo().args(["test", "-p", "figurine-e2e", "--no-fail-fast"]))?;
    println!("tests: {passed} passed, {failed} failed");
    Ok(())
}

/// A long pose stream into the QEMU firmware: 0 drops expected; prints queue high-water marks
/// and the worst per-sample cycle count.
pub fn soak(seconds: u64, rate_hz: u64) -> Result<()> {
    crate::setup::setup()?;
    firmware(Board::Qemu, true)?;
    step(&format!(
        "soak: {rate_hz} Hz for {seconds} s into the QEMU firmware"
    ));
    run(cargo()
        .env("FIGURINE_SOAK_SECONDS", seconds.to_string())
        .env("FIGURINE_SOAK_RATE_HZ", rate_hz.to_string())
        .args([
            "test",
            "--release",
            "-p",
            "figurine-e2e",
            "--test",
            "soak",
            "--",
            "--ignored",
            "--nocapture",
        ]))
}

/// Everything CI checks.
pub fn test() -> Result<()> {
    let start = Instant::now();
    crate::setup::setup()?;

    step("rustfmt");
    run(cargo().args(["fmt", "--all", "--", "--check"]))?;

    step("import circles");
    crate::modules::check(&root())?;

    step("no_std crates for thumbv7em-none-eabihf");
    for (krate, features) in NO_STD_CRATES {
        run(cargo().args([
            "check",
            "-p",
            krate,
            "--target",
            "thumbv7em-none-eabihf",
            "--no-default-features",
        ]))?;
        run(cargo().args([
            "check",
            "-p",
            krate,
            "--target",
            "thumbv7em-none-eabihf",
            "--no-default-features",
            "--features",
            features,
        ]))?;
    }

    if root().join("firmware/app/Cargo.toml").exists() {
        firmware(Board::Nrf52840, true)?;
        firmware(Board::Qemu, true)?;
        step("clippy (firmware)");
        for board in [Board::Qemu, Board::Nrf52840] {
            run(firmware_cargo().args([
                "clippy",
                "--release",
                "--no-default-features",
                "--features",
                board.feature(),
                "--target-dir",
                board.target_dir(),
                "--",
                "-D",
                "warnings",
            ]))?;
        }
    }

    step("clippy (workspace)");
    run(cargo().args([
        "clippy",
        "--workspace",
        "--all-targets",
        "--",
        "-D",
        "warnings",
    ]))?;

    step("tests (workspace, including end-to-end)");
    let (passed, failed) = run_tests(cargo().args(["test", "--workspace", "--no-fail-fast"]))?;

    step("fuzz smoke: every target");
    crate::fuzz::fuzz(&crate::fuzz::FuzzOptions {
        seconds: crate::fuzz::SMOKE_SECONDS,
        runs: 0,
        targets: Vec::new(),
    })?;
    println!(
        "\nall checks passed in {:.0} s",
        start.elapsed().as_secs_f64()
    );
    println!("tests: {passed} passed, {failed} failed");
    Ok(())
}

/// Runs a `cargo test` command, echoing its output, and sums its `test result:` lines so the
/// run ends on one total (`N passed, N failed`) rather than on the last crate's doc-tests.
fn run_tests(cmd: &mut Command) -> Result<(u64, u64)> {
    use std::io::{BufRead, BufReader};
    let shown = format!("{cmd:?}");
    let mut child = cmd
        .stdout(std::process::Stdio::piped())
        .spawn()
        .with_context(|| format!("could not start {shown}"))?;
    let (mut passed, mut failed) = (0u64, 0u64);
    if let Some(out) = child.stdout.take() {
        for line in BufReader::new(out).lines() {
            let line = line?;
            println!("{line}");
            if let Some(rest) = line.trim().strip_prefix("test result: ") {
                let count = |word: &str| -> u64 {
                    rest.split([';', '.'])
                        .map(str::trim)
                        .find_map(|part| {
                            part.strip_suffix(word).and_then(|n| n.trim().parse().ok())
                        })
                        .unwrap_or(0)
                };
                passed += count("passed");
                failed += count("failed");
            }
        }
    }
    let status = child.wait()?;
    if !status.success() {
        println!("tests: {passed} passed, {failed} failed");
        anyhow::bail!("tests failed ({status}): {shown}");
    }
    Ok((passed, failed))
}
