//! The composite tasks: test, firmware, fuzz.

use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result};

use crate::util::{cargo, have, root, run, step};

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

/// Builds the firmware for one board.
pub fn firmware(board: Board, release: bool) -> Result<()> {
    step(&format!("firmware: build for {board:?}"));
    let app = root().join("firmware/app");
    let mut cmd = Command::new("cargo");
    cmd.current_dir(&app).args([
        "build",
        "--no-default-features",
        "--features",
        board.feature(),
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
            run(Command::new("cargo")
                .current_dir(root().join("firmware/app"))
                .args([
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

/// Real files that seed a fuzz corpus: `(data subfolder, file-name suffix)`; a folder
/// starting with `@` is in the repository instead of the data folder. The LAFAN-derived files
/// may not be committed, so these seeds are copied in at run time.
type RealSeeds = &'static [(&'static str, &'static str)];

/// Fuzz targets: (fuzz crate folder, target name, real-data seeds).
const FUZZ_TARGETS: &[(&str, &str, RealSeeds)] = &[
    ("protocol/fuzz", "decode_stream", &[]),
    ("host/fuzz", "poselog_csv", &[]),
    ("host/fuzz", "bvh_import", &[("bvh", ".bvh")]),
    (
        "host/fuzz",
        "deepmimic_import",
        &[("deepmimic", ".txt"), ("deepmimic", ".urdf")],
    ),
    ("host/fuzz", "events_jsonl", &[]),
    (
        "host/fuzz",
        "library_json",
        &[("@host/assets", "library.json")],
    ),
    (
        "host/fuzz",
        "effort_json",
        &[("@host/assets", "effort.json")],
    ),
    ("firmware/recognizer/fuzz", "sample_feed", &[]),
    ("firmware/recognizer/fuzz", "blobs", &[]),
];

/// Runs every fuzz target for `seconds`; prints each target's execution count.
pub fn fuzz(seconds: u64) -> Result<()> {
    if !have("cargo-fuzz") {
        step("installing cargo-fuzz");
        run(Command::new("cargo").args(["+nightly", "install", "--locked", "cargo-fuzz"]))?;
    }
    let data = crate::data::data_dir();
    let mut summary = Vec::new();
    for (dir, target, real_seeds) in FUZZ_TARGETS {
        let dir = root().join(dir);
        step(&format!("fuzz {target} for {seconds} s"));
        let corpus = dir.join("corpus").join(target);
        std::fs::create_dir_all(&corpus)?;
        for (sub, suffix) in *real_seeds {
            for entry in std::fs::read_dir(data.join(sub))
                .into_iter()
                .flatten()
                .flatten()
            {
                let p = entry.path();
                let small = entry.metadata().is_ok_and(|m| m.len() < 512 * 1024);
                if small && p.to_string_lossy().ends_with(suffix) {
                    if let Some(name) = p.file_name() {
                        std::fs::copy(&p, corpus.join(name))?;
                    }
                }
            }
        }
        let seeds = dir.join("seeds").join(target);
        let mut cmd = Command::new("cargo");
        cmd.current_dir(&dir)
            .args(["+nightly", "fuzz", "run", target])
            .arg(&corpus);
        if seeds.exists() {
            cmd.arg(&seeds);
        }
        cmd.args([
            "--",
            &format!("-max_total_time={seconds}"),
            "-print_final_stats=1",
        ]);
        let out = cmd
            .output()
            .with_context(|| format!("could not start {cmd:?}"))?;
        let log = String::from_utf8_lossy(&out.stderr);
        let execs = log
            .lines()
            .find_map(|l| l.strip_prefix("stat::number_of_executed_units:"))
            .map(|n| n.trim().to_string())
            .unwrap_or_else(|| "?".into());
        if !out.status.success() {
            eprintln!("{log}");
            anyhow::bail!(
                "fuzz target {target} failed (a crash is saved under {}/artifacts)",
                dir.display()
            );
        }
        println!("{target}: {execs} executions, no crash");
        summary.push(format!(
            "{target}: {execs} executions in {seconds} s, 0 crashes"
        ));
    }
    step("fuzz summary");
    for line in summary {
        println!("{line}");
    }
    Ok(())
}
