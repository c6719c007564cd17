//! `graph_bench merge`: how `figurine graph merge` grows with the library, and so with the
//! local minima it reads and the edges it keeps.
//!
//! For each library size the job is planned and its tiles run in this process (default band,
//! default T_MG / T_LMA), then `figurine graph merge` runs as its own process, `RUNS` times:
//! wall time from spawn to exit, and the merge's own figures from its output line (read, style,
//! CPU, peak resident memory). One more run under `strace -f -y -e trace=read,pread64` counts
//! the bytes the merge read, per file kind (feature store, tiles, the rest); without strace
//! those columns are NaN. Every merged graph is compared with `graph build` of the same clips
//! (built in this process) byte for byte.
//!
//! Two columns model the growth: style seconds per edge kept, and the memory the merge must
//! hold at its peak (the measurements and the style vectors, 2 × 456 bytes per window, and 28
//! bytes per edge kept: 12 as a candidate, 16 as an edge), to set beside the measured peak.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use anyhow::{bail, Result};
use figurine_host::graph::plan::{plan_job, DEFAULT_BAND};
use figurine_host::graph::tile::run_tile;
use figurine_host::graph::{build_graph, BuildParams, GraphClip};

use crate::figures::after;

/// Bytes a process read, by file kind.
#[derive(Debug, Clone, Copy)]
struct BytesRead {
    store: f64,
    tiles: f64,
    other: f64,
}

/// Sums the results of `read`/`pread64` calls in an `strace -y` log, by the file they read.
fn bytes_read(log: &str) -> BytesRead {
    let mut b = BytesRead {
        store: 0.0,
        tiles: 0.0,
        other: 0.0,
    };
    for line in log.lines() {
        if !(line.contains("read(")
            || line.contains("read64(")
            || line.contains("read resumed>")
            || line.contains("read64 resumed>"))
        {
            continue;
        }
        // A call interrupted by another thread's line is completed on a "resumed" line, which
        // holds the result but not the file: such calls count as "other".
        let Some(n) = line
            .rsplit_once(") = ")
            .and_then(|(_, r)| r.split_whitespace().next())
            .and_then(|r| r.parse::<f64>().ok())
            .filter(|&n| n >= 0.0)
        else {
            continue;
        };
        if line.contains("features.arrow>") {
            b.store += n;
        } else if line.contains("/tiles/tile-") {
            b.tiles += n;
        } else {
            b.other += n;
        }
    }
    b
}

