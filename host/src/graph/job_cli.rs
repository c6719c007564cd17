//! `figurine graph plan | tile | merge`: the build as tiles of a job folder (see [`super::plan`]).

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;

use super::graph::Variant;
use super::inputs::{load, BuildOpts};
use super::merge::merge_job;
use super::plan::{plan_job, DEFAULT_BAND};
use super::slurm::{own_job, submit, write_scripts, DEFAULT_MAX_ARRAY_INDEX};
use super::tile::run_tile;
use super::{cpu_seconds, peak_memory_mib, GraphError};

// Arguments of `graph plan`.
#[derive(Args, Debug)]
pub(super) struct PlanArgs {
    /// Clip files (.bvh, DeepMimic .txt next to humanoid.urdf) or folders of them.
    #[arg(required = true)]
    clips: Vec<PathBuf>,
    /// Job folder (created; must be on a file system every node sees).
    #[arg(long)]
    out: PathBuf,
    /// Band of window centres per tile side, frames (a multiple of --tile).
    #[arg(long, default_value_t = DEFAULT_BAND)]
    band: usize,
    /// Graph file the merge job writes (default: JOB/graph.bin).
    #[arg(long)]
    graph: Option<PathBuf>,
    /// CPUs per Slurm task (default: this machine's).
    #[arg(long)]
    cpus_per_task: Option<usize>,
    /// Submit the job (JOB/submit.sh) once planned. Inside a Slurm job (`srun figurine graph
    /// plan … --submit`) the tiles wait for that job and start as soon as it ends.
    #[arg(long)]
    submit: bool,
    #[command(flatten)]
    opts: BuildOpts,
}

// Arguments of `graph tile`.
#[derive(Args, Debug)]
pub(super) struct TileArgs {
    /// Job folder from `figurine graph plan`.
    job: PathBuf,
    /// Tile index (0 .. tiles − 1; a Slurm array task's SLURM_ARRAY_TASK_ID).
    #[arg(long)]
    index: usize,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

// Arguments of `graph merge`.
#[derive(Args, Debug)]
pub(super) struct MergeArgs {
    /// Job folder from `figurine graph plan`, every tile computed.
    job: PathBuf,
    /// Output graph file.
    #[arg(long)]
    out: PathBuf,
    /// Print only errors.
    #[arg(long)]
    quiet: bool,
}

/// `graph plan`: features, manifest and Slurm scripts into the job folder.
pub(super) fn plan_cmd(a: PlanArgs) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let (clips, roles, p) = load(&a.clips, &a.opts)?;
    let load_seconds = t0.elapsed().as_secs_f64();
    let planned = plan_job(&clips, &roles, &p, a.band, &a.out)?;
    let m = &planned.manifest;
    let graph = a.graph.unwrap_or_else(|| a.out.join("graph.bin"));
    let cpus = a
        .cpus_per_task
        .or_else(|| std::thread::available_parallelism().ok().map(|n| n.get()))
        .unwrap_or(1);
    let exe = std::env::current_exe()?;
    write_scripts(m, &a.out, &exe, &graph, cpus)?;
    if planned.stale_removed > 0 {
        eprintln!(
            "note: removed {} tile files of the previous plan",
            planned.stale_removed
        );
    }
    println!(
        "plan {}: {} clips, {} frames, {} tiles ({} frames per band); features {:.1} MiB; {:.2} s (load {:.3} s, features {:.3} s, store {:.3} s), cpu {:.2} s",
        m.plan,
        m.clips.len(),
        m.frames,
        m.tiles.len(),
        m.band,
        planned.store_bytes as f64 / (1024.0 * 1024.0),
        t0.elapsed().as_secs_f64(),
        load_seconds,
        planned.features_seconds,
        planned.write_seconds,
        cpu_seconds().unwrap_or(f64::NAN),
    );
    if m.tiles.len() > DEFAULT_MAX_ARRAY_INDEX + 1 {
        eprintln!(
            "note: {} tiles exceed Slurm's default MaxArraySize (1001): raise it, or plan with a larger --band",
            m.tiles.len()
        );
    }
    if a.submit {
        let after = own_job();
        let t1 = Instant::now();
        let s = submit(&a.out, after.as_deref())?;
        println!(
            "{} (submitted in {:.3} s)",
            s.message,
            t1.elapsed().as_secs_f64()
        );
        if let Some(id) = after {
            println!("the tiles start when Slurm job {id} (this plan) ends");
        }
        return Ok(());
    }
    let job = a.out.display();
    println!("run with Slurm:   sh {job}/submit.sh        (tiles as a job array, then the merge)");
    println!(
        "or by hand:       figurine graph tile {job} --index I   (I = 0..{}), then
                  figurine graph merge {job} --out {}",
        m.tiles.len() - 1,
        graph.display()
    );
    Ok(())
}

/// `graph tile`: one tile of a planned job.
pub(super) fn tile_cmd(a: TileArgs) -> anyhow::Result<()> {
    let r = run_tile(&a.job, a.index, !a.quiet)?;
    println!(
        "tile {}: {} kernel tiles, {} window pairs, {} local minima; read {:.3} s, search {:.3} s (search cpu {:.2} s), write {:.3} s, cpu {:.2} s, peak {:.0} MiB; wrote {}",
        a.index,
        r.kernels,
        r.found.pairs,
        r.found.candidates.len(),
        r.read_seconds,
        r.search_seconds,
        r.search_cpu_seconds,
        r.write_seconds,
        cpu_seconds().unwrap_or(f64::NAN),
        peak_memory_mib().unwrap_or(f64::NAN),
        r.path.display()
    );
    Ok(())
}

/// `graph merge`: every tile into the graph file, written atomically.
pub(super) fn merge_cmd(a: MergeArgs) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let (g, st) = merge_job(&a.job)?;
    // Written beside the target and renamed, so a failed merge never leaves half a graph.
    let name = a
        .out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = a
        .out
        .with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    g.save(&tmp)?;
    std::fs::rename(&tmp, &a.out).map_err(|source| GraphError::Io {
        path: a.out.clone(),
        source,
    })?;
    if !a.quiet {
        println!(
            "{} tiles, {} window pairs, {} local maxima, {} transitions (MG); read {:.3} s, style {:.3} s, total {:.3} s, cpu {:.2} s, peak {:.0} MiB, store bytes {:.1} MB; wrote {}",
            st.tiles,
            st.pairs,
            st.local_minima,
            g.count(Variant::Mg, None, None),
            st.read_seconds,
            st.assemble_seconds,
            t0.elapsed().as_secs_f64(),
            cpu_seconds().unwrap_or(f64::NAN),
            peak_memory_mib().unwrap_or(f64::NAN),
            st.store_bytes_read as f64 / 1e6,
            a.out.display()
        );
    }
    Ok(())
}
