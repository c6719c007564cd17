//! The Slurm job a plan writes: a job array of tiles and a merge that depends on it.
//!
//! Slurm is what most university clusters and many studio render farms already run, and a job
//! array is its native form of "the same command for indices 0..N−1": one array task per tile
//! (`SLURM_ARRAY_TASK_ID` is the tile index), retried or re-run per index, and a merge job held
//! with `--dependency=afterok:` until every task succeeded. Nothing here schedules: the scripts
//! only call `figurine graph tile` and `figurine graph merge`.
//!
//! `plan` writes into the job folder:
//! - `tile.sbatch`: `#SBATCH --array=0-(N−1)`, `--cpus-per-task`, one log per task in `logs/`;
//! - `merge.sbatch`: the merge, writing the graph file;
//! - `submit.sh`: submits both (extra arguments, e.g. `--partition=…`, go to both `sbatch`).
//!
//! The job folder must be on a file system every node sees, and `figurine` at the same path
//! on every node (or named by the `FIGURINE` environment variable at submission; sbatch
//! passes the environment on).
//!
//! What Slurm adds to a job's time is its scheduling latency, which the cluster's slurm.conf
//! decides, not the scripts. slurmctld never starts a batch job on its submission: its
//! background loop starts pending jobs once a second, after `batch_sched_delay` (default 3 s)
//! has passed. A job ending triggers a scheduling pass at once only through the epilog's
//! completion message, so on a cluster without any `Epilog` a dependent job (the merge) and
//! array tasks waiting for a free node also wait for that loop (Slurm 22.05 to 25.11). With
//! `batch_sched_delay=0` and an `Epilog` (most sites have one), the tiles start within a
//! second of `submit.sh` and the merge within a tenth of a second of the last tile; the
//! test cluster of `tests/support/slurm.rs` is set up that way.

use std::path::Path;

use super::plan::{write_atomic, Manifest};
use super::GraphError;

/// Largest array index Slurm accepts without raising `MaxArraySize` (default 1001).
pub const DEFAULT_MAX_ARRAY_INDEX: usize = 1000;

/// `s` quoted for a POSIX shell.
pub fn sh_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// The three scripts for job folder `job` (absolute), running `exe`, writing `graph`, with
/// `cpus` CPUs per task.
pub fn scripts(
    m: &Manifest,
    job: &Path,
    exe: &Path,
    graph: &Path,
    cpus: usize,
) -> [(String, String); 3] {
    let q = |p: &Path| sh_quote(&p.to_string_lossy());
    let (jq, eq, gq) = (q(job), q(exe), q(graph));
    let logs = job.join("logs");
    let last = m.tiles.len().saturating_sub(1);
    let tile = format!(
        "#!/bin/sh\n\
         #SBATCH --job-name=figurine-tiles\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --cpus-per-task={cpus}\n\
         #SBATCH --output={logs}/tile-%a.out\n\
         # One tile of graph job {plan} per array task; a task may be re-run at any time.\n\
         set -eu\n\
         export RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{cpus}}}\"\n\
         exec \"${{FIGURINE:-{eq}}}\" graph tile {jq} --index \"$SLURM_ARRAY_TASK_ID\" --quiet\n",
        logs = logs.display(),
        plan = m.plan,
    );
    let merge = format!(
        "#!/bin/sh\n\
         #SBATCH --job-name=figurine-merge\n\
         #SBATCH --cpus-per-task={cpus}\n\
         #SBATCH --output={logs}/merge.out\n\
         # Merges graph job {plan} once every tile task succeeded.\n\
         set -eu\n\
         export RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{cpus}}}\"\n\
         exec \"${{FIGURINE:-{eq}}}\" graph merge {jq} --out {gq}\n",
        logs = logs.display(),
        plan = m.plan,
    );
    let submit = format!(
        "#!/bin/sh\n\
         # Submits graph job {plan}: {n} tile tasks, then the merge (afterok). Arguments go to\n\
         # both sbatch calls (e.g. --partition=NAME --account=NAME).\n\
         set -eu\n\
         tiles=$(sbatch --parsable \"$@\" {jt})\n\
         tiles=${{tiles%%;*}}\n\
         merge=$(sbatch --parsable \"$@\" --dependency=afterok:\"$tiles\" {jm})\n\
         merge=${{merge%%;*}}\n\
         echo \"tiles: job $tiles ({n} tasks); merge: job $merge -> \"{gq}\n",
        plan = m.plan,
        n = m.tiles.len(),
        jt = q(&job.join("tile.sbatch")),
        jm = q(&job.join("merge.sbatch")),
    );
    [
        ("tile.sbatch".into(), tile),
        ("merge.sbatch".into(), merge),
        ("submit.sh".into(), submit),
    ]
}

/// Writes the scripts into `job` (made absolute first) and makes them executable.
pub fn write_scripts(
    m: &Manifest,
    job: &Path,
    exe: &Path,
    graph: &Path,
    cpus: usize,
) -> Result<(), GraphError> {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let job = abs(job);
    for (name, text) in scripts(m, &job, &abs(exe), &abs(graph), cpus.max(1)) {
        let path = job.join(name);
        write_atomic(&path, text.as_bytes())?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).map_err(
                |source| GraphError::Io {
                    path: path.clone(),
                    source,
                },
            )?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoting_survives_spaces_and_quotes() {
        assert_eq!(sh_quote("a b"), "'a b'");
        assert_eq!(sh_quote("it's"), r"'it'\''s'");
    }
}
