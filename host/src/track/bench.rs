//! `figurine track bench`: the tracker against the truth. Generated gestures (every action in
//! turn, random effort) are placed in front of the camera at each distance, rendered with the
//! webcam's faults, encoded to MP4, decoded and tracked; the report gives position and
//! orientation error by distance, by speed and by turn rate, frames lost, the time per frame,
//! whether the recognizer reads the same actions from the tracked log as from the true one,
//! and the tracked log's jitter at rest; then a figurine held still at each distance, read for
//! false alarms ([`super::still`]).

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use super::detect::Family;
use super::eval::{
    compare, place, quantile, quat, render_video, scene, still_noise, summarize, tag_speeds,
    track_video, truth_log, FrameError, Noise, Setup, Summary, Tracking,
};
use super::rig::{BoxSize, DEFAULT_BOX_M};
use super::still::{run_still, still_report};
use super::trial::{
    kept_truths, knobs, steady_readings, write_truths, Reader, JITTER_DRAWS, JITTER_LEVELS,
};
use crate::synth::{gesture, Action, Effort};

/// Arguments of `figurine track bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Distances from the camera to each gesture's start, metres.
    #[arg(long, value_delimiter = ',', default_values_t = [0.5, 0.75, 1.0])]
    pub distances: Vec<f64>,
    /// Gestures per distance (actions in turn: walk, run, jump, …; 0: the figurine held
    /// still only, see `--rest-seconds`).
    #[arg(long, default_value_t = 12)]
    pub gestures: usize,
    /// Master seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Keep the videos and logs here (default: a temporary folder, removed).
    #[arg(long)]
    pub keep: Option<PathBuf>,
    /// Track without smoothing the orientation (`figurine track --raw`).
    #[arg(long)]
    pub raw: bool,
    /// Edge of the tag's black square, metres.
    #[arg(long, default_value_t = 0.04)]
    pub tag_size: f64,
    /// Frames per second of the rendered camera (many webcams also give 60 at 640×480: half
    /// the turn from one frame to the next; the smear is the 8 ms exposure's either way).
    #[arg(long, default_value_t = 30.0)]
    pub fps: f64,
    /// Search every frame whole, not near the tag's last place first (slower; for
    /// comparing the two).
    #[arg(long)]
    pub whole_frames: bool,
    /// The camera exposure the tracker assumes for its motion-blur retry, milliseconds (the
    /// videos are rendered with 8 ms whatever this says; 0 turns the retry off).
    #[arg(long, default_value_t = super::tracker::DEFAULT_EXPOSURE_S * 1000.0)]
    pub exposure_ms: f64,
    /// Track a rig of four tags around the figurine instead of one on its chest: `box`, a
    /// box with tags 0, 1, 2, 3 on its front, left, back and right sides.
    #[arg(long, value_parser = ["box"])]
    pub rig: Option<String>,
    /// The box rig's width (across, the figurine's X), metres.
    #[arg(long, default_value_t = DEFAULT_BOX_M)]
    pub box_width: f64,
    /// The box rig's depth (front to back, its Z), metres.
    #[arg(long, default_value_t = DEFAULT_BOX_M)]
    pub box_depth: f64,
    /// With `--rig box`: a fifth tag on the box's top, this high above the side tags' centres
    /// (metres; the box is drawn that tall).
    #[arg(long, requires = "rig")]
    pub box_top: Option<f64>,
    /// With `--keep DIR`: track the videos an earlier run kept there (same seed, distances
    /// and tag size) instead of rendering them again; a missing one is rendered.
    #[arg(long, requires = "keep")]
    pub reuse: bool,
    /// How far the rendered camera looks down at the figurine, degrees (0: level, at its
    /// height; a laptop's webcam looking at a toy on the desk, 20–40).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub camera_tilt: f64,
    /// How far the tracker is told the camera looks down, degrees (`figurine track
    /// --camera-tilt`; default: `--camera-tilt`, the truth).
    #[arg(long, allow_negative_numbers = true)]
    pub track_tilt: Option<f64>,
    /// Seconds of a figurine held still in a hand at each distance, tracked and read for
    /// false alarms ([`super::still`]; 0: none).
    #[arg(long, default_value_t = 60.0)]
    pub rest_seconds: f64,
}

