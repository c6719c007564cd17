//! `graph_bench engine`: the same library built by `figurine graph build` and by the engine
//! path on a single-node Slurm cluster started here: `srun figurine graph plan … --submit` (the
//! plan as a job step, which submits a job array of `graph tile` tasks that waits for it, and a
//! dependent `graph merge`). Both are the CLI a user runs, on the same BVH files (the library is
//! written to a folder first), so both include loading the clips and starting processes.
//!
//! Two overheads are printed: wall time (`srun` to the merged graph file, against the build
//! command's) and CPU time (plan + every tile + merge, against the build's). On a machine shared
//! with other work wall time also measures the neighbours; CPU time measures what the split
//! itself costs, and the gap (wall time neither plan, tile nor merge, per task) is what Slurm
//! adds. Each run also prints its stages from plan to graph: the plan's, each tile's and the
//! merge's own timings (from their output) and Slurm's (from slurmctld's log: the plan job's
//! allocation and end, each task's allocation and completion, the merge's), so that where the
//! time goes is measured, not guessed. With several runs, the medians follow. The scale model
//! uses CPU time per window pair divided by the cores of a task.
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use figurine_host::graph::store::BYTES_PER_FRAME;
use figurine_host::graph::GraphClip;
use figurine_host::motion::write_bvh_path;

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

