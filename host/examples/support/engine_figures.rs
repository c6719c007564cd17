//! The figures of one `graph_bench engine` run: each tile's and the merge's own timings (from
//! their log lines), Slurm's timeline (from slurmctld's log), and the row of the printed table
//! they make, or the medians of several runs.

use std::path::Path;

use anyhow::{bail, Context, Result};

use crate::slurm_log::SlurmTimeline;

/// Figures of one tile task, from its log line.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct TileLog {
    pub(crate) pairs: f64,
    pub(crate) read_s: f64,
    pub(crate) search_s: f64,
    pub(crate) search_cpu: f64,
    pub(crate) write_s: f64,
    pub(crate) cpu_s: f64,
    pub(crate) peak_mib: f64,
}

impl TileLog {
    /// Wall seconds inside `figurine graph tile`.
    pub(crate) fn wall(&self) -> f64 {
        self.read_s + self.search_s + self.write_s
    }
}

/// The number after `key` in `text` (e.g. `"read "` → 0.12 in "read 0.12 s").
pub(crate) fn after(text: &str, key: &str) -> Option<f64> {
    let rest = &text[text.find(key)? + key.len()..];
    rest.split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .next()?
        .parse()
        .ok()
}

pub(crate) fn tile_log(job: &Path, i: usize) -> Result<TileLog> {
    let path = job.join("logs").join(format!("tile-{i}.out"));
    let t = std::fs::read_to_string(&path).with_context(|| path.display().to_string())?;
    let pairs = t
        .split(" window pairs")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|n| n.parse().ok());
    let field = |k| after(&t, k);
    match (
        pairs,
        field("read "),
        field("search "),
        field("search cpu "),
        field("write "),
        field(", cpu "),
        field("peak "),
    ) {
        (
            Some(pairs),
            Some(read_s),
            Some(search_s),
            Some(search_cpu),
            Some(write_s),
            Some(cpu_s),
            Some(peak_mib),
        ) => Ok(TileLog {
            pairs,
            read_s,
            search_s,
            search_cpu,
            write_s,
            cpu_s,
            peak_mib,
        }),
        _ => bail!("{}: no figures in `{t}`", path.display()),
    }
}

/// What one engine run measured.
pub(crate) struct EngineRun {
    /// Figures of each tile task.
    pub(crate) tiles: Vec<TileLog>,
    /// The merge task's log.
    pub(crate) merge_log: String,
    /// Wall seconds of `srun figurine graph plan … --submit`, from its start to its return.
    pub(crate) srun_s: f64,
    /// The plan's own wall seconds (before submitting), of which loading the clips, computing
    /// features and writing the store and manifest.
    pub(crate) plan_s: f64,
    pub(crate) load_s: f64,
    pub(crate) features_s: f64,
    pub(crate) write_s: f64,
    /// Plan CPU seconds.
    pub(crate) plan_cpu: f64,
    /// Wall seconds of `submit.sh` (two sbatch calls) inside the plan.
    pub(crate) submit_s: f64,
    /// Wall seconds from `srun` to the merged graph file.
    pub(crate) wall: f64,
    /// Feature store size, bytes.
    pub(crate) store: u64,
    /// Slurm's timeline of the job (None if its log could not be read).
    pub(crate) slurm: Option<SlurmTimeline>,
}

