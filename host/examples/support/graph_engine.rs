//! `graph_bench engine`: the same library built by `graph build` and by a Slurm job array of
//! `graph tile` tasks with a dependent `graph merge`, on a single-node cluster started here.
//!
//! Two overheads are printed: wall time (plan to merged graph file, against the build's) and
//! CPU time (plan + every tile + merge, against the build's). On a machine shared with other
//! work wall time also measures the neighbours; CPU time measures what the split itself costs,
//! and the gap (wall time neither plan, tile nor merge, per task) is what Slurm adds. Each run
//! also prints its stages from plan to graph: the plan's, each tile's and the merge's own
//! timings (from their log lines) and Slurm's (from slurmctld's log: submission, allocation
//! and completion of every task), so that where the time goes is measured, not guessed. With
//! several runs, the medians follow. The scale model uses CPU time per window pair divided by
//! the cores of a task.
use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use figurine_host::graph::build::BuildStats;
use figurine_host::graph::plan::plan_job;
use figurine_host::graph::slurm::write_scripts;
use figurine_host::graph::store::BYTES_PER_FRAME;
use figurine_host::graph::{build_graph, BuildParams};
use figurine_host::graph::{cpu_seconds, peak_memory_mib, GraphClip, Variant};

use crate::figures::{after, tile_log, EngineRun, Row};
use crate::slurm_log::timeline;
use crate::support::slurm::Cluster;

/// Frames of the library the scale model is for (about 40 h at 30 fps, AMASS-size).
const MODEL_FRAMES: f64 = 4.0e6;
/// Band of the modelled job: 31 bands, 496 tiles, within Slurm's default array limit.
const MODEL_BAND: f64 = 131_072.0;
/// Machine counts of the scale model.
const MODEL_MACHINES: [f64; 4] = [1.0, 10.0, 50.0, 200.0];

