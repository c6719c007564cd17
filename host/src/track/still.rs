//! `figurine track bench --rest-seconds N`: the tracker with the figurine held still.
//!
//! A webcam user rests the figurine in a hand between gestures, in view of the camera. The
//! recognizer must stay silent then, whatever the tracker makes of it. So at each distance
//! the bench also renders a figurine held still in a child's hand (`synth rest`'s hand:
//! tremor, sway and idle fidgets, under a Lighthouse-grade truth) for N seconds, tracks the
//! video as it tracks the gestures, and counts the actions the shipped library reads from
//! the true log and from the tracked one:
//!
//! | figure | what it says |
//! |---|---|
//! | actions per hour, tracked (truth) | false alarms a webcam player sees at rest; the truth's count shows how many the hand itself causes |
//! | orientation error, median / p90 | how far the reported pose sits from the truth at rest (a lone tag's mirror pose sits several degrees off) |
//! | frame-to-frame turn, median / p90 | the jitter the recognizer's noise floor must learn (the truth's own beside it) |

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;

use super::detect::Family;
use super::eval::{
    compare, place, quantile, quat, render_video, scene, track_video, truth_log, FrameError,
    FrameTruth, Setup, Tracking,
};
use super::trial::{kept_truths, knobs, write_truths, Reader};
use crate::poselog::PoseSample;
use crate::synth::rest::{rest_log, RestKind, RestSpec, TRACKER_LEVELS};
use crate::synth::Range;

/// Tracker rate of the true rest log, Hz (the renderer blurs between its samples).
pub const TRUTH_RATE_HZ: f64 = 240.0;

/// The figurine held still at one distance, tracked.
#[derive(Debug, Clone)]
pub struct StillRun {
    /// Distance from the camera, metres.
    pub distance: f64,
    /// Length of the rest, seconds.
    pub seconds: f64,
    /// Every frame compared.
    pub frames: Vec<FrameError>,
    /// Actions the recognizer read from the truth at the camera's frame times.
    pub truth_actions: Vec<String>,
    /// Actions it read from the tracked log.
    pub tracked_actions: Vec<String>,
    /// The tracked log's orientation turn between consecutive samples, degrees.
    pub tracked_turns_deg: Vec<f64>,
    /// The truth's turn between the same frames, degrees.
    pub truth_turns_deg: Vec<f64>,
}

/// The turn between consecutive samples, degrees.
fn turns_deg(samples: &[PoseSample]) -> Vec<f64> {
    samples
        .windows(2)
        .map(|w| quat(&w[0]).angle_between(quat(&w[1])).to_degrees())
        .collect()
}