/// One gesture tracked.
#[derive(Debug, Clone)]
pub struct GestureRun {
    /// The action performed.
    pub action: Action,
    /// Distance it started at, metres.
    pub distance: f64,
    /// Every frame compared.
    pub frames: Vec<FrameError>,
    /// How fast each frame's tags moved, m/s ([`super::eval::tag_speeds`]; one per frame).
    pub tag_speeds: Vec<f64>,
    /// Actions the recognizer read from the truth at the camera's frame times.
    pub truth_actions: Vec<String>,
    /// The most edits any of those needed to match its pattern (0: all exact): how near the
    /// gesture itself lies to the edge of what its pattern accepts.
    pub truth_edits: u32,
    /// Actions it read from the tracked log.
    pub tracked_actions: Vec<String>,
    /// Actions it read from the truth kept at only the frames where the tracker gave a
    /// sample: what a tracker without error, but with the same gaps (the tag out of sight,
    /// lost), would give.
    pub gapped_actions: Vec<String>,
    /// For each of [`JITTER_LEVELS`], how many of [`JITTER_DRAWS`] copies of the truth with
    /// that white jitter are read as the truth is: how steadily the recognizer reads the
    /// gesture under any tracker's jitter, whatever this tracker does.
    pub steady: Vec<u32>,
    /// Tracking time per frame (detection and pose), seconds.
    pub latency_s: Vec<f64>,
    /// Pixels the detector searched per frame.
    pub searched_px: Vec<usize>,
}

/// Renders, tracks and compares one gesture; files go in `dir`.
pub fn run_gesture(
    setup: &Setup,
    action: Action,
    seed: u64,
    dir: &std::path::Path,
    how: Tracking,
    reuse: bool,
) -> Result<GestureRun> {
    let mut pick = crate::synth::rng::SynthRng::from_u64(seed);
    let effort = Effort::random_state(&mut pick);
    let doodle = gesture(seed, &knobs(), action, effort);
    let placed = place(&doodle.log, setup.distance, setup.camera());
    let sc = scene(setup, Family::Tag36h11, 0)?;
    let video = dir.join(format!("{}-{seed}.mp4", action.name()));
    let truths = match kept_truths(reuse, &video, setup, &sc) {
        Some(t) => t,
        None => {
            let t = render_video(setup, &sc, &placed, &video)?;
            if dir.join("keep").exists() {
                write_truths(&video.with_extension("frames.csv"), setup, &t)?;
            }
            t
        }
    };
    let run = track_video(setup, Family::Tag36h11, 0, &video, how)?;
    let frames = compare(&truths, &run.log, setup.camera());
    let tag_speeds = tag_speeds(&sc.body, &truths);
    let truth = truth_log(&truths);
    let reader = Reader::shipped()?;
    let (truth_actions, truth_edits) = reader.reading(&truth)?;
    let tracked_actions = reader.actions(&run.log)?;
    let gapped = crate::poselog::PoseLog {
        samples: truth
            .samples
            .iter()
            .filter(|s| run.log.samples.iter().any(|k| (k.t - s.t).abs() < 1e-6))
            .copied()
            .collect(),
    };
    let gapped_actions = reader.actions(&gapped)?;
    let steady = steady_readings(&reader, &truth, &truth_actions, seed)?;
    if dir.join("keep").exists() {
        truth.write_path(&video.with_extension("truth.csv"))?;
        run.log.write_path(&video.with_extension("tracked.csv"))?;
    }
    Ok(GestureRun {
        action,
        distance: setup.distance,
        frames,
        tag_speeds,
        truth_actions,
        truth_edits,
        tracked_actions,
        gapped_actions,
        steady,
        latency_s: run.latency_s,
        searched_px: run.searched_px,
    })
}

/// Turn rate below which a frame counts as moving without turning in the report's last speed
/// row, rad/s: a tag's face then smears along a line, which the blur retry can undo.
pub const SLOW_TURN_RAD_S: f64 = 5.0;

/// Each frame of one gesture with the figurine's true turn rate there, rad/s: the angle
/// between its neighbours' orientations over their time apart (one-sided at the ends).
fn turn_rates(frames: &[FrameError]) -> Vec<(&FrameError, f64)> {
    let last = frames.len().saturating_sub(1);
    frames
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let (a, b) = (&frames[i.saturating_sub(1)], &frames[(i + 1).min(last)]);
            let dt = b.truth.t - a.truth.t;
            let angle = quat(&a.truth.pose).angle_between(quat(&b.truth.pose));
            let rate = if dt > 0.0 { angle / dt } else { 0.0 };
            (f, if rate.is_finite() { rate } else { 0.0 })
        })
        .collect()
}