/// Runs `figurine ARGS…` (or `cmd` as given) and returns its stdout; fails with its output.
fn run_out(cmd: &mut std::process::Command) -> Result<String> {
    let out = cmd.output()?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    if !out.status.success() {
        bail!(
            "{cmd:?} failed: {text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    Ok(text)
}

/// The word after `key` in `text`.
fn word_after(text: &str, key: &str) -> Result<String> {
    text.split(key)
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .map(|w| w.trim_end_matches([',', ';']).to_string())
        .with_context(|| format!("no `{key}` in: {text}"))
}

/// The number after `key` in `text`, or an error quoting it.
fn number_after(text: &str, key: &str) -> Result<f64> {
    after(text, key).with_context(|| format!("no `{key}` figure in: {text}"))
}

/// What `figurine graph build` printed, and its wall seconds.
struct Built {
    wall: f64,
    load: f64,
    lma: f64,
    posture: f64,
    posture_cpu: f64,
    style: f64,
    cpu: f64,
    peak: f64,
    local_minima: f64,
    edges: f64,
}

/// `figurine graph build LIB --out OUT`, timed from spawn to exit.
fn build_cli(exe: &Path, lib: &Path, out: &Path) -> Result<Built> {
    let t = Instant::now();
    let text = run_out(
        std::process::Command::new(exe)
            .args(["graph", "build"])
            .arg(lib)
            .arg("--out")
            .arg(out)
            .arg("--quiet"),
    )?;
    let wall = t.elapsed().as_secs_f64();
    Ok(Built {
        wall,
        load: number_after(&text, "load ")?,
        lma: number_after(&text, ", LMA ")?,
        posture: number_after(&text, "posture ")?,
        posture_cpu: number_after(&text, "posture cpu ")?,
        style: number_after(&text, "style ")?,
        cpu: number_after(&text, ", cpu ")?,
        peak: number_after(&text, "peak ")?,
        local_minima: word_after(&text, "window pairs, ")?.parse()?,
        edges: word_after(&text, "MG ")?.parse()?,
    })
}

/// One engine run of library folder `lib` with bands of `band` frames: `srun figurine graph
/// plan … --submit` (with `via_srun`; else the plan on this machine, outside Slurm, as a user
/// on a login node would run it and `submit.sh`), then the graph file awaited; checks the
/// merged bytes against `built`.
fn engine_run(
    cluster: &Cluster,
    lib: &Path,
    band: usize,
    via_srun: bool,
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
    let mut cmd = if via_srun {
        let mut c = cluster.command("srun");
        c.arg(format!("--cpus-per-task={cpus}"))
            .arg("--job-name=figurine-plan")
            .arg(exe);
        c
    } else {
        cluster.command(&exe.to_string_lossy())
    };
    let text = run_out(
        cmd.args(["graph", "plan"])
            .arg(lib)
            .arg("--out")
            .arg(&job)
            .args(["--band", &band.to_string(), "--submit", "--quiet"])
            .env("FIGURINE", exe),
    )?;
    let srun_s = t0.elapsed().as_secs_f64();
    let plan_id = if via_srun {
        Some(word_after(&text, "when Slurm job ")?)
    } else {
        None
    };
    let (array_id, merge_id) = (
        word_after(&text, "tiles: job ")?,
        word_after(&text, "merge: job ")?,
    );
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
    let tiles_n: usize = word_after(&text, " frames, ")?.parse()?;
    let tiles = (0..tiles_n)
        .map(|i| tile_log(&job, i))
        .collect::<Result<Vec<_>>>()?;
    let slurm = std::fs::read_to_string(cluster.controller_log())
        .ok()
        .and_then(|log| timeline(&log, plan_id.as_deref(), &array_id, &merge_id));
    let store = std::fs::metadata(job.join("features.arrow"))?.len();
    Ok(EngineRun {
        tiles,
        merge_log,
        srun_s,
        plan_s: number_after(&text, "MiB; ")?,
        load_s: number_after(&text, "(load ")?,
        features_s: number_after(&text, ", features ")?,
        write_s: number_after(&text, "store ")?,
        plan_cpu: number_after(&text, "cpu ")?,
        submit_s: number_after(&text, "submitted in ")?,
        wall,
        store,
        slurm,
    })
}

/// The release `figurine` binary beside the examples folder, which the benches run as a user
/// would.
pub fn figurine_exe() -> Result<PathBuf> {
    std::env::current_exe()?
        .parent()
        .and_then(Path::parent)
        .map(|d| d.join("figurine"))
        .filter(|p| p.is_file())
        .context(
            "no release figurine binary: cargo build --release -p figurine-host --bin figurine",
        )
}

/// Runs the comparison for each band of `bands` (frames), `runs` times over (each time
/// `graph build` first, then every band, so each run's overhead compares like conditions),
/// and prints every figure, then the medians; with `model_too`, also the scale model for 4 M
/// frames from the last band's runs.
pub fn run(clips: &[GraphClip], bands: &[usize], runs: usize, model_too: bool) -> Result<()> {
    let n: usize = clips.iter().map(|c| c.len()).sum();
    let exe = figurine_exe()?;
    let dir = std::env::temp_dir().join(format!("figurine-graph-engine-{}", std::process::id()));
    // The library as BVH files, so that `graph build` and `graph plan` read the same clips the
    // way a user's commands would.
    let lib = dir.join("library");
    std::fs::create_dir_all(&lib)?;
    for (k, c) in clips.iter().enumerate() {
        write_bvh_path(&c.clip, &lib.join(format!("clip{k:03}.bvh")))?;
    }
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
    // Each band twice: planned outside Slurm and submitted with submit.sh (the first task
    // waits for the controller's next pass), then planned by an srun step that submits.
    let jobs: Vec<(usize, bool)> = bands
        .iter()
        .flat_map(|&b| [(b, false), (b, true)])
        .collect();
    let label =
        |&(band, srun): &(usize, bool)| format!("{band} {}", if srun { "srun" } else { "sbatch" });
    let mut rows: Vec<Vec<Row>> = vec![Vec::new(); jobs.len()];
    let mut tiles_of = vec![0usize; jobs.len()];
    let (mut minima, mut edges) = (0.0, 0.0);
    let runs = runs.max(1);
    for rep in 0..runs {
        let built_path = dir.join("build.bin");
        let bl = build_cli(&exe, &lib, &built_path)?;
        let (build_s, build_cpu) = (bl.wall, bl.cpu);
        let built = std::fs::read(&built_path)?;
        (minima, edges) = (bl.local_minima, bl.edges);
        println!(
            "{}figurine graph build, {n} frames: {build_s:.2} s, cpu {build_cpu:.2} s (load {:.2} s, LMA {:.2} s, posture {:.2} s, style {:.2} s), peak {:.0} MiB; {minima} local maxima, {edges} MG edges",
            if runs > 1 { format!("run {}/{runs}: ", rep + 1) } else { String::new() },
            bl.load,
            bl.lma,
            bl.posture,
            bl.style,
            bl.peak,
        );
        let Some(cluster) = &cluster else {
            std::fs::remove_dir_all(&dir).ok();
            return Ok(());
        };
        println!(
            "\n{:>12} {:>5} | {:>7} {:>6} {:>8} {:>6} {:>6} | {:>7} {:>6} | {:>6} {:>6} {:>6} {:>5} | {:>7} {:>6} {:>5}",
            "band", "tiles", "build s", "plan s", "engine s", "wall+", "gap s", "cpu s", "cpu+", "tile s", "max s", "cpu s", "MiB", "merge s", "cpu s", "MiB"
        );
        for (b, job) in jobs.iter().enumerate() {
            let (band, via_srun) = *job;
            let r = engine_run(cluster, &lib, band, via_srun, &exe, &dir, &built)?;
            let row = Row::of(&r, build_s, build_cpu);
            row.print(&label(job), r.tiles.len());
            // The same kernel tiles in both: wall and CPU of the tiles' searches against the
            // build's posture stage.
            println!(
                "        search: tiles {:.2} s, cpu {:.2} s; graph build's posture {:.2} s, cpu {:.2} s",
                r.tiles.iter().map(|t| t.search_s).sum::<f64>(),
                r.tiles.iter().map(|t| t.search_cpu).sum::<f64>(),
                bl.posture,
                bl.posture_cpu,
            );
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
        for (b, job) in jobs.iter().enumerate() {
            Row::median(&rows[b]).print(&label(job), tiles_of[b]);
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
    let minima = minima * pair_ratio;
    let edges_4m = edges * pair_ratio;
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
