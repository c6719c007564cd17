//! `cargo xtask`: figurine's build automation.
//!
//! * `setup` — installs what a fresh Debian machine needs (idempotent).
//! * `test` — setup, then every check: fmt, import circles, clippy, host tests, no_std checks
//!   for the thumb target, firmware builds for every board, end-to-end tests.
//! * `demo` — the main job: a doodle recognised, animated, rendered (target/demo/).
//! * `bench` — prints every figure (sizes, speed, accuracy, instructions, render, graph).
//! * `e2e` — the firmware in QEMU against the host.
//! * `soak --seconds N --rate HZ` — a long pose stream into the QEMU firmware.
//! * `firmware --board qemu|nrf52840` — builds the firmware binary.
//! * `fuzz [--seconds N] [--runs N] [--target T]` — runs the cargo-fuzz targets on the pinned
//!   stable toolchain (`RUSTC_BOOTSTRAP=1`); `test` runs a short smoke of every target.

mod bench;
mod data;
mod demo;
mod fuzz;
mod modules;
mod setup;
mod tasks;
mod util;

use clap::{Parser, Subcommand};

/// figurine's build automation.
#[derive(Parser)]
#[command(name = "cargo xtask")]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Install the Rust target, Debian packages, validators and real data (idempotent).
    Setup,
    /// The main job: a doodle recognised, animated and rendered (writes target/demo/).
    Demo,
    /// Print every figure: wire sizes, recognizer speed and accuracy, firmware size,
    /// instructions and latency, render and motion-graph build times.
    Bench,
    /// Build the QEMU firmware and run the end-to-end tests against it.
    E2e,
    /// Stream poses into the QEMU firmware for a long time and report drops and high-water marks.
    Soak {
        /// Duration, seconds.
        #[arg(long, default_value_t = 600)]
        seconds: u64,
        /// Pose rate, Hz.
        #[arg(long, default_value_t = 1000)]
        rate: u64,
    },
    /// Fetch only the real motion data into target/figurine-data.
    Data,
    /// Run every check and test (calls setup first).
    Test,
    /// Build the firmware for a board.
    Firmware {
        /// Which board: `qemu` (mps2-an386) or `nrf52840`.
        #[arg(long, default_value = "qemu")]
        board: tasks::Board,
        /// Build with the dev profile instead of release.
        #[arg(long)]
        debug: bool,
    },
    /// Run every cargo-fuzz target (pinned stable toolchain, no nightly; installs cargo-fuzz).
    /// Fails on any crash; prints executions per target.
    Fuzz {
        /// Seconds per target (at most).
        #[arg(long, default_value_t = fuzz::SMOKE_SECONDS)]
        seconds: u64,
        /// Executions per target (at most; 0: no limit), e.g. 10000000 for a campaign.
        #[arg(long, default_value_t = 0)]
        runs: u64,
        /// Only this target (repeatable); default: all.
        #[arg(long = "target")]
        targets: Vec<String>,
    },
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Cmd::Setup => setup::setup(),
        Cmd::Data => data::fetch(),
        Cmd::Demo => demo::demo().map(|_| ()),
        Cmd::Bench => bench::bench(),
        Cmd::E2e => tasks::e2e(),
        Cmd::Soak { seconds, rate } => tasks::soak(seconds, rate),
        Cmd::Test => tasks::test(),
        Cmd::Firmware { board, debug } => {
            setup::rust_target()?;
            tasks::firmware(board, !debug)
        }
        Cmd::Fuzz {
            seconds,
            runs,
            targets,
        } => fuzz::fuzz(&fuzz::FuzzOptions {
            seconds,
            runs,
            targets,
        }),
    }
}