/// A table's rows: the frames whose key lies in each bin `[lo, hi)`, labelled by `label`;
/// empty bins are left out.
fn binned(
    out: &mut String,
    frames: &[(&FrameError, f64)],
    bins: &[(f64, f64)],
    label: impl Fn(f64, f64) -> String,
) {
    for &(lo, hi) in bins {
        let s = summarize(
            frames
                .iter()
                .filter(|(_, k)| *k >= lo && *k < hi)
                .map(|(f, _)| *f),
        );
        if s.frames > 0 {
            row(out, &label(lo, hi), &s);
        }
    }
}

fn row(out: &mut String, label: &str, s: &Summary) {
    let _ = writeln!(
        out,
        "| {label} | {} | {:.1} % ({:.1} % of frames in sight) | {:.1} / {:.1} | {:.2} / {:.2} |",
        s.frames,
        100.0 * s.lost as f64 / s.frames.max(1) as f64,
        100.0 * s.lost_visible_share(),
        s.pos_median_mm,
        s.pos_p90_mm,
        s.ori_median_deg,
        s.ori_p90_deg
    );
}

/// The report's tables for a set of tracked gestures.
pub fn report(runs: &[GestureRun]) -> String {
    let mut out = String::new();
    let all: Vec<&FrameError> = runs.iter().flat_map(|r| &r.frames).collect();
    let head = "| frames | lost | position error median / p90, mm | orientation error median / p90, ° |\n|---|---|---|---|---|";
    let _ = writeln!(out, "by distance from the camera (m)\n| distance {head}");
    let keyed = |key: fn(&FrameError) -> f64| all.iter().map(|&f| (f, key(f))).collect();
    let hundredths = |lo: f64, hi: f64| format!("{lo:.2}–{hi:.2}");
    let by_distance: Vec<_> = keyed(|f| -f.truth.pose.pos[2]);
    let distances = [(0.2, 0.5), (0.5, 0.75), (0.75, 1.0), (1.0, 1.5)];
    binned(&mut out, &by_distance, &distances, hundredths);
    let _ = writeln!(out, "\nby speed (m/s)\n| speed {head}");
    let by_speed: Vec<_> = keyed(|f| f.truth.speed);
    let speeds = [
        (0.0, 0.05),
        (0.05, 0.25),
        (0.25, 0.5),
        (0.5, 1.0),
        (1.0, 9.0),
    ];
    binned(&mut out, &by_speed, &speeds, hundredths);
    // A turning figurine's tags outrun its centre: the same frames by how fast its tags moved.
    let _ = writeln!(
        out,
        "\nby the tags' speed (m/s: the fastest corner of any tag)\n| tags' speed {head}"
    );
    let by_tag_speed: Vec<_> = runs
        .iter()
        .flat_map(|r| r.frames.iter().zip(r.tag_speeds.iter().copied()))
        .collect();
    binned(&mut out, &by_tag_speed, &speeds, hundredths);
    // Motion blur grows with how fast the tag's face turns as much as with how fast it moves:
    // the lost frames' cause shows by turn rate, and at speed without turning.
    let turning: Vec<(&FrameError, f64)> =
        runs.iter().flat_map(|r| turn_rates(&r.frames)).collect();
    let _ = writeln!(out, "\nby turn rate (rad/s)\n| turn rate {head}");
    let rates = [
        (0.0, 2.0),
        (2.0, 5.0),
        (5.0, 10.0),
        (10.0, 20.0),
        (20.0, f64::INFINITY),
    ];
    binned(&mut out, &turning, &rates, |lo, hi| {
        if hi.is_finite() {
            format!("{lo:.0}–{hi:.0}")
        } else {
            format!("{lo:.0} and more")
        }
    });
    let s = summarize(
        turning
            .iter()
            .filter(|(f, w)| *w < SLOW_TURN_RAD_S && f.truth.speed >= 0.5 && f.truth.speed < 1.0)
            .map(|(f, _)| *f),
    );
    if s.frames > 0 {
        let label = format!("0.5–1 m/s, turning under {SLOW_TURN_RAD_S:.0} rad/s");
        row(&mut out, &label, &s);
    }
    let s = summarize(all.iter().copied());
    let _ = writeln!(out, "\nall\n| all {head}");
    row(&mut out, "all", &s);
    let same = runs
        .iter()
        .filter(|r| r.truth_actions == r.tracked_actions)
        .count();
    let _ = writeln!(
        out,
        "\nrecognized actions: the same from the tracked log as from the true one in {same} of \
         {} gestures ({:.1} %)",
        runs.len(),
        100.0 * same as f64 / runs.len().max(1) as f64
    );
    let share = |n: usize| 100.0 * n as f64 / runs.len().max(1) as f64;
    let gaps_only = runs
        .iter()
        .filter(|r| r.gapped_actions == r.truth_actions)
        .count();
    let error_only = runs
        .iter()
        .filter(|r| r.gapped_actions == r.tracked_actions)
        .count();
    let _ = writeln!(
        out,
        "  the gaps alone (the truth kept at only the frames the tracker gave a sample) leave it \
         the same in {gaps_only} ({:.1} %); the tracker's error alone (tracked against that gapped \
         truth) in {error_only} ({:.1} %)",
        share(gaps_only),
        share(error_only)
    );
    // The recognizer's own steadiness bounds what any tracker can reach: a gesture near its
    // pattern's edge tips under a tenth of a millimetre.
    let _ = write!(
        out,
        "  the truth with white jitter alone (each sample moved and turned afresh, {JITTER_DRAWS} \
         draws, mean):"
    );
    for (level, (pos_mm, ori_deg)) in JITTER_LEVELS.iter().enumerate() {
        let same: u32 = runs.iter().filter_map(|r| r.steady.get(level)).sum();
        let mean = f64::from(same) / JITTER_DRAWS as f64;
        let _ = write!(
            out,
            " σ {pos_mm} mm and {ori_deg}°, the same in {mean:.2} ({:.1} %);",
            100.0 * mean / runs.len().max(1) as f64
        );
    }
    let _ = writeln!(out);
    // Against what was played: the tracked log may read the action where the truth misreads
    // it, and the other way round.
    let played = |r: &&GestureRun, read: &[String]| read == [r.action.name()];
    let truth_played = runs.iter().filter(|r| played(r, &r.truth_actions)).count();
    let tracked_played = runs
        .iter()
        .filter(|r| played(r, &r.tracked_actions))
        .count();
    let _ = writeln!(
        out,
        "  read as the action played, alone: from the truth {truth_played} ({:.1} %), from the \
         tracked log {tracked_played} ({:.1} %)",
        share(truth_played),
        share(tracked_played)
    );
    // A reading that already needed edits from the truth lies near its pattern's edge, where
    // a few millimetres of tracking error tip it: the share that agrees, by those edits.
    let _ = write!(out, "  by the edits the true log's reading needed:");
    for (label, lo, hi) in [("none", 0, 0), ("one", 1, 1), ("two or more", 2, u32::MAX)] {
        let (n, same) = runs
            .iter()
            .filter(|r| (lo..=hi).contains(&r.truth_edits))
            .fold((0, 0), |(n, same), r| {
                (
                    n + 1,
                    same + usize::from(r.truth_actions == r.tracked_actions),
                )
            });
        let _ = write!(out, " {label}, the same in {same} of {n};");
    }
    let _ = writeln!(out);
    // Each gesture read otherwise, with how steadily its truth reads under the jitter levels:
    // one that tips under a third of a millimetre lies at its pattern's edge.
    for r in runs.iter().filter(|r| r.truth_actions != r.tracked_actions) {
        let steady: Vec<String> = r
            .steady
            .iter()
            .map(|n| format!("{n}/{JITTER_DRAWS}"))
            .collect();
        let _ = writeln!(
            out,
            "  {} at {:.2} m: truth {:?}, tracked {:?}, truth with the gaps {:?}, truth with \
             white jitter the same in {} draws",
            r.action.name(),
            r.distance,
            r.truth_actions,
            r.tracked_actions,
            r.gapped_actions,
            steady.join(", ")
        );
    }
    let mut lat: Vec<f64> = runs.iter().flat_map(|r| r.latency_s.clone()).collect();
    let (med, p95) = (quantile(&mut lat, 0.5), quantile(&mut lat, 0.95));
    let mut px: Vec<f64> = runs
        .iter()
        .flat_map(|r| r.searched_px.iter().map(|&p| p as f64))
        .collect();
    let _ = writeln!(
        out,
        "\nframe → sample (detection and pose, 640×480): median {:.1} ms, p95 {:.1} ms; \
         pixels searched per frame, median {:.0}",
        med * 1000.0,
        p95 * 1000.0,
        quantile(&mut px, 0.5)
    );
    let _ = writeln!(out, "\ntracked jitter at rest (σ):");
    for (lo, hi) in [(0.2, 0.65), (0.65, 0.9), (0.9, 1.5)] {
        let frames: Vec<FrameError> = runs
            .iter()
            .flat_map(|r| r.frames.iter().copied())
            .filter(|f| {
                let d = -f.truth.pose.pos[2];
                d >= lo && d < hi
            })
            .collect();
        let Noise {
            across_mm,
            depth_mm,
            ori_deg,
            pairs,
        } = still_noise(&frames);
        if pairs > 0 {
            let _ = writeln!(
                out,
                "  {lo:.2}–{hi:.2} m: across {across_mm:.2} mm, depth {depth_mm:.2} mm, \
                 orientation {ori_deg:.3}° ({pairs} still frame pairs)"
            );
        }
    }
    out
}

