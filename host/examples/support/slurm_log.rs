//! Slurm's own timeline of one graph job, read from slurmctld's log: when the plan's job (an
//! `srun` step that submits the rest) ended, when each tile task was allocated and ended, when
//! the merge was allocated and ended.
//!
//! slurmctld logs these events with millisecond time stamps at its default level:
//! ```text
//! [2026-12-02T06:00:30.800] _job_complete: JobId=10 done
//! [2026-12-02T06:00:30.887] _slurm_rpc_submit_batch_job: JobId=11 InitPrio=4294901749 usec=425
//! [2026-12-02T06:00:31.841] sched: Allocate JobId=11_0(11) NodeList=vm #CPUs=2 Partition=figurine
//! [2026-12-02T06:00:32.957] _job_complete: JobId=11_0(11) done
//! ```
//! Only differences between its stamps are used, so the log's time zone does not matter.

/// What Slurm did with one job array and its dependent merge, seconds.
#[derive(Debug, Clone, Default)]
pub struct SlurmTimeline {
    /// From the plan job's end (or, with no plan job, the array's submission) to the first
    /// task's allocation.
    pub first_start: f64,
    /// Each task's time from allocation to completion, in task order.
    pub task_runs: Vec<f64>,
    /// Time between tasks: each allocation after the first, less the previous completion
    /// (with one task at a time on the node; 0 when tasks overlap).
    pub between: f64,
    /// From the last task's completion to the merge's allocation.
    pub merge_start: f64,
    /// The merge's time from allocation to completion.
    pub merge_run: f64,
    /// From the plan job's end (or the array's submission) to the merge's completion.
    pub span: f64,
}

/// Seconds since 1970-01-01 of a `YYYY-MM-DDTHH:MM:SS.mmm` stamp (as if it were UTC).
fn seconds(stamp: &str) -> Option<f64> {
    let (date, time) = stamp.split_once('T')?;
    let mut d = date.split('-').map(|v| v.parse::<i64>().ok());
    let (y, m, day) = (d.next()??, d.next()??, d.next()??);
    let mut t = time.split(':');
    let (h, min, s) = (
        t.next()?.parse::<f64>().ok()?,
        t.next()?.parse::<f64>().ok()?,
        t.next()?.parse::<f64>().ok()?,
    );
    // Days from the civil date (proleptic Gregorian), March-based year.
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * ((m + 9) % 12) + 2) / 5 + day - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    Some(days as f64 * 86_400.0 + h * 3600.0 + min * 60.0 + s)
}

/// One event of the log: its time and the job token (`11`, `11_0(11)`).
fn event<'a>(line: &'a str, marker: &str) -> Option<(f64, &'a str)> {
    let stamp = line.strip_prefix('[')?.split(']').next()?;
    let rest = &line[line.find(marker)? + marker.len()..];
    let token = rest.strip_prefix("JobId=")?.split_whitespace().next()?;
    Some((seconds(stamp)?, token))
}