/// Waits for the merged graph `graph` of merge job `merge_id`: a file test every 5 ms (what a
/// user waits for, and no load on the node), Slurm asked once a second whether the job ended
/// without it. An `scontrol` call every 0.1 s, as before, took ≈ 8 ms of CPU each from the
/// tasks it timed.
fn wait_for_graph(cluster: &Cluster, merge_id: &str, graph: &Path, job: &Path) -> Result<()> {
    let t0 = Instant::now();
    let mut asked = Instant::now();
    while !graph.is_file() {
        if t0.elapsed() > Duration::from_secs(1800) {
            bail!("no graph after 30 minutes\n{}", cluster.log_tail());
        }
        if asked.elapsed() > Duration::from_secs(1) {
            asked = Instant::now();
            if let Some(state) = cluster.ended_state(merge_id) {
                if !graph.is_file() {
                    let log = std::fs::read_to_string(job.join("logs/merge.out"));
                    bail!(
                        "merge job {merge_id}: {state}, no graph\n{}",
                        log.unwrap_or_default()
                    );
                }
            }
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    Ok(())
}

/// One engine run of `clips` with bands of `band` frames; checks the merged bytes against
/// `built`.
fn engine_run(
    cluster: &Cluster,
    clips: &[GraphClip],
    band: usize,
    exe: &Path,
    dir: &Path,
    built: &[u8],
) -> Result<EngineRun> {
    let job = dir.join(format!("job-{band}"));
    std::fs::remove_dir_all(&job).ok();
    let graph = job.join("graph.bin");
    let cpus = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let t0 = Instant::now();
    let c0 = cpu_seconds().unwrap_or(f64::NAN);
    let planned = plan_job(
        clips,
        &Default::default(),
        &BuildParams::default(),
        band,
        &job,
    )?;
    write_scripts(&planned.manifest, &job, exe, &graph, cpus)?;
    let (plan_s, plan_cpu) = (
        t0.elapsed().as_secs_f64(),
        cpu_seconds().unwrap_or(f64::NAN) - c0,
    );
    let ts = Instant::now();
    let out = cluster
        .command("sh")
        .arg(job.join("submit.sh"))
        .env("FIGURINE", exe)
        .output()?;
    let submit_s = ts.elapsed().as_secs_f64();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let id = |key: &str| {
        text.split(key)
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .map(str::to_string)
            .with_context(|| format!("submit.sh: {text}{}", String::from_utf8_lossy(&out.stderr)))
    };
    let (array_id, merge_id) = (id("tiles: job ")?, id("merge: job ")?);
    wait_for_graph(cluster, &merge_id, &graph, &job)?;
    let wall = t0.elapsed().as_secs_f64();
    let state = cluster
        .wait_job(&merge_id, Duration::from_secs(60))
        .map_err(anyhow::Error::msg)?;
    let merge_log = std::fs::read_to_string(job.join("logs/merge.out")).unwrap_or_default();
    if state != "COMPLETED" {
        bail!("merge job {merge_id}: {state}\n{merge_log}");
    }
    if std::fs::read(&graph)? != built {
        bail!("the graph from the job array differs from graph build");
    }
    let tiles = (0..planned.manifest.tiles.len())
        .map(|i| tile_log(&job, i))
        .collect::<Result<Vec<_>>>()?;
    let slurm = std::fs::read_to_string(cluster.controller_log())
        .ok()
        .and_then(|log| timeline(&log, &array_id, &merge_id));
    Ok(EngineRun {
        tiles,
        merge_log,
        plan_s,
        features_s: planned.features_seconds,
        write_s: planned.write_seconds,
        plan_cpu,
        submit_s,
        wall,
        store: planned.store_bytes,
        slurm,
    })
}

/// Runs the comparison for each band of `bands` (frames), `runs` times over (each time
/// `graph build` first, then every band, so each run's overhead compares like conditions),
/// and prints every figure, then the medians; with `model_too`, also the scale model for 4 M
/// frames from the last band's runs.
pub fn run(clips: &[GraphClip], bands: &[usize], runs: usize, model_too: bool) -> Result<()> {
    let n: usize = clips.iter().map(|c| c.len()).sum();
    let exe = std::env::current_exe()?
        .parent()
        .and_then(Path::parent)
        .map(|d| d.join("figurine"))
        .filter(|p| p.is_file())
        .context(
            "no release figurine binary: cargo build --release -p figurine-host --bin figurine",
        )?;
    let dir = std::env::temp_dir().join(format!("figurine-graph-engine-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let p = BuildParams::default();
    let cluster = match Cluster::start(&dir.join("cluster")) {
        Ok(c) => Some(c),
        Err(why) => {
            println!("engine: skipped ({why})");
            None
        }
    };
    let mut fits: Vec<(f64, f64)> = Vec::new();
    let mut model: Option<(f64, f64, f64, f64, f64)> = None;
    let (mut merge_read, mut merge_style) = (f64::NAN, f64::NAN);
    let mut rows: Vec<Vec<Row>> = vec![Vec::new(); bands.len()];
    let mut tiles_of = vec![0usize; bands.len()];
    let mut st = BuildStats::default();
    let mut edges = 0;
    let runs = runs.max(1);
    for rep in 0..runs {
        let t = Instant::now();
        let c0 = cpu_seconds().unwrap_or(f64::NAN);
        let (g, stats) = build_graph(clips, &p)?;
        let built_path = dir.join("build.bin");
        g.save(&built_path)?;
        let build_s = t.elapsed().as_secs_f64();
        let build_cpu = cpu_seconds().unwrap_or(f64::NAN) - c0;
        let built = std::fs::read(&built_path)?;
        edges = g.count(Variant::Mg, None, None);
        println!(
            "{}graph build, {n} frames: {build_s:.2} s, cpu {build_cpu:.2} s (LMA {:.2} s, posture {:.2} s, style {:.2} s), peak {:.0} MiB; {} local maxima, {edges} MG edges",
            if runs > 1 { format!("run {}/{runs}: ", rep + 1) } else { String::new() },
            stats.lma_seconds,
            stats.posture_seconds,
            stats.style_seconds,
            peak_memory_mib().unwrap_or(f64::NAN),
            stats.local_minima,
        );
        st = stats;
        let Some(cluster) = &cluster else {
            std::fs::remove_dir_all(&dir).ok();
            return Ok(());
        };
        println!(
            "\n{:>6} {:>5} | {:>7} {:>6} {:>8} {:>6} {:>6} | {:>7} {:>6} | {:>6} {:>6} {:>6} {:>5} | {:>7} {:>6} {:>5}",
            "band", "tiles", "build s", "plan s", "engine s", "wall+", "gap s", "cpu s", "cpu+", "tile s", "max s", "cpu s", "MiB", "merge s", "cpu s", "MiB"
        );
        for (b, &band) in bands.iter().enumerate() {
            let r = engine_run(cluster, clips, band, &exe, &dir, &built)?;
            let row = Row::of(&r, build_s, build_cpu);
            row.print(&band.to_string(), r.tiles.len());
            tiles_of[b] = r.tiles.len();
            let k = r.tiles.len() as f64;
            let tiles_cpu: f64 = r.tiles.iter().map(|t| t.cpu_s).sum();
            if rep == 0 {
                fits.push((band as f64, row.peak));
            }
            let pairs: f64 = r.tiles.iter().map(|t| t.pairs).sum();
            // Per pair and per frame read, CPU seconds (all the tile's CPU time is put on its
            // pairs).
            let read_per_frame =
                r.tiles.iter().map(|t| t.read_s).sum::<f64>() / (k * 2.0 * band as f64);
            model = Some((
                tiles_cpu / pairs,
                read_per_frame,
                row.gap,
                r.plan_cpu,
                r.store as f64,
            ));
            if b == 0 && rep == 0 {
                println!(
                    "        feature store {:.1} MiB for {n} frames = {:.0} MiB per million frames ({BYTES_PER_FRAME} bytes of values per frame)",
                    r.store as f64 / 1048576.0,
                    r.store as f64 / n as f64 * 1e6 / 1048576.0
                );
                println!("        merge: {}", r.merge_log.trim());
                merge_read = after(&r.merge_log, "read ").unwrap_or(f64::NAN);
                merge_style = after(&r.merge_log, "style ").unwrap_or(f64::NAN);
            }
            rows[b].push(row);
        }
        println!();
    }
    if runs > 1 {
        println!("medians of {runs} runs:");
        for (b, &band) in bands.iter().enumerate() {
            Row::median(&rows[b]).print(&band.to_string(), tiles_of[b]);
        }
    }
    drop(cluster);
    if !model_too {
        std::fs::remove_dir_all(&dir).ok();
        return Ok(());
    }

    // Scale model: measured CPU per pair over the task's cores, measured read per frame,
    // Slurm's measured per-task gap, plan CPU linear in frames.
    let (cpu_pair, s_read_frame, gap, plan_s, store) = model.context("no engine run")?;
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1) as f64;
    let s_pair = cpu_pair / cores;
    let b = (MODEL_FRAMES / MODEL_BAND).ceil();
    let tiles = b * (b + 1.0) / 2.0;
    let tile_s = MODEL_BAND * MODEL_BAND * s_pair + 2.0 * MODEL_BAND * s_read_frame;
    let scale = MODEL_FRAMES / n as f64;
    let pair_ratio = scale * scale;
    let minima = st.local_minima as f64 * pair_ratio;
    let edges_4m = edges as f64 * pair_ratio;
    // Tile memory grows linearly with the band (its two bands' frames): fit to the two runs.
    let (slope, icpt) = match (fits.first(), fits.last()) {
        (Some(&(b1, m1)), Some(&(b2, m2))) if b2 != b1 => {
            ((m2 - m1) / (b2 - b1), m1 - (m2 - m1) / (b2 - b1) * b1)
        }
        _ => (0.0, f64::NAN),
    };
    println!(
        "\nscale model, {:.0} M frames (pairs ×{pair_ratio:.0}), bands of {MODEL_BAND} frames, machines of {cores} cores like this one: {tiles:.0} tiles of {:.0} s each ({:.2} CPU-ns per window pair measured), tile memory ≈ {:.0} MiB, feature store {:.1} GiB, plan {:.0} s (linear in frames)",
        MODEL_FRAMES / 1e6,
        tile_s,
        cpu_pair * 1e9,
        icpt + slope * MODEL_BAND,
        store / n as f64 * MODEL_FRAMES / 1073741824.0,
        plan_s * scale,
    );
    println!(
        "  merge reads ≈ {minima:.2e} local minima ({:.0} GiB of tiles) and keeps ≈ {edges_4m:.2e} edges if edges grow like pairs; merge memory ≈ {:.1} GiB (measurements and style vectors) + {:.1} GiB (edges)",
        minima * 12.0 / 1073741824.0,
        2.0 * 456.0 * MODEL_FRAMES / 1073741824.0,
        edges_4m * 28.0 / 1073741824.0
    );
    // Merge: reading grows with the local minima, style with the edges; both like pairs.
    let merge_s = (merge_read + merge_style) * pair_ratio;
    println!(
        "  merge ≈ {:.2} h on one machine (read {merge_read:.2} s + style {merge_style:.2} s at {n} frames, × {pair_ratio:.0})",
        merge_s / 3600.0
    );
    println!("  {:>9} | {:>8} | {:>10}", "machines", "tiles h", "total h");
    for k in MODEL_MACHINES {
        let waves = (tiles / k).ceil();
        let spread = plan_s * scale + waves * (tile_s + gap);
        println!(
            "  {k:>9.0} | {:>8.2} | {:>10.2}",
            spread / 3600.0,
            (spread + merge_s) / 3600.0
        );
    }
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}
