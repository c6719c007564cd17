//! Motion-graph build benchmark: time and peak memory at ~10k, ~27k and ~54k frames (30 fps)
//! made from the real BVH files (repeated to reach the size).
//!
//! `cargo run --release -p figurine-host --example graph_bench` runs each size in its own child
//! process (so each peak-memory figure, VmHWM from /proc/self/status, is its own) and prints a
//! table; `… -- FRAMES` runs one size. Needs the data of `cargo xtask setup` (or
//! FIGURINE_DATA_DIR).
//!
//! `… -- engine` writes the library as BVH files and compares `figurine graph build` on them
//! with the same job run through Slurm on a single-node cluster started for it (see
//! `tests/support/slurm.rs`; needs root and the `slurm-wlm` and `munge` packages): planned
//! outside Slurm and submitted with `submit.sh` ("sbatch"), and planned by `srun figurine graph
//! plan … --submit` ("srun"), each a job array of tiles and a dependent merge. 54k frames in
//! 10, 3 and 1 tiles, three runs (medians printed), then 108k frames once. It prints the
//! engine's overhead, its stages from plan to graph, time and memory per tile, merge time and
//! memory, the feature store's size, and a scale model for 4 M frames. `… -- engine FRAMES
//! RUNS BAND…` runs one library size with the given bands (frames) RUNS times. It needs the
//! release `figurine` binary beside the examples folder (`cargo build --release -p
//! figurine-host --bin figurine`).
//!
//! `… -- merge [RUNS [FRAMES…]]` plans and tiles libraries of 27k, 54k and 108k frames (or
//! FRAMES…) and times `figurine graph merge` on each (RUNS merges, default 3): wall, CPU, peak
//! memory and bytes read against the local minima and edges (see `support/merge_figures.rs`);
//! it needs the same release binary.

use std::process::Command;
use std::time::Instant;

#[path = "support/graph_engine.rs"]
mod engine;
#[path = "support/engine_figures.rs"]
mod figures;
#[path = "support/merge_figures.rs"]
mod merge_figures;
#[path = "support/slurm_log.rs"]
mod slurm_log;
#[path = "../tests/support/mod.rs"]
mod support;

use figurine_host::data::require_data_file;
use figurine_host::graph::plan::DEFAULT_BAND;
use figurine_host::graph::source::load_clips;
use figurine_host::graph::{build_graph, BuildParams};
use figurine_host::graph::{GraphClip, Variant};

const FILES: [&str; 6] = [
    "lafan_dance1.bvh",
    "lafan_test.bvh",
    "blender_gestures.bvh",
    "mocapbank_kneel.bvh",
    "sword_attack.bvh",
    "mixamo_walk_turn.bvh",
];
const SIZES: [usize; 3] = [10_000, 27_000, 54_000];

use figurine_host::graph::peak_memory_mib as peak_mib;

/// The library repeated (and the last copy cut) to exactly `frames` frames.
pub fn library(base: &[GraphClip], frames: usize) -> Vec<GraphClip> {
    let mut out = Vec::new();
    let mut total = 0;
    'outer: for rep in 0.. {
        for c in base {
            let left = frames - total;
            if left < figurine_host::graph::WINDOW {
                break 'outer;
            }
            let mut c = c.clone();
            c.clip.name = format!("{}#{rep}", c.clip.name);
            if c.len() > left {
                c.points.truncate(left);
                c.clip.frames.truncate(left);
            }
            total += c.len();
            out.push(c);
        }
    }
    out
}

fn one(frames: usize) -> anyhow::Result<()> {
    let paths = FILES
        .iter()
        .map(|f| require_data_file("bvh", f))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let base = load_clips(&paths, &Default::default())?;
    let clips = library(&base, frames);
    let n: usize = clips.iter().map(|c| c.len()).sum();
    let t = Instant::now();
    let (g, st) = build_graph(&clips, &BuildParams::default())?;
    let secs = t.elapsed().as_secs_f64();
    println!(
        "{n:>7} frames  {:>8.2} s  peak {:>7.1} MiB  | pairs {:.3e}  local maxima {}  MG {}  LMA-MG {}  | lma {:.2} s posture {:.2} s style {:.2} s",
        secs,
        peak_mib().unwrap_or(f64::NAN),
        st.pairs as f64,
        st.local_minima,
        g.count(Variant::Mg, None, None),
        g.count(Variant::Lma, None, None),
        st.lma_seconds,
        st.posture_seconds,
        st.style_seconds
    );
    Ok(())
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("engine") {
        let paths = FILES
            .iter()
            .map(|f| require_data_file("bvh", f))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let base = load_clips(&paths, &Default::default())?;
        if let [frames, runs, bands @ ..] = &args[1..] {
            let bands = bands
                .iter()
                .map(|b| b.parse())
                .collect::<Result<Vec<usize>, _>>()?;
            anyhow::ensure!(!bands.is_empty(), "usage: engine [FRAMES RUNS BAND…]");
            return engine::run(
                &library(&base, frames.parse()?),
                &bands,
                runs.parse()?,
                false,
            );
        }
        // 54k frames cut into 10, 3 and 1 tiles (the default band), three times over for
        // medians, then a library twice as large in 3 tiles of the default band.
        println!("54,000 frames:");
        engine::run(
            &library(&base, 54_000),
            &[16_384, 27_136, DEFAULT_BAND],
            3,
            true,
        )?;
        println!("\n108,000 frames:");
        return engine::run(&library(&base, 108_000), &[DEFAULT_BAND], 1, false);
    }
    if args.first().map(String::as_str) == Some("merge") {
        let paths = FILES
            .iter()
            .map(|f| require_data_file("bvh", f))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let base = load_clips(&paths, &Default::default())?;
        let runs = args.get(1).map(|r| r.parse()).transpose()?.unwrap_or(3);
        let sizes = match args.get(2..) {
            Some(s) if !s.is_empty() => s
                .iter()
                .map(|f| f.parse())
                .collect::<Result<Vec<usize>, _>>()?,
            _ => vec![27_000, 54_000, 108_000],
        };
        let libraries: Vec<Vec<GraphClip>> = sizes.iter().map(|&f| library(&base, f)).collect();
        return merge_figures::run(&libraries, runs);
    }
    if let Some(arg) = args.first() {
        return one(arg.parse()?);
    }
    println!(
        "graph build on {} threads (real BVH data repeated; 30 fps; T_MG 0.9, T_LMA 0.8)",
        rayon::current_num_threads()
    );
    let exe = std::env::current_exe()?;
    for size in SIZES {
        let status = Command::new(&exe).arg(size.to_string()).status()?;
        anyhow::ensure!(status.success(), "benchmark at {size} frames failed");
    }
    Ok(())
}
