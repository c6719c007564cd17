//! `cargo xtask fuzz`: every cargo-fuzz target, on the pinned stable toolchain.
//!
//! cargo-fuzz passes nightly-only flags (`-Zsanitizer=address`, …) to rustc; the pinned
//! toolchain accepts them under `RUSTC_BOOTSTRAP=1`, so neither CI nor a developer needs a
//! nightly. AddressSanitizer is used when the toolchain ships its runtime (rust-std does for
//! x86_64 Linux), else the targets run without a sanitizer (panics, overflow checks and
//! debug assertions still catch bugs). The three fuzz crates share one target folder
//! (`target/fuzz`) so libFuzzer and the common crates are built once.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{bail, Context, Result};

use crate::util::{have, output, root, run, step};

/// cargo-fuzz release installed by setup (builds with the pinned stable toolchain).
const CARGO_FUZZ_VERSION: &str = "0.13.2";

/// Seconds each target runs in the CI smoke (`cargo xtask test`).
pub const SMOKE_SECONDS: u64 = 15;

/// An input that takes longer than this (seconds) is reported as a hang: a malformed file
/// must fail fast, and the slowest seed runs in well under a second.
const INPUT_TIMEOUT_S: u64 = 10;

/// Memory limit per fuzz process, MiB (also the largest single allocation allowed).
const RSS_LIMIT_MB: u64 = 2048;

/// Real files that seed a fuzz corpus: `(data subfolder, file-name suffix)`; a folder
/// starting with `@` is in the repository instead of the data folder. The LAFAN-derived files
/// may not be committed, so these seeds are copied in at run time.
type RealSeeds = &'static [(&'static str, &'static str)];

/// One fuzz target.
struct Target {
    /// Fuzz crate folder, relative to the repository root.
    dir: &'static str,
    /// cargo-fuzz target name.
    name: &'static str,
    /// Real files copied into the corpus.
    real_seeds: RealSeeds,
    /// libFuzzer `-max_len` (0: libFuzzer's choice, the largest corpus input or 4096).
    max_len: usize,
}

/// Every fuzz target.
const TARGETS: &[Target] = &[
    Target {
        dir: "protocol/fuzz",
        name: "decode_stream",
        real_seeds: &[],
        max_len: 0,
    },
    Target {
        dir: "host/fuzz",
        name: "poselog_csv",
        real_seeds: &[],
        max_len: 0,
    },
    // Real BVH files are trimmed to their hierarchy and first frames (see `bvh_seed`): the
    // hierarchy is what varies between exporters, and 500 KB of frame lines per input would
    // cut the execution rate a hundredfold.
    Target {
        dir: "host/fuzz",
        name: "bvh_import",
        real_seeds: &[("bvh", ".bvh")],
        max_len: 32 * 1024,
    },
    Target {
        dir: "host/fuzz",
        name: "deepmimic_import",
        real_seeds: &[("deepmimic", ".txt"), ("deepmimic", ".urdf")],
        max_len: 0,
    },
    Target {
        dir: "host/fuzz",
        name: "events_jsonl",
        real_seeds: &[],
        max_len: 0,
    },
    Target {
        dir: "host/fuzz",
        name: "library_json",
        real_seeds: &[("@host/assets", "library.json")],
        max_len: 0,
    },
    Target {
        dir: "host/fuzz",
        name: "effort_json",
        real_seeds: &[("@host/assets", "effort.json")],
        max_len: 0,
    },
    // Seeds (host/fuzz/seeds/): a manifest and a tile of a DeepMimic plan.
    Target {
        dir: "host/fuzz",
        name: "graph_manifest",
        real_seeds: &[],
        max_len: 0,
    },
    Target {
        dir: "host/fuzz",
        name: "graph_tile",
        real_seeds: &[],
        max_len: 0,
    },
    // Seed: a one-clip feature store with its frame count and plan id in front (written by
    // `graph::store`'s tests with FIGURINE_WRITE_FUZZ_SEEDS=1). Inputs up to twice its size.
    Target {
        dir: "host/fuzz",
        name: "graph_store",
        real_seeds: &[],
        max_len: 96 * 1024,
    },
    // Seed (host/fuzz/seeds/): a tracked stream's lines with a header and a comment.
    Target {
        dir: "host/fuzz",
        name: "pose_lines",
        real_seeds: &[],
        max_len: 0,
    },
    // Seeds (host/fuzz/seeds/): the box rig with its top tag, then a calibration.
    Target {
        dir: "host/fuzz",
        name: "track_files",
        real_seeds: &[],
        max_len: 0,
    },
    // Seed (host/fuzz/seeds/): a two-clip graph file with its edges (written by `graph::graph`'s
    // tests with FIGURINE_WRITE_FUZZ_SEEDS=1).
    Target {
        dir: "host/fuzz",
        name: "graph_file",
        real_seeds: &[],
        max_len: 0,
    },
    // Seed (host/fuzz/seeds/): three actions over the target's own two BVH takes — a whole
    // clip, a cut one played to both sides, two variants (ping-ponged, scaled). The shipped
    // library names files in folders, which the target skips.
    Target {
        dir: "host/fuzz",
        name: "clip_library",
        real_seeds: &[],
        max_len: 0,
    },
    Target {
        dir: "firmware/recognizer/fuzz",
        name: "sample_feed",
        real_seeds: &[],
        max_len: 0,
    },
    Target {
        dir: "firmware/recognizer/fuzz",
        name: "blobs",
        real_seeds: &[],
        max_len: 0,
    },
];