/// Renders `seconds` of a figurine held still in a hand at `setup.distance`, tracks it and
/// reads it; files go in `dir` (a kept video is tracked again when `reuse`).
pub fn run_still(
    setup: &Setup,
    seconds: f64,
    seed: u64,
    dir: &Path,
    how: Tracking,
    reuse: bool,
) -> Result<StillRun> {
    let spec = RestSpec {
        seconds,
        kind: Some(RestKind::Hand),
        tracker: Some(TRACKER_LEVELS[0]),
        rate_hz: Some(Range::fixed(TRUTH_RATE_HZ)),
        knobs: knobs(),
    };
    if let Err(e) = spec.validate() {
        anyhow::bail!("--rest-seconds: {e}");
    }
    let placed = place(&rest_log(seed, &spec).log, setup.distance, setup.camera());
    let sc = scene(setup, Family::Tag36h11, 0)?;
    let video = dir.join(format!("still-{seed}.mp4"));
    let truths: Vec<FrameTruth> = match kept_truths(reuse, &video, setup, &sc) {
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
    let truth = truth_log(&truths);
    // The truth's turn over the frames the tracker kept, so both jitters span the same gaps.
    let kept: Vec<PoseSample> = frames
        .iter()
        .filter(|f| f.tracked.is_some())
        .map(|f| f.truth.pose)
        .collect();
    if dir.join("keep").exists() {
        truth.write_path(&video.with_extension("truth.csv"))?;
        run.log.write_path(&video.with_extension("tracked.csv"))?;
    }
    let reader = Reader::shipped()?;
    Ok(StillRun {
        distance: setup.distance,
        seconds,
        truth_actions: reader.actions(&truth)?,
        tracked_actions: reader.actions(&run.log)?,
        tracked_turns_deg: turns_deg(&run.log.samples),
        truth_turns_deg: turns_deg(&kept),
        frames,
    })
}

/// The section of the bench's report on the figurine held still.
pub fn still_report(runs: &[StillRun]) -> String {
    let mut out = String::new();
    if runs.is_empty() {
        return out;
    }
    let _ = writeln!(
        out,
        "\nheld still in a hand (tremor, sway, idle fidgets), the shipped library:\n\
         | distance | seconds | lost | actions from the tracked log (per hour) | from the truth | \
         orientation error median / p90, ° | frame-to-frame turn median / p90, ° (truth) |\n\
         |---|---|---|---|---|---|---|"
    );
    for r in runs {
        let per_hour = |n: usize| n as f64 * 3600.0 / r.seconds.max(1e-9);
        let lost = r.frames.iter().filter(|f| f.error.is_none()).count();
        let mut ori: Vec<f64> = r
            .frames
            .iter()
            .filter_map(|f| f.error.map(|e| e.1))
            .collect();
        let mut turn = r.tracked_turns_deg.clone();
        let mut truth_turn = r.truth_turns_deg.clone();
        let _ = writeln!(
            out,
            "| {:.2} m | {:.0} | {:.1} % | {} ({:.0}) | {} ({:.0}) | {:.2} / {:.2} | {:.2} / {:.2} ({:.2} / {:.2}) |",
            r.distance,
            r.seconds,
            100.0 * lost as f64 / r.frames.len().max(1) as f64,
            r.tracked_actions.len(),
            per_hour(r.tracked_actions.len()),
            r.truth_actions.len(),
            per_hour(r.truth_actions.len()),
            quantile(&mut ori, 0.5),
            quantile(&mut ori, 0.9),
            quantile(&mut turn, 0.5),
            quantile(&mut turn, 0.9),
            quantile(&mut truth_turn, 0.5),
            quantile(&mut truth_turn, 0.9),
        );
    }
    let (tracked, truth, seconds) = runs.iter().fold((0, 0, 0.0), |(a, b, s), r| {
        (
            a + r.tracked_actions.len(),
            b + r.truth_actions.len(),
            s + r.seconds,
        )
    });
    let _ = writeln!(
        out,
        "at rest, {seconds:.0} s in all: actions from the tracked logs {tracked} ({:.0} per \
         hour), from the truth {truth}",
        tracked as f64 * 3600.0 / seconds.max(1e-9)
    );
    for r in runs.iter().filter(|r| !r.tracked_actions.is_empty()) {
        let _ = writeln!(
            out,
            "  at {:.2} m: {}",
            r.distance,
            r.tracked_actions.join(" ")
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    fn still(distance: f64, tracked: &[&str]) -> StillRun {
        StillRun {
            distance,
            seconds: 60.0,
            frames: Vec::new(),
            truth_actions: Vec::new(),
            tracked_actions: tracked.iter().map(|s| s.to_string()).collect(),
            tracked_turns_deg: vec![1.0, 2.0, 3.0],
            truth_turns_deg: vec![0.1, 0.2, 0.3],
        }
    }

    #[test]
    fn the_report_counts_actions_per_hour_over_every_distance() {
        let text = still_report(&[still(0.5, &[]), still(1.0, &["bow", "bow", "turn"])]);
        assert!(
            text.contains("| 1.00 m | 60 | 0.0 % | 3 (180) | 0 (0) |"),
            "{text}"
        );
        assert!(
            text.contains(
                "at rest, 120 s in all: actions from the tracked logs 3 (90 per hour), from the truth 0"
            ),
            "{text}"
        );
        assert!(text.contains("  at 1.00 m: bow bow turn"), "{text}");
        assert!(!text.contains("  at 0.50 m"), "{text}");
        assert_eq!(still_report(&[]), "");
    }

    #[test]
    fn a_turn_is_measured_between_consecutive_samples() {
        let s = |t: f64, deg: f64| {
            let q = DQuat::from_rotation_x(deg.to_radians());
            PoseSample {
                t,
                pos: [0.0; 3],
                quat: [q.w, q.x, q.y, q.z],
            }
        };
        let turns = turns_deg(&[s(0.0, 0.0), s(0.1, 2.0), s(0.2, -1.0)]);
        assert_eq!(turns.len(), 2);
        assert!(
            (turns[0] - 2.0).abs() < 1e-9 && (turns[1] - 3.0).abs() < 1e-9,
            "{turns:?}"
        );
    }
}
