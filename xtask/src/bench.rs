//! `cargo xtask bench`: every figure the issues ask for, printed (nothing here is a test); the
//! benchmark plots (false alarms at rest, the robustness sweep) are written to `target/bench/`.

use anyhow::Result;

use crate::util::{cargo, root, run, step};

/// Runs a host-crate target (`--example NAME` or `--bin figurine`) in release mode, with `args`.
fn host_run(kind: &str, name: &str, args: &[&str]) -> Result<()> {
    run(cargo()
        .args([
            "run",
            "-q",
            "--release",
            "-p",
            "figurine-host",
            kind,
            name,
            "--",
        ])
        .args(args))
}

/// Runs one of the host crate's benchmark examples in release mode, with `args`.
fn host_example(name: &str, args: &[&str]) -> Result<()> {
    host_run("--example", name, args)
}

/// Runs `figurine ARGS…` built in release mode.
fn figurine(args: &[&str]) -> Result<()> {
    host_run("--bin", "figurine", args)
}

/// Runs every benchmark in turn, each printing its own figures with its command; the plots go
/// to `target/bench/`.
pub fn bench() -> Result<()> {
    crate::setup::setup()?;

    step("wire sizes: cargo run -p figurine-protocol --example sizes");
    run(cargo().args(["run", "-q", "-p", "figurine-protocol", "--example", "sizes"]))?;

    step("recognizer on the host: cargo bench -p figurine-host --bench recognizer");
    run(cargo().args(["bench", "-p", "figurine-host", "--bench", "recognizer"]))?;

    step("recognition accuracy: figurine eval (fresh seed, each action learnt from 3 examples)");
    figurine(&["eval"])?;

    let plots = root().join("target/bench");
    let rest_png = plots.join("rest_false_alarms.png");
    step(&format!(
        "false alarms per hour at rest: figurine eval rest --plot {}",
        rest_png.display()
    ));
    figurine(&["eval", "rest", "--plot", &rest_png.to_string_lossy()])?;

    let sweep_png = plots.join("robustness_sweep.png");
    step(&format!(
        "robustness to tracker noise, rate and doodle scale: figurine eval sweep --plot {}",
        sweep_png.display()
    ));
    figurine(&["eval", "sweep", "--plot", &sweep_png.to_string_lossy()])?;

    step("recognition on real doodles (people's motion capture): figurine eval real");
    figurine(&["eval", "real"])?;
    step("the same over 15 libraries learnt from the generator: figurine eval real --libraries 15");
    figurine(&["eval", "real", "--libraries", "15"])?;

    step("one action played several times back to back: figurine eval repeat");
    figurine(&["eval", "repeat"])?;

    step(
        "animation plausibility against real motion capture: figurine check --reference --defaults",
    );
    figurine(&["check", "--reference", "--defaults"])?;

    step(
        "webcam tracker against the truth (rendered doodles, 640x480, 4 cm tag at 0.5-1 m; \
         then a figurine held still for 60 s at each distance, read for false alarms): \
         figurine track bench",
    );
    figurine(&["track", "bench"])?;
    step(
        "webcam tracker searching every frame whole, for what the region search saves \
         (frame → sample and pixels searched against the run above): figurine track bench \
         --whole-frames --rest-seconds 0",
    );
    figurine(&["track", "bench", "--whole-frames", "--rest-seconds", "0"])?;
    step(
        "webcam tracker, the box rig with its top seen from a camera looking down 25 degrees \
         (told the tilt): figurine track bench --rig box --box-top 0.0925 --camera-tilt 25 \
         --rest-seconds 0",
    );
    figurine(&[
        "track",
        "bench",
        "--rig",
        "box",
        "--box-top",
        "0.0925",
        "--camera-tilt",
        "25",
        "--rest-seconds",
        "0",
    ])?;

    step("firmware: sizes, instructions per sample, latency, sustained rate");
    if !crate::util::have("defmt-print") {
        // The mean instructions per sample come from the firmware's defmt log.
        run(std::process::Command::new("cargo").args(["install", "--locked", "defmt-print"]))?;
    }
    crate::tasks::firmware(crate::tasks::Board::Qemu, true)?;
    crate::tasks::firmware(crate::tasks::Board::Nrf52840, true)?;
    run(cargo().args([
        "test",
        "-q",
        "-p",
        "figurine-e2e",
        "--release",
        "--test",
        "bench",
        "--",
        "--ignored",
        "--nocapture",
        "--test-threads",
        "1",
    ]))?;

    step("render: 30 s at 30 fps, 1280x720 (cargo run --release -p figurine-host --example render_bench)");
    host_example("render_bench", &[])?;

    step("motion graph build at ~10k/27k/54k frames (cargo run --release -p figurine-host --example graph_bench)");
    host_example("graph_bench", &[])?;

    step("distributed motion graph, 54k frames: graph build vs a Slurm job array of tiles and a dependent merge (cargo run --release -p figurine-host --example graph_bench -- engine)");
    // The job array runs the release `figurine` binary.
    crate::util::build_figurine()?;
    host_example("graph_bench", &["engine"])?;

    Ok(())
}