/// What to run.
#[derive(Debug, Clone)]
pub struct FuzzOptions {
    /// Seconds per target (at most).
    pub seconds: u64,
    /// Executions per target (at most; 0: no limit).
    pub runs: u64,
    /// Only these targets (empty: all).
    pub targets: Vec<String>,
}

/// The figures of one target's run.
#[derive(Debug, Default)]
struct Figures {
    execs: u64,
    seconds: f64,
    cov: Option<u64>,
    corpus: Option<u64>,
}

/// Installs cargo-fuzz when it is missing (from crates.io, built by the pinned toolchain).
pub fn install() -> Result<()> {
    if have("cargo-fuzz") {
        return Ok(());
    }
    step(&format!("installing cargo-fuzz {CARGO_FUZZ_VERSION}"));
    run(Command::new("cargo").current_dir(root()).args([
        "install",
        "--locked",
        "cargo-fuzz",
        "--version",
        CARGO_FUZZ_VERSION,
    ]))
}

/// The shared target folder of the fuzz crates.
fn target_dir() -> PathBuf {
    root().join("target/fuzz")
}

/// `address` when the pinned toolchain ships the AddressSanitizer runtime, else `none`.
fn sanitizer() -> &'static str {
    let sysroot = output(
        Command::new("rustc")
            .current_dir(root())
            .args(["--print", "sysroot"]),
    );
    let lib =
        sysroot.map(|s| PathBuf::from(s.trim()).join("lib/rustlib/x86_64-unknown-linux-gnu/lib"));
    let has_asan = lib
        .and_then(|l| std::fs::read_dir(l).ok())
        .into_iter()
        .flatten()
        .flatten()
        .any(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.starts_with("librustc-") && n.ends_with("_rt.asan.a")
        });
    if has_asan {
        "address"
    } else {
        "none"
    }
}

/// A `cargo fuzz SUBCOMMAND` in `dir` with the shared build settings.
fn cargo_fuzz(dir: &Path, sub: &str, sanitizer: &str) -> Command {
    let mut c = Command::new("cargo");
    c.current_dir(dir)
        // cargo-fuzz's -Z flags on the pinned stable toolchain (no nightly needed).
        .env("RUSTC_BOOTSTRAP", "1")
        .args(["fuzz", sub, "--sanitizer", sanitizer, "--target-dir"])
        .arg(target_dir());
    c
}

