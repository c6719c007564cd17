//! The distributed graph build end to end on the real DeepMimic clips: `graph plan`, the tiles
//! (by hand, and as a Slurm job array on a single-node cluster started for the test), `graph
//! merge`, and the merged file compared byte for byte with `graph build`.

mod common;
mod support;

use std::path::{Path, PathBuf};
use std::time::Duration;

use common::{deepmimic_dir, figurine};
use support::slurm::Cluster;

/// Build options of both paths: looser thresholds (14 short clips), small kernel tiles so the
/// job has several tiles.
const OPTS: [&str; 6] = ["--t-mg", "0.85", "--t-lma", "0.7", "--tile", "64"];
/// Frames per band: 3 bands over DeepMimic's 989 usable frames, 6 tiles.
const BAND: &str = "384";

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("figurine-tiles-{}-{name}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `graph build` of the clips into `dir/build.bin`; its bytes.
fn build(dm: &Path, dir: &Path) -> Vec<u8> {
    let g = dir.join("build.bin");
    let mut args = vec![
        "graph",
        "build",
        dm.to_str().unwrap(),
        "--out",
        g.to_str().unwrap(),
    ];
    args.extend(OPTS);
    args.push("--quiet");
    let (ok, out, err) = figurine(&args);
    assert!(ok, "{out}\n{err}");
    std::fs::read(g).unwrap()
}

/// `graph plan` into `dir/job`; the number of tiles.
fn plan(dm: &Path, job: &Path, extra: &[&str]) -> usize {
    let mut args = vec![
        "graph",
        "plan",
        dm.to_str().unwrap(),
        "--out",
        job.to_str().unwrap(),
        "--band",
        BAND,
    ];
    args.extend(OPTS);
    args.extend(extra);
    args.push("--quiet");
    let (ok, out, err) = figurine(&args);
    assert!(ok, "{out}\n{err}");
    // "plan …: 14 clips, 5000 frames, 6 tiles (1024 frames per band); …"
    let tiles = out
        .split(" tiles (")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no tile count in: {out}"));
    assert!(out.contains("submit.sh"), "{out}");
    tiles
}

#[test]
fn tiles_by_hand_merge_to_the_build_and_bad_jobs_are_refused() {
    let Some(dm) = deepmimic_dir() else { return };
    let dir = tmp("hand");
    let built = build(&dm, &dir);
    let job = dir.join("job");
    let n = plan(&dm, &job, &[]);
    assert!(n >= 3, "{n} tiles");
    let js = job.to_str().unwrap();
    let g = dir.join("merged.bin");
    let gs = g.to_str().unwrap();

    // Tile 0 is missing: merge names it and writes nothing.
    for i in 1..n {
        let (ok, out, err) = figurine(&["graph", "tile", js, "--index", &i.to_string(), "--quiet"]);
        assert!(ok, "{out}\n{err}");
    }
    let (ok, _, err) = figurine(&["graph", "merge", js, "--out", gs]);
    assert!(
        !ok && err.contains("tile-00000.bin") && err.contains("missing"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(!g.exists());
    let (ok, _, err) = figurine(&["graph", "tile", js, "--index", &n.to_string()]);
    assert!(!ok && err.contains("does not exist"), "{err}");

    let (ok, out, err) = figurine(&["graph", "tile", js, "--index", "0", "--quiet"]);
    assert!(ok, "{out}\n{err}");
    let (ok, out, err) = figurine(&["graph", "merge", js, "--out", gs]);
    assert!(ok, "{out}\n{err}");
    assert!(
        std::fs::read(&g).unwrap() == built,
        "merged graph differs from graph build"
    );

    // A store of another plan (other thresholds) is foreign to this manifest.
    let other = dir.join("other");
    plan(&dm, &other, &["--weights", "0.4,0.2,0.2,0.2"]);
    std::fs::copy(other.join("features.arrow"), job.join("features.arrow")).unwrap();
    let (ok, _, err) = figurine(&["graph", "merge", js, "--out", gs]);
    assert!(
        !ok && err.contains("features.arrow") && err.contains("plan"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn slurm_job_array_and_dependent_merge_equal_the_build() {
    let Some(dm) = deepmimic_dir() else { return };
    let dir = tmp("slurm");
    let cluster = match Cluster::start(&dir.join("cluster")) {
        Ok(c) => c,
        Err(why) => {
            eprintln!("skipping the Slurm test: {why}");
            return;
        }
    };
    let built = build(&dm, &dir);
    let job = dir.join("job");
    let n = plan(&dm, &job, &["--cpus-per-task", "1"]);
    let script = std::fs::read_to_string(job.join("tile.sbatch")).unwrap();
    assert!(
        script.contains(&format!("#SBATCH --array=0-{}", n - 1)),
        "{script}"
    );

    let out = cluster
        .command("sh")
        .arg(job.join("submit.sh"))
        .env("FIGURINE", env!("CARGO_BIN_EXE_figurine"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // "tiles: job 1 (6 tasks); merge: job 2 -> …"
    let merge_id = text
        .split("merge: job ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .unwrap_or_else(|| panic!("no merge job id in: {text}"))
        .to_string();
    let state = cluster
        .wait_job(&merge_id, Duration::from_secs(120))
        .unwrap();
    let log = |f: &str| std::fs::read_to_string(job.join("logs").join(f)).unwrap_or_default();
    assert_eq!(
        state,
        "COMPLETED",
        "merge log:\n{}\ntile 0 log:\n{}",
        log("merge.out"),
        log("tile-0.out")
    );
    // Every array task ran its own tile.
    for i in 0..n {
        assert!(
            log(&format!("tile-{i}.out")).contains(&format!("tile {i}:")),
            "tile {i}: {}",
            log(&format!("tile-{i}.out"))
        );
    }
    let merged = std::fs::read(job.join("graph.bin")).unwrap();
    assert!(
        merged == built,
        "graph from the Slurm job differs from graph build"
    );

    // The plan as a Slurm job step that submits the job itself: the tile array depends on the
    // plan's job, so slurmctld starts it when that job ends.
    let job2 = dir.join("job2");
    let mut args = vec![
        "-c1",
        "--job-name=figurine-plan",
        env!("CARGO_BIN_EXE_figurine"),
        "graph",
        "plan",
        dm.to_str().unwrap(),
        "--out",
        job2.to_str().unwrap(),
        "--band",
        BAND,
        "--cpus-per-task",
        "1",
        "--submit",
        "--quiet",
    ];
    args.extend(OPTS);
    let out = cluster.command("srun").args(&args).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let after = |key: &str| {
        text.split(key)
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .unwrap_or_else(|| panic!("no `{key}` in: {text}"))
            .to_string()
    };
    let (plan_id, tiles_id, merge_id) = (
        after("when Slurm job "),
        after("tiles: job "),
        after("merge: job "),
    );
    let state = cluster
        .wait_job(&merge_id, Duration::from_secs(120))
        .unwrap();
    assert_eq!(state, "COMPLETED", "{text}");
    assert!(
        std::fs::read(job2.join("graph.bin")).unwrap() == built,
        "graph from the srun-planned job differs from graph build"
    );
    // slurmctld's log: the plan's job ended before the first tile task was allocated.
    let log = std::fs::read_to_string(cluster.controller_log()).unwrap();
    let line_of = |needle: &str| {
        log.lines()
            .position(|l| l.contains(needle))
            .unwrap_or_else(|| panic!("no `{needle}` in slurmctld's log"))
    };
    assert!(
        line_of(&format!("_job_complete: JobId={plan_id} done"))
            < line_of(&format!("sched: Allocate JobId={tiles_id}_")),
        "the tiles started before the plan's job ended"
    );
    drop(cluster);
    std::fs::remove_dir_all(&dir).ok();
}