/// The timeline of array job `array` (its tasks are `array_K(…)`) and merge job `merge` in
/// the log `text`, from the end of plan job `plan` or, without one, from the array's
/// submission; `None` when an event is missing (another log format, a job not finished).
pub fn timeline(text: &str, plan: Option<&str>, array: &str, merge: &str) -> Option<SlurmTimeline> {
    let prefix = format!("{array}_");
    let is_task = |t: &str| t.starts_with(&prefix);
    let (mut plan_done, mut submitted) = (None, None);
    let mut tasks: Vec<(String, Option<f64>, Option<f64>)> = Vec::new();
    let (mut merge_alloc, mut merge_done) = (None, None);
    // Index of a task's entry (`11_3(14)` → `11_3`), added on first sight.
    fn task(tasks: &mut Vec<(String, Option<f64>, Option<f64>)>, tok: &str) -> usize {
        let name = tok.split('(').next().unwrap_or(tok).to_string();
        match tasks.iter().position(|t| t.0 == name) {
            Some(k) => k,
            None => {
                tasks.push((name, None, None));
                tasks.len() - 1
            }
        }
    }
    for line in text.lines() {
        if let Some((t, tok)) = event(line, "_slurm_rpc_submit_batch_job: ") {
            if tok == array {
                submitted = Some(t);
            }
        } else if let Some((t, tok)) = event(line, "sched: Allocate ") {
            if is_task(tok) {
                let k = task(&mut tasks, tok);
                tasks[k].1 = Some(t);
            } else if tok == merge {
                merge_alloc = Some(t);
            }
        } else if let Some((t, tok)) = event(line, "_job_complete: ") {
            if !line.trim_end().ends_with(" done") {
                continue;
            }
            if is_task(tok) {
                let k = task(&mut tasks, tok);
                tasks[k].2 = Some(t);
            } else if tok == merge {
                merge_done = Some(t);
            } else if Some(tok) == plan {
                plan_done = Some(t);
            }
        }
    }
    let plan_done = match plan {
        Some(_) => plan_done?,
        None => submitted?,
    };
    let mut runs: Vec<(f64, f64)> = tasks
        .iter()
        .map(|t| Some((t.1?, t.2?)))
        .collect::<Option<_>>()?;
    if runs.is_empty() {
        return None;
    }
    let task_runs = runs.iter().map(|(a, d)| d - a).collect();
    runs.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut between = 0.0;
    let mut free_at = runs[0].1;
    for &(a, d) in &runs[1..] {
        between += (a - free_at).max(0.0);
        free_at = free_at.max(d);
    }
    let (ma, md) = (merge_alloc?, merge_done?);
    Some(SlurmTimeline {
        first_start: runs[0].0 - plan_done,
        task_runs,
        between,
        merge_start: ma - free_at,
        merge_run: md - ma,
        span: md - plan_done,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_a_two_task_array_and_its_merge() {
        let log = "\
[2026-12-02T23:59:59.400] sched: _slurm_rpc_allocate_resources JobId=10 NodeList=vm usec=275
[2026-12-02T23:59:59.480] _slurm_rpc_submit_batch_job: JobId=11 InitPrio=9 usec=425
[2026-12-02T23:59:59.500] _job_complete: JobId=10 done
[2026-12-02T23:59:59.510] _slurm_rpc_submit_batch_job: JobId=13 InitPrio=8 usec=427
[2026-12-03T00:00:00.000] sched: Allocate JobId=11_0(11) NodeList=vm #CPUs=2 Partition=p
[2026-12-03T00:00:02.000] _job_complete: JobId=11_0(11) WEXITSTATUS 0
[2026-12-03T00:00:02.000] _job_complete: JobId=11_0(11) done
[2026-12-03T00:00:02.250] sched: Allocate JobId=11_1(12) NodeList=vm #CPUs=2 Partition=p
[2026-12-03T00:00:03.250] _job_complete: JobId=11_1(12) done
[2026-12-03T00:00:03.350] sched: Allocate JobId=13 NodeList=vm #CPUs=2 Partition=p
[2026-12-03T00:00:03.850] _job_complete: JobId=13 done
";
        let t = timeline(log, Some("10"), "11", "13").unwrap();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-6;
        assert!(close(t.first_start, 0.5), "{t:?}");
        assert_eq!(t.task_runs.len(), 2);
        assert!(close(t.task_runs[0], 2.0) && close(t.task_runs[1], 1.0));
        assert!(close(t.between, 0.25) && close(t.merge_start, 0.1));
        assert!(close(t.merge_run, 0.5) && close(t.span, 4.35));
        assert!(timeline(log, Some("10"), "11", "14").is_none());
        assert!(timeline(log, Some("9"), "11", "13").is_none());
        // Without a plan job, from the array's submission.
        let t = timeline(log, None, "11", "13").unwrap();
        assert!(close(t.first_start, 0.52) && close(t.span, 4.37), "{t:?}");
    }
}