/// Runs the fuzz targets; fails on any crash, hang or out-of-memory input, naming the saved
/// artifact. Prints executions and executions per second per target.
pub fn fuzz(opts: &FuzzOptions) -> Result<()> {
    let start = Instant::now();
    install()?;
    let chosen: Vec<&Target> = TARGETS
        .iter()
        .filter(|t| opts.targets.is_empty() || opts.targets.iter().any(|n| n == t.name))
        .collect();
    if let Some(unknown) = opts
        .targets
        .iter()
        .find(|n| !TARGETS.iter().any(|t| t.name == n.as_str()))
    {
        let all: Vec<&str> = TARGETS.iter().map(|t| t.name).collect();
        bail!(
            "unknown fuzz target {unknown:?}; targets: {}",
            all.join(", ")
        );
    }
    let sanitizer = sanitizer();

    let mut dirs: Vec<&str> = chosen.iter().map(|t| t.dir).collect();
    dirs.dedup();
    for dir in &dirs {
        step(&format!("fuzz: build {dir} (sanitizer {sanitizer})"));
        run(&mut cargo_fuzz(&root().join(dir), "build", sanitizer))?;
    }
    let built = start.elapsed().as_secs_f64();

    let data = crate::data::data_dir();
    let mut summary = Vec::new();
    for t in &chosen {
        let dir = root().join(t.dir);
        let corpus = dir.join("corpus").join(t.name);
        std::fs::create_dir_all(&corpus)
            .with_context(|| format!("creating {}", corpus.display()))?;
        copy_real_seeds(t, &data, &corpus)?;
        step(&format!(
            "fuzz {} for {} s{}",
            t.name,
            opts.seconds,
            if opts.runs > 0 {
                format!(" or {} executions", opts.runs)
            } else {
                String::new()
            }
        ));
        let fig = run_target(t, &dir, &corpus, opts, sanitizer)?;
        let line = format!(
            "{}: {} executions in {:.0} s ({:.0}/s){}{}, 0 crashes",
            t.name,
            fig.execs,
            fig.seconds,
            fig.execs as f64 / fig.seconds.max(1e-3),
            fig.cov.map(|c| format!(", cov {c}")).unwrap_or_default(),
            fig.corpus
                .map(|c| format!(", corpus {c}"))
                .unwrap_or_default(),
        );
        println!("{line}");
        summary.push(line);
    }
    step("fuzz summary");
    for line in summary {
        println!("{line}");
    }
    println!(
        "fuzzing took {:.0} s ({built:.0} s building, sanitizer {sanitizer})",
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Copies the target's real seed files into its corpus.
fn copy_real_seeds(t: &Target, data: &Path, corpus: &Path) -> Result<()> {
    for (sub, suffix) in t.real_seeds {
        let folder = match sub.strip_prefix('@') {
            Some(repo_dir) => root().join(repo_dir),
            None => data.join(sub),
        };
        for entry in std::fs::read_dir(&folder).into_iter().flatten().flatten() {
            let p = entry.path();
            if !p.to_string_lossy().ends_with(suffix) {
                continue;
            }
            let Some(name) = p.file_name() else { continue };
            let bytes = std::fs::read(&p).with_context(|| format!("reading {}", p.display()))?;
            let seed = match *suffix {
                ".bvh" => bvh_seed(&bytes),
                ".txt" => deepmimic_seed(&bytes),
                _ => bytes,
            };
            if seed.len() <= 512 * 1024 {
                std::fs::write(corpus.join(name), seed)?;
            }
        }
    }
    Ok(())
}

/// Frames kept in a trimmed BVH or DeepMimic seed.
const BVH_SEED_FRAMES: usize = 8;

/// A real BVH file cut to its hierarchy and first [`BVH_SEED_FRAMES`] frames, with the
/// `Frames:` line saying so.
fn bvh_seed(bytes: &[u8]) -> Vec<u8> {
    let text = String::from_utf8_lossy(bytes);
    let mut out = String::new();
    let mut in_motion = false;
    let mut frames = 0;
    for line in text.lines() {
        let trimmed = line.trim_start();
        if in_motion && !trimmed.starts_with("Frame") {
            if frames == BVH_SEED_FRAMES {
                break;
            }
            frames += 1;
        }
        if trimmed.starts_with("Frames:") {
            out.push_str(&format!("Frames: {BVH_SEED_FRAMES}\n"));
            continue;
        }
        in_motion |= trimmed.starts_with("MOTION");
        out.push_str(line);
        out.push('\n');
    }
    out.into_bytes()
}

/// A DeepMimic motion file (one frame per line inside `"Frames": [ … ]`) cut to its first
/// [`BVH_SEED_FRAMES`] frames; other text is returned whole.
fn deepmimic_seed(bytes: &[u8]) -> Vec<u8> {
    let text = String::from_utf8_lossy(bytes);
    let mut out = String::new();
    let mut frames = 0;
    for line in text.lines() {
        let t = line.trim();
        let is_frame = t.starts_with('[') && t.len() > 1;
        if is_frame && frames == BVH_SEED_FRAMES {
            while out.ends_with(['\n', ',']) {
                out.pop();
            }
            out.push_str("\n]\n}\n");
            return out.into_bytes();
        }
        frames += usize::from(is_frame);
        out.push_str(line);
        out.push('\n');
    }
    bytes.to_vec()
}

/// Runs one target; parses libFuzzer's final statistics.
fn run_target(
    t: &Target,
    dir: &Path,
    corpus: &Path,
    opts: &FuzzOptions,
    sanitizer: &str,
) -> Result<Figures> {
    let mut cmd = cargo_fuzz(dir, "run", sanitizer);
    // Stack use-after-return detection (on by default in recent ASan) puts every stack frame
    // on the heap; it cannot fire in safe Rust and cost 8–43 % of the execution rate here.
    cmd.env("ASAN_OPTIONS", "detect_stack_use_after_return=0")
        .arg(t.name)
        .arg(corpus);
    let seeds = dir.join("seeds").join(t.name);
    if seeds.exists() {
        cmd.arg(&seeds);
    }
    cmd.args([
        "--".to_string(),
        format!("-max_total_time={}", opts.seconds),
        format!("-timeout={INPUT_TIMEOUT_S}"),
        format!("-rss_limit_mb={RSS_LIMIT_MB}"),
        "-print_final_stats=1".to_string(),
    ]);
    if opts.runs > 0 {
        cmd.arg(format!("-runs={}", opts.runs));
    }
    if t.max_len > 0 {
        cmd.arg(format!("-max_len={}", t.max_len));
    }
    let shown = format!("{cmd:?}");
    let t0 = Instant::now();
    let out = cmd
        .output()
        .with_context(|| format!("could not start {shown}"))?;
    let seconds = t0.elapsed().as_secs_f64();
    let log = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        eprintln!("{log}");
        bail!(
            "fuzz target {} failed ({}): a crashing input is saved under {}/artifacts/{} \
             (reproduce: cd {} && RUSTC_BOOTSTRAP=1 cargo fuzz run --sanitizer {sanitizer} \
             {} artifacts/{}/<file>); command: {shown}",
            t.name,
            out.status,
            dir.display(),
            t.name,
            dir.display(),
            t.name,
            t.name
        );
    }
    let stat = |key: &str| -> Option<u64> {
        log.lines()
            .find_map(|l| l.strip_prefix(key))
            .and_then(|v| v.trim().parse().ok())
    };
    // The last status line, e.g. `#315335 DONE cov: 445 ft: 1201 corp: 252/10Kb …`.
    let last = log
        .lines()
        .rev()
        .find(|l| l.starts_with('#') && l.contains("cov:"));
    let field = |name: &str| -> Option<u64> {
        let mut it = last?.split_whitespace();
        it.find(|w| *w == name)?;
        it.next()?.split('/').next()?.parse().ok()
    };
    Ok(Figures {
        execs: stat("stat::number_of_executed_units:").unwrap_or(0),
        seconds,
        cov: field("cov:"),
        corpus: field("corp:"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deepmimic_seeds_keep_a_few_frames_and_stay_json() {
        let mut text = String::from("{\n\"Loop\": \"wrap\",\n\"Frames\":\n[\n");
        let rows: Vec<String> = (0..30).map(|i| format!("[{i}, 0.5, 1]")).collect();
        text.push_str(&rows.join(",\n"));
        text.push_str("\n]\n}\n");
        let seed = String::from_utf8(deepmimic_seed(text.as_bytes())).unwrap();
        let last = format!("[{}, 0.5, 1]\n]\n}}\n", BVH_SEED_FRAMES - 1);
        assert!(seed.ends_with(&last), "{seed}");
        assert_eq!(seed.matches(", 0.5, 1]").count(), BVH_SEED_FRAMES);
        assert_eq!(deepmimic_seed(b"<robot/>"), b"<robot/>");
    }

    #[test]
    fn bvh_seeds_keep_the_hierarchy_and_a_few_frames() {
        let mut text = String::from(
            "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: 100\n\
             Frame Time: 0.01\n",
        );
        for i in 0..100 {
            text.push_str(&format!("{i}\n"));
        }
        let seed = String::from_utf8(bvh_seed(text.as_bytes())).unwrap();
        assert!(seed.starts_with("HIERARCHY\nROOT a\n"));
        assert!(seed.contains(&format!("Frames: {BVH_SEED_FRAMES}\nFrame Time: 0.01\n0\n")));
        assert!(seed.ends_with(&format!("\n{}\n", BVH_SEED_FRAMES - 1)));
        assert_eq!(seed.lines().count(), 9 + BVH_SEED_FRAMES);
    }

    /// Every `[[bin]]` of every fuzz crate is in [`TARGETS`] and the other way round, so a
    /// new fuzz target cannot be left out of the CI smoke.
    #[test]
    fn targets_match_the_fuzz_crates() {
        let mut dirs: Vec<&str> = TARGETS.iter().map(|t| t.dir).collect();
        dirs.sort_unstable();
        dirs.dedup();
        let mut declared = Vec::new();
        for dir in dirs {
            let text = std::fs::read_to_string(root().join(dir).join("Cargo.toml")).unwrap();
            for bin in text.split("[[bin]]").skip(1) {
                let name = bin
                    .lines()
                    .find_map(|l| l.trim().strip_prefix("name = \""))
                    .and_then(|n| n.strip_suffix('"'))
                    .unwrap();
                declared.push((dir, name.to_string()));
            }
        }
        let mut listed: Vec<(&str, String)> = TARGETS
            .iter()
            .map(|t| (t.dir, t.name.to_string()))
            .collect();
        declared.sort();
        listed.sort();
        assert_eq!(declared, listed);
    }
}
