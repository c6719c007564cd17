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
//! decides, not the scripts. slurmctld never starts a batch job on its submission (its
//! `job_allocate` only tests a batch job; an interactive `srun`/`salloc` request is allocated
//! at once): its background loop starts pending jobs once a second, after `batch_sched_delay`
//! (default 3 s) has passed. A job ending triggers a scheduling pass at once only through the
//! epilog's completion message, so on a cluster without any `Epilog` a dependent job (the
//! merge) and array tasks waiting for a free node also wait for that loop (Slurm 22.05 to
//! 25.11). With `batch_sched_delay=0` and an `Epilog` (most sites have one), the tiles start
//! within a second of `submit.sh` and the merge within a tenth of a second of the last tile;
//! the test cluster of `tests/support/slurm.rs` is set up that way.
//!
//! The plan's own second of waiting goes too when the plan runs as a Slurm job step and
//! submits the job itself: `srun figurine graph plan … --submit` is allocated at once, and
//! [`submit`] makes the tile array depend on that job (`afterok`), so the array is scheduled
//! by the plan job's end, a few hundredths of a second after the plan, not at the next pass.

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
         # (a quoted default inside \"${{…:-…}}\" would keep its quotes in dash)\n\
         exe={eq}\n\
         exec \"${{FIGURINE:-$exe}}\" graph tile {jq} --index \"$SLURM_ARRAY_TASK_ID\" --quiet\n",
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
         exe={eq}\n\
         exec \"${{FIGURINE:-$exe}}\" graph merge {jq} --out {gq}\n",
        logs = logs.display(),
        plan = m.plan,
    );
    let submit = format!(
        "#!/bin/sh\n\
         # Submits graph job {plan}: {n} tile tasks, then the merge (afterok). Arguments go to\n\
         # both sbatch calls (e.g. --partition=NAME --account=NAME). With FIGURINE_AFTER=JOBID\n\
         # the tiles wait for that job to succeed (`graph plan --submit` inside a Slurm job).\n\
         set -eu\n\
         tiles=$(sbatch --parsable ${{FIGURINE_AFTER:+--dependency=afterok:$FIGURINE_AFTER}} \"$@\" {jt})\n\
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

/// What [`submit`] did: the two jobs and what the script printed.
#[derive(Debug, Clone, PartialEq)]
pub struct Submitted {
    /// Job id of the tile array.
    pub tiles: String,
    /// Job id of the merge.
    pub merge: String,
    /// The script's output line.
    pub message: String,
}

/// The Slurm job this process runs in (`SLURM_JOB_ID`, digits only), if any.
pub fn own_job() -> Option<String> {
    std::env::var("SLURM_JOB_ID")
        .ok()
        .filter(|id| !id.is_empty() && id.bytes().all(|b| b.is_ascii_digit()))
}

/// Runs `JOB/submit.sh` (written by [`write_scripts`]); with `after`, a job id, the tile array
/// waits for that job to succeed. Errors carry the script's own message (no `sbatch`, a
/// refused submission).
pub fn submit(job: &Path, after: Option<&str>) -> Result<Submitted, GraphError> {
    let script = job.join("submit.sh");
    let mut cmd = std::process::Command::new("sh");
    cmd.arg(&script).env_remove("FIGURINE_AFTER");
    if let Some(id) = after {
        cmd.env("FIGURINE_AFTER", id);
    }
    let out = cmd.output().map_err(|source| GraphError::Io {
        path: script.clone(),
        source,
    })?;
    let text = String::from_utf8_lossy(&out.stdout).trim().to_string();
    let failed = || {
        GraphError::Invalid(format!(
            "{}: submission failed ({}): {}{}",
            script.display(),
            out.status,
            text,
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    };
    if !out.status.success() {
        return Err(failed());
    }
    let id = |key: &str| {
        text.split(key)
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .map(str::to_string)
    };
    match (id("tiles: job "), id("merge: job ")) {
        (Some(tiles), Some(merge)) => Ok(Submitted {
            tiles,
            merge,
            message: text,
        }),
        _ => Err(failed()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoting_survives_spaces_and_quotes() {
        assert_eq!(sh_quote("a b"), "'a b'");
        assert_eq!(sh_quote("it's"), r"'it'\''s'");
    }

    /// The program a script runs, as `sh` resolves it with FIGURINE unset and set.
    #[test]
    fn scripts_run_the_planned_binary_unless_figurine_names_another() {
        let m = Manifest {
            format: crate::graph::plan::JOB_FORMAT.into(),
            version: crate::graph::plan::JOB_VERSION,
            plan: "00000000000000ff".into(),
            params: Default::default(),
            roles: Default::default(),
            clips: Vec::new(),
            frames: 1000,
            windows: 966,
            band: 512,
            store_version: 1,
            tiles: crate::graph::plan::tile_list(1000, 512),
        };
        let exe = Path::new("/opt/it's a dir/figurine");
        let [tile, merge, _] = scripts(&m, Path::new("/j"), exe, Path::new("/j/g.bin"), 2);
        for (name, text) in [tile, merge] {
            let line = text
                .lines()
                .find(|l| l.starts_with("exe="))
                .unwrap_or_else(|| panic!("{name}: no exe= line"));
            let resolve = |figurine: Option<&str>| {
                let mut cmd = std::process::Command::new("sh");
                cmd.arg("-c")
                    .arg(format!("{line}\nprintf %s \"${{FIGURINE:-$exe}}\""))
                    .env_remove("FIGURINE");
                if let Some(f) = figurine {
                    cmd.env("FIGURINE", f);
                }
                String::from_utf8(cmd.output().unwrap().stdout).unwrap()
            };
            assert_eq!(resolve(None), exe.to_str().unwrap(), "{name}");
            assert_eq!(resolve(Some("/usr/bin/other")), "/usr/bin/other", "{name}");
            assert!(text.contains("exec \"${FIGURINE:-$exe}\" graph "), "{name}");
        }
    }
}