/// `figurine track bench`.
pub fn run(args: &BenchArgs) -> Result<()> {
    if !(args.tag_size > 0.0 && args.tag_size < 0.5) {
        anyhow::bail!(
            "--tag-size {}: the black square's edge in metres",
            args.tag_size
        );
    }
    if !(args.fps >= 1.0 && args.fps <= 1000.0) {
        anyhow::bail!("--fps {}: frames per second, 1 to 1000", args.fps);
    }
    for (flag, deg) in [
        ("--camera-tilt", args.camera_tilt),
        ("--track-tilt", args.track_tilt.unwrap_or(0.0)),
    ] {
        if deg.is_nan() || deg.abs() >= 90.0 {
            anyhow::bail!("{flag} {deg}: how far the camera looks down, degrees (-90 to 90)");
        }
    }
    let tmp;
    let dir = match &args.keep {
        Some(d) => {
            std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
            std::fs::write(d.join("keep"), b"").ok();
            d.clone()
        }
        None => {
            tmp = std::env::temp_dir().join(format!("figurine-track-bench-{}", std::process::id()));
            std::fs::create_dir_all(&tmp)?;
            tmp.clone()
        }
    };
    let rig_box = args.rig.as_ref().map(|_| BoxSize {
        width: args.box_width,
        depth: args.box_depth,
        top: args.box_top,
    });
    if let Some(b) = rig_box {
        let rig = super::rig::Rig::checked_box(Family::Tag36h11, 0, args.tag_size, b)?;
        eprintln!("a box rig of {} × {} m:", b.width, b.depth);
        for line in rig.describe() {
            eprintln!("  {line}");
        }
    }
    let how = Tracking {
        smooth: !args.raw,
        region_search: !args.whole_frames,
        exposure_s: args.exposure_ms.max(0.0) / 1000.0,
        camera_tilt_deg: args.track_tilt.unwrap_or(args.camera_tilt),
    };
    // The camera and picture at the di-th distance, alike for its gestures and its rest.
    let setup_at = |di: usize, distance: f64| Setup {
        distance,
        tag_size: args.tag_size,
        seed: args.seed.wrapping_add(di as u64),
        rig_box,
        fps: args.fps,
        camera_tilt_deg: args.camera_tilt,
        ..Setup::default()
    };
    let mut runs = Vec::new();
    for (di, &distance) in args.distances.iter().enumerate() {
        let setup = setup_at(di, distance);
        for g in 0..args.gestures {
            let action = Action::ALL[g % Action::ALL.len()];
            let seed = args.seed.wrapping_mul(1000) + (di * 100 + g) as u64;
            let r = run_gesture(&setup, action, seed, &dir, how, args.reuse)?;
            let s = summarize(&r.frames);
            eprintln!(
                "{:>9} at {distance:.2} m: {} frames, {:.1} % lost, {:.1} mm, {:.2}°, truth {:?}, tracked {:?}",
                action.name(),
                s.frames,
                100.0 * s.lost as f64 / s.frames.max(1) as f64,
                s.pos_median_mm,
                s.ori_median_deg,
                r.truth_actions,
                r.tracked_actions
            );
            runs.push(r);
        }
    }
    let mut stills = Vec::new();
    if args.rest_seconds > 0.0 {
        for (di, &distance) in args.distances.iter().enumerate() {
            let setup = setup_at(di, distance);
            let seed = args.seed.wrapping_mul(1000) + (di * 100 + 99) as u64;
            let r = run_still(&setup, args.rest_seconds, seed, &dir, how, args.reuse)?;
            eprintln!(
                "held still at {distance:.2} m: {} frames, truth {:?}, tracked {:?}",
                r.frames.len(),
                r.truth_actions,
                r.tracked_actions
            );
            stills.push(r);
        }
    }
    if !runs.is_empty() {
        print!("{}", report(&runs));
    }
    print!("{}", still_report(&stills));
    if args.keep.is_none() {
        let _ = std::fs::remove_dir_all(&dir);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(truth: &[&str], tracked: &[&str], gapped: &[&str]) -> GestureRun {
        let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect();
        GestureRun {
            action: Action::Walk,
            distance: 0.5,
            frames: Vec::new(),
            tag_speeds: Vec::new(),
            truth_actions: names(truth),
            truth_edits: 0,
            tracked_actions: names(tracked),
            gapped_actions: names(gapped),
            steady: vec![JITTER_DRAWS as u32, 1],
            latency_s: vec![0.001],
            searched_px: vec![5_000],
        }
    }

    #[test]
    fn the_report_parts_the_gaps_from_the_tracker_s_error() {
        let runs = [
            run(&["walk"], &["walk"], &["walk"]),
            // Out of sight half the time: the gaps alone lose it, the tracker adds nothing.
            run(&["spin"], &["turn"], &["turn"]),
            // In sight throughout: the tracker's error alone.
            run(&["kick"], &["bow"], &["kick"]),
        ];
        let text = report(&runs);
        assert!(text.contains("in 1 of 3 gestures"), "{text}");
        assert!(text.contains("leave it the same in 2 (66.7 %)"), "{text}");
        assert!(text.contains("in 2 (66.7 %)\n"), "{text}");
        assert!(
            text.contains(
                "truth with the gaps [\"turn\"], truth with white jitter the same in 4/4, 1/4 draws"
            ),
            "{text}"
        );
        // Every draw at the first level, one of four at the second, for each of the three.
        assert!(
            text.contains("σ 0.3 mm and 0.15°, the same in 3.00 (100.0 %); σ 1 mm and 0.5°, the same in 0.75 (25.0 %);"),
            "{text}"
        );
    }

    #[test]
    fn the_report_parts_agreement_by_the_edits_the_true_reading_needed() {
        let edited = |e, r: GestureRun| GestureRun {
            truth_edits: e,
            ..r
        };
        let runs = [
            run(&["walk"], &["walk"], &["walk"]),
            edited(1, run(&["punch"], &["run"], &["punch"])),
            edited(1, run(&["kick"], &["kick"], &["kick"])),
            edited(3, run(&["throw"], &["kick"], &["throw"])),
        ];
        let text = report(&runs);
        assert!(
            text.contains(
                "needed: none, the same in 1 of 1; one, the same in 1 of 2; \
                 two or more, the same in 0 of 1;"
            ),
            "{text}"
        );
    }

    #[test]
    fn lost_frames_are_told_apart_by_how_fast_the_figurine_turned() {
        // A yaw at 3 rad/s, then at 30 rad/s, at 30 fps; the fast half loses every other frame.
        let frames: Vec<FrameError> = (0..20)
            .map(|i| {
                let t = i as f64 / 30.0;
                let yaw = if i < 10 {
                    3.0 * t
                } else {
                    3.0 / 3.0 + 30.0 * (t - 1.0 / 3.0)
                };
                let q = glam::DQuat::from_rotation_y(yaw);
                let pose = crate::poselog::PoseSample {
                    t,
                    pos: [0.0, 0.0, -0.5],
                    quat: [q.w, q.x, q.y, q.z],
                };
                let lost = i >= 10 && i % 2 == 0;
                FrameError {
                    truth: super::super::eval::FrameTruth {
                        t,
                        pose,
                        speed: 0.1,
                        hidden: false,
                    },
                    error: (!lost).then_some((1.0, 1.0)),
                    delta: None,
                    tracked: None,
                }
            })
            .collect();
        let rates: Vec<f64> = turn_rates(&frames).iter().map(|(_, w)| *w).collect();
        assert!((rates[1] - 3.0).abs() < 1e-9, "{rates:?}");
        assert!((rates[15] - 30.0).abs() < 1e-9, "{rates:?}");
        let mut r = run(&["turn"], &["turn"], &["turn"]);
        r.frames = frames;
        let text = report(&[r]);
        // The frame at the change of rate sees one neighbour of each: 16.5 rad/s.
        assert!(text.contains("| 2–5 | 10 | 0.0 %"), "{text}");
        assert!(text.contains("| 10–20 | 1 | 100.0 %"), "{text}");
        assert!(text.contains("| 20 and more | 9 | 44.4 %"), "{text}");
    }
}
