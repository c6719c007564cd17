//! `cargo xtask demo`: the main job, end to end, on a bundled (generated) doodle.
//!
//! 1. `figurine synth sequence` — a seeded doodle of several actions with efforts, as a child
//!    would play them (a real tracker log works the same way).
//! 2. `figurine simulate` — the recognizer (the firmware's own code) reads it: actions, start
//!    and end, Laban Time and Weight.
//! 3. `figurine animate` — a full-body animation along the doodled path (BVH and glTF), and
//!    `figurine check` — how it compares with real motion capture.
//! 4. `figurine render` — a GIF of it, plus one still frame.
//!
//! Everything lands in `target/demo/`.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result};

use crate::util::{root, run, step};

/// Seed of the bundled demo doodle.
const DEMO_SEED: &str = "2026";

fn figurine(bin: &Path) -> Command {
    let mut c = Command::new(bin);
    c.current_dir(root());
    c
}

/// Runs the demo; returns the folder it wrote.
pub fn demo() -> Result<PathBuf> {
    crate::setup::setup()?;
    step("demo: build figurine (release)");
    crate::util::build_figurine()?;
    let bin = root().join("target/release/figurine");
    let out = root().join("target/demo");
    std::fs::create_dir_all(&out)?;
    let log = out.join("doodle.csv");
    let labels = out.join("doodle_labels.json");
    let events = out.join("events.jsonl");
    let bvh = out.join("animation.bvh");
    let glb = out.join("animation.glb");
    let gif = out.join("animation.gif");
    let still = out.join("frame.png");

    step("demo 1/4: a doodle of several actions (figurine synth sequence)");
    run(figurine(&bin)
        .args([
            "synth", "sequence", "--seed", DEMO_SEED, "--count", "6", "--out",
        ])
        .arg(&log)
        .arg("--labels")
        .arg(&labels))?;
    println!(
        "doodle: {}  (what was played: {})",
        log.display(),
        labels.display()
    );

    step("demo 2/4: recognise actions and efforts (figurine simulate)");
    run(figurine(&bin).arg("simulate").arg(&log))?;
    let jsonl = figurine(&bin)
        .args(["simulate", "--jsonl"])
        .arg(&log)
        .output()
        .context("running figurine simulate --jsonl")?;
    anyhow::ensure!(
        jsonl.status.success(),
        "figurine simulate failed: {}",
        String::from_utf8_lossy(&jsonl.stderr)
    );
    std::fs::write(&events, &jsonl.stdout)?;
    println!("events: {}", events.display());

    step("demo 3/4: assemble the character animation (figurine animate)");
    run(figurine(&bin)
        .arg("animate")
        .arg(&log)
        .arg("--events")
        .arg(&events)
        .arg("--out")
        .arg(&bvh)
        .arg("--glb")
        .arg(&glb))?;
    // Would a person believe it? The plausibility report against real motion capture.
    run(figurine(&bin).arg("check").arg(&bvh))?;

    step("demo 4/4: render it (figurine render, Vulkan via lavapipe when there is no GPU)");
    run(figurine(&bin)
        .arg("render")
        .arg(&bvh)
        .arg("--doodle")
        .arg(&log)
        .arg("--events")
        .arg(&events)
        .args(["--size", "480x270", "--fps", "15", "--out"])
        .arg(&gif))?;
    run(figurine(&bin)
        .arg("render")
        .arg(&bvh)
        .arg("--doodle")
        .arg(&log)
        .arg("--events")
        .arg(&events)
        .args(["--size", "960x540", "--out"])
        .arg(&still))?;

    println!("\ndemo written to {}:", out.display());
    for f in [&log, &labels, &events, &bvh, &glb, &gif, &still] {
        println!("  {}", f.display());
    }
    Ok(out)
}
