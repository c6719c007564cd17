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
///
/// A test binary that dies before its summary (a signal, an abort, a C library calling
/// `exit`) leaves no `test result:` line; cargo names it, and the binary says why, only on
/// standard error, far above the end of a long log. So standard error is kept in a ring of
/// [`DEATH_CONTEXT_LINES`] lines, and each `to rerun pass` block is repeated at the end with
/// the lines before it, so a CI log's tail says which binary failed and how.
fn run_tests(cmd: &mut Command) -> Result<(u64, u64)> {
    let shown = format!("{cmd:?}");
    let run = collect_tests(cmd)?;
    if !run.success {
        if !run.failures.is_empty() {
            println!(
                "\nwhat cargo and the test binaries said on standard error before each failure:"
            );
            for line in &run.failures {
                println!("  {line}");
            }
        }
        println!("tests: {} passed, {} failed", run.passed, run.failed);
        anyhow::bail!("tests failed ({}): {shown}", run.status);
    }
    Ok((run.passed, run.failed))
}

/// What a `cargo test` run printed that [`run_tests`] reports.
#[derive(Debug)]
struct TestRun {
    passed: u64,
    failed: u64,
    success: bool,
    status: String,
    /// Each failure's standard-error context (see [`run_tests`]), blocks begun by `--`.
    failures: Vec<String>,
}

/// Runs `cmd`, echoing both its streams, and gathers a [`TestRun`].
fn collect_tests(cmd: &mut Command) -> Result<TestRun> {
    use std::io::{BufRead, BufReader};
    let shown = format!("{cmd:?}");
    let mut child = cmd
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .with_context(|| format!("could not start {shown}"))?;
    // Standard error is read on its own thread, so neither pipe can fill and stall cargo.
    let stderr = child.stderr.take().map(|err| {
        std::thread::spawn(move || {
            let mut ring = std::collections::VecDeque::new();
            let mut failures: Vec<String> = Vec::new();
            let mut after = 0usize;
            for line in BufReader::new(err).lines().map_while(|l| l.ok()) {
                eprintln!("{line}");
                if after > 0 {
                    after -= 1;
                    failures.push(line);
                    continue;
                }
                if line.contains("to rerun pass") {
                    failures.push("--".to_string());
                    failures.extend(ring.drain(..));
                    failures.push(line);
                    // cargo's "Caused by: process didn't exit successfully: … (signal: …)".
                    after = 4;
                    continue;
                }
                if ring.len() == DEATH_CONTEXT_LINES {
                    ring.pop_front();
                }
                ring.push_back(line);
            }
            failures
        })
    });
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
    let failures = stderr
        .and_then(|reader| reader.join().ok())
        .unwrap_or_default();
    Ok(TestRun {
        passed,
        failed,
        success: status.success(),
        status: status.to_string(),
        failures,
    })
}

/// Standard-error lines kept before each failed test binary's `to rerun pass` line: enough
/// for cargo's `Running` line and what a dying binary printed (a panic inside a panic, a
/// stack overflow, a C library's message).
const DEATH_CONTEXT_LINES: usize = 12;

#[cfg(test)]
mod tests {
    use super::*;

    /// A stand-in for `cargo test`: a shell that prints what cargo and a test binary print.
    fn shell(script: &str) -> Command {
        let mut cmd = Command::new("sh");
        cmd.args(["-c", script]);
        cmd
    }

    #[test]
    fn results_are_summed_over_every_binary() {
        let run = collect_tests(&mut shell(
            "echo 'test result: ok. 3 passed; 0 failed; 1 ignored'; \
             echo 'test result: FAILED. 2 passed; 1 failed; 0 ignored'; exit 101",
        ))
        .unwrap();
        assert_eq!((run.passed, run.failed, run.success), (5, 1, false));
    }

    #[test]
    fn a_binary_that_dies_is_named_with_what_it_said_before() {
        let run = collect_tests(&mut shell(
            "echo '     Running unittests src/lib.rs (target/debug/deps/a-1)' >&2; \
             echo 'test result: ok. 3 passed; 0 failed' ; \
             echo '     Running unittests src/lib.rs (target/debug/deps/b-2)' >&2; \
             echo \"thread 'x' has overflowed its stack\" >&2; \
             echo 'error: test failed, to rerun pass `-p b --lib`' >&2; \
             echo '' >&2; echo 'Caused by:' >&2; \
             echo '  process didn'\"'\"'t exit successfully: `b-2` (signal: 6, SIGABRT)' >&2; \
             exit 101",
        ))
        .unwrap();
        assert!(!run.success);
        assert_eq!((run.passed, run.failed), (3, 0));
        let said = run.failures.join("\n");
        for needle in ["deps/b-2", "overflowed its stack", "-p b --lib", "SIGABRT"] {
            assert!(said.contains(needle), "{needle} missing from:\n{said}");
        }
    }

    #[test]
    fn a_run_that_passes_keeps_no_failure() {
        let run = collect_tests(&mut shell(
            "echo '     Running x' >&2; echo 'test result: ok. 1 passed; 0 failed'",
        ))
        .unwrap();
        assert!(run.success);
        assert!(run.failures.is_empty());
    }
}