/// One `figurine graph merge` run: wall seconds and its output line.
fn merge_once(exe: &Path, job: &Path, out: &Path, strace: Option<&Path>) -> Result<(f64, String)> {
    let mut cmd = match strace {
        Some(log) => {
            let mut c = Command::new("strace");
            c.args(["-f", "-y", "-e", "trace=read,pread64", "-o"])
                .arg(log)
                .arg(exe);
            c
        }
        None => Command::new(exe),
    };
    let t = Instant::now();
    let o = cmd
        .args(["graph", "merge"])
        .arg(job)
        .arg("--out")
        .arg(out)
        .output()?;
    let wall = t.elapsed().as_secs_f64();
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    if !o.status.success() {
        bail!(
            "merge of {} failed: {text}{}",
            job.display(),
            String::from_utf8_lossy(&o.stderr)
        );
    }
    Ok((wall, text))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Plans, tiles and merges each library of `libraries` (`runs` merges each) and prints one row
/// per library.
pub fn run(libraries: &[Vec<GraphClip>], runs: usize) -> Result<()> {
    let exe = crate::engine::figurine_exe()?;
    let has_strace = Command::new("strace").arg("-V").output().is_ok();
    let dir = std::env::temp_dir().join(format!("figurine-merge-bench-{}", std::process::id()));
    println!(
        "graph merge, default band and thresholds; medians of {runs} merges; bytes read from one run under strace{}",
        if has_strace { "" } else { " (no strace here: NaN)" }
    );
    println!(
        "(MiB: peak resident; model: what the merge must hold, MiB; store MB: the store's size, then MB read from it, from the tiles and from other files)"
    );
    println!(
        "{:>8} {:>5} {:>10} {:>9} | {:>7} {:>6} {:>6} {:>6} {:>5} | {:>7} {:>5} | {:>8} {:>8} {:>8} {:>8}",
        "frames",
        "tiles",
        "minima",
        "edges",
        "wall s",
        "read s",
        "style",
        "cpu s",
        "MiB",
        "µs/edge",
        "model",
        "store MB",
        "read MB",
        "tiles MB",
        "other MB"
    );
    let p = BuildParams::default();
    for clips in libraries {
        let n: usize = clips.iter().map(|c| c.len()).sum();
        let job = dir.join(format!("job-{n}"));
        std::fs::remove_dir_all(&job).ok();
        let planned = plan_job(clips, &Default::default(), &p, DEFAULT_BAND, &job)?;
        for i in 0..planned.manifest.tiles.len() {
            run_tile(&job, i, false)?;
        }
        let built = dir.join(format!("build-{n}.bin"));
        build_graph(clips, &p)?.0.save(&built)?;
        let merged = job.join("graph.bin");
        let mut walls = Vec::new();
        let mut lines = Vec::new();
        for _ in 0..runs.max(1) {
            std::fs::remove_file(&merged).ok();
            let (wall, text) = merge_once(&exe, &job, &merged, None)?;
            if std::fs::read(&merged)? != std::fs::read(&built)? {
                bail!("{n} frames: the merged graph differs from graph build");
            }
            walls.push(wall);
            lines.push(text);
        }
        let field = |key: &str| median(lines.iter().filter_map(|l| after(l, key)).collect());
        let count = |key: &str| {
            lines
                .first()
                .and_then(|l| l.split(key).next())
                .and_then(|s| s.rsplit(' ').next())
                .and_then(|w| w.parse::<f64>().ok())
                .unwrap_or(f64::NAN)
        };
        let read = if has_strace {
            let log = dir.join(format!("strace-{n}.log"));
            merge_once(&exe, &job, &dir.join("strace.bin"), Some(&log))?;
            let b = bytes_read(&std::fs::read_to_string(&log)?);
            std::fs::remove_file(&log).ok();
            b
        } else {
            BytesRead {
                store: f64::NAN,
                tiles: f64::NAN,
                other: f64::NAN,
            }
        };
        let edges = count(" transitions");
        let model_mib =
            (2.0 * 456.0 * planned.manifest.windows as f64 + 28.0 * edges) / (1024.0 * 1024.0);
        println!(
            "{n:>8} {:>5} {:>10.0} {:>9.0} | {:>7.3} {:>6.3} {:>6.3} {:>6.2} {:>5.0} | {:>7.2} {:>5.0} | {:>8.1} {:>8.1} {:>8.1} {:>8.1}",
            planned.manifest.tiles.len(),
            count(" local maxima"),
            edges,
            median(walls),
            field("read "),
            field("style "),
            field("cpu "),
            field("peak "),
            field("style ") / edges * 1e6,
            model_mib,
            planned.store_bytes as f64 / 1e6,
            read.store / 1e6,
            read.tiles / 1e6,
            read.other / 1e6,
        );
        std::fs::remove_dir_all(&job).ok();
        std::fs::remove_file(&built).ok();
    }
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strace_lines_are_summed_by_file() {
        let log = "\
12 read(3</j/features.arrow>, \"\"..., 10) = 10
12 pread64(4</j/tiles/tile-00000.bin>, \"\"..., 8, 0) = 8
12 read(5</etc/ld.so.cache>, \"\"..., 4) = 4
13 read(3</j/features.arrow>, <unfinished ...>
13 <... read resumed>\"\"..., 7) = 7
12 read(3</j/features.arrow>, \"\", 10) = 0
12 read(9</x>, 0x0, 1) = -1 EBADF (Bad file descriptor)";
        let b = bytes_read(log);
        assert_eq!((b.store, b.tiles, b.other), (10.0, 8.0, 11.0));
    }
}