/// The figures of one row of the table (one run, or the medians of several).
#[derive(Debug, Clone, Default)]
pub(crate) struct Row {
    pub(crate) wall: f64,
    pub(crate) build: f64,
    pub(crate) build_cpu: f64,
    pub(crate) plan: f64,
    pub(crate) gap: f64,
    pub(crate) cpu: f64,
    pub(crate) tile_mean: f64,
    pub(crate) tile_max: f64,
    pub(crate) tile_cpu: f64,
    pub(crate) peak: f64,
    pub(crate) merge: f64,
    pub(crate) merge_cpu: f64,
    pub(crate) merge_mib: f64,
    /// Wall seconds of each stage from plan to graph, named.
    pub(crate) stages: Vec<(&'static str, f64)>,
}

impl Row {
    pub(crate) fn of(r: &EngineRun, build: f64, build_cpu: f64) -> Row {
        let k = r.tiles.len() as f64;
        let work: f64 = r.tiles.iter().map(TileLog::wall).sum();
        let tile_cpu: f64 = r.tiles.iter().map(|t| t.cpu_s).sum();
        let merge = after(&r.merge_log, "total ").unwrap_or(f64::NAN);
        let merge_cpu = after(&r.merge_log, "cpu ").unwrap_or(f64::NAN);
        let sum = |f: fn(&TileLog) -> f64| r.tiles.iter().map(f).sum::<f64>();
        let mut stages = vec![
            ("plan: load", r.load_s),
            ("plan: features", r.features_s),
            ("plan: store + manifest", r.write_s),
            (
                "plan: scripts",
                r.plan_s - r.load_s - r.features_s - r.write_s,
            ),
            ("submit.sh", r.submit_s),
            (
                "srun: plan step start + end",
                r.srun_s - r.plan_s - r.submit_s,
            ),
        ];
        match &r.slurm {
            Some(s) => {
                let in_slurm: f64 = s.task_runs.iter().sum();
                let merge_slurm = s.merge_run;
                stages.extend([
                    ("Slurm: plan's end to the first task", s.first_start),
                    ("tiles: read", sum(|t| t.read_s)),
                    ("tiles: search", sum(|t| t.search_s)),
                    ("tiles: write", sum(|t| t.write_s)),
                    ("Slurm: task start + end", in_slurm - work),
                    ("Slurm: between tasks", s.between),
                    ("Slurm: to the merge", s.merge_start),
                    (
                        "merge: read",
                        after(&r.merge_log, "read ").unwrap_or(f64::NAN),
                    ),
                    (
                        "merge: style",
                        after(&r.merge_log, "style ").unwrap_or(f64::NAN),
                    ),
                    (
                        "merge: write",
                        merge
                            - after(&r.merge_log, "read ").unwrap_or(f64::NAN)
                            - after(&r.merge_log, "style ").unwrap_or(f64::NAN),
                    ),
                    ("Slurm: merge start + end", merge_slurm - merge),
                    // What the other stages leave: srun returns a few hundredths of a second
                    // after slurmctld logs the plan job's end, and the graph file appears a few
                    // hundredths before it logs the merge's, so this is about zero when
                    // nothing else is lost.
                    ("rest", r.wall - r.srun_s - s.span),
                ]);
            }
            None => stages.push(("Slurm log unread", f64::NAN)),
        }
        Row {
            wall: r.wall,
            build,
            build_cpu,
            plan: r.srun_s,
            gap: (r.wall - r.plan_s - r.submit_s - work - merge) / (k + 1.0),
            cpu: r.plan_cpu + tile_cpu + merge_cpu,
            tile_mean: work / k,
            tile_max: r.tiles.iter().map(TileLog::wall).fold(0.0, f64::max),
            tile_cpu: tile_cpu / k,
            peak: r.tiles.iter().map(|t| t.peak_mib).fold(0.0, f64::max),
            merge,
            merge_cpu,
            merge_mib: after(&r.merge_log, "peak ").unwrap_or(f64::NAN),
            stages,
        }
    }

    /// Field by field medians of `rows` (stages by position).
    pub(crate) fn median(rows: &[Row]) -> Row {
        let med = |f: &dyn Fn(&Row) -> f64| {
            let mut v: Vec<f64> = rows.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let stages = (0..rows[0].stages.len())
            .map(|i| (rows[0].stages[i].0, med(&|r: &Row| r.stages[i].1)))
            .collect();
        Row {
            wall: med(&|r| r.wall),
            build: med(&|r| r.build),
            build_cpu: med(&|r| r.build_cpu),
            plan: med(&|r| r.plan),
            gap: med(&|r| r.gap),
            cpu: med(&|r| r.cpu),
            tile_mean: med(&|r| r.tile_mean),
            tile_max: med(&|r| r.tile_max),
            tile_cpu: med(&|r| r.tile_cpu),
            peak: med(&|r| r.peak),
            merge: med(&|r| r.merge),
            merge_cpu: med(&|r| r.merge_cpu),
            merge_mib: med(&|r| r.merge_mib),
            stages,
        }
    }

    pub(crate) fn print(&self, label: &str, tiles: usize) {
        println!(
            "{label:>12} {tiles:>5} | {:>7.2} {:>6.2} {:>8.2} {:>5.0}% {:>6.2} | {:>7.2} {:>5.0}% | {:>6.2} {:>6.2} {:>6.2} {:>5.0} | {:>7.2} {:>6.2} {:>5.0}",
            self.build,
            self.plan,
            self.wall,
            100.0 * (self.wall / self.build - 1.0),
            self.gap,
            self.cpu,
            100.0 * (self.cpu / self.build_cpu - 1.0),
            self.tile_mean,
            self.tile_max,
            self.tile_cpu,
            self.peak,
            self.merge,
            self.merge_cpu,
            self.merge_mib,
        );
        let stages: Vec<String> = self
            .stages
            .iter()
            .map(|(name, v)| format!("{name} {v:.3}"))
            .collect();
        println!("        stages, s: {}", stages.join(" · "));
    }
}
