//! A recorded log that ends is read as if the figurine had rested on: what `simulate` reports
//! for a log is what the device reports for the same motion followed by stillness
//! (`figurine_recognizer::Recognizer::flush`).
//!
//! At a pause the recognizer commits its pending match as the whole phrase around it, cuts
//! two performances read as one, and reads on from what moved after. The stream's end used to
//! commit the pending match as it stood and nothing more, so a gesture whose log ended before
//! a pause committed it was reported cut short, as another action, or not at all.

use std::process::Command;

use figurine_host::events::read_events;
use figurine_host::link::blobs;
use figurine_host::poselog::PoseLog;
use figurine_host::recognize::simulate::{load_effort, simulate_log};
use figurine_host::synth::{self, Action, Doodle, Knobs, Range};

mod scratch;
use scratch::Scratch;

/// `d`'s log cut 0.1 s after the end of its last label.
fn ending_soon(d: &Doodle) -> PoseLog {
    let end = d.labels.iter().map(|l| l.end).fold(0.0, f64::max) + 0.1;
    PoseLog {
        samples: d
            .log
            .samples
            .iter()
            .filter(|s| s.t <= end)
            .copied()
            .collect(),
    }
}

/// The actions the shipped library reads in a log, in order.
fn shipped_reader() -> impl Fn(&PoseLog) -> Vec<String> {
    let b = blobs::load(None, None).expect("shipped library and effort model");
    let effort = load_effort(None).expect("shipped effort model");
    move |log| {
        let sim = simulate_log(log, &b.names, &b.library, Some(effort)).unwrap();
        sim.records.into_iter().map(|r| r.action).collect()
    }
}

/// The generator's every knob at its default but the tracker's noise, ×3.
fn noise_x3() -> Knobs {
    Knobs {
        noise: Range::new(3.0, 3.0),
        ..Knobs::default()
    }
}

/// Every action of the generator at noise ×3, 60 performances each, the log ending 0.1 s after
/// the motion and the same with 3 s of stillness after that, read by the shipped library: the
/// actions reported differ for 13 of 720 logs (21 when the end committed the pending match as
/// it stood). Most of those left are kicks that no pattern matched and none could go on from:
/// the end gives such a phrase its closed reading (`nearest`), the resting figurine only a
/// phrase some pattern could go on from (`simulate --why`: "no action read it"). Both ways of
/// making them agree were measured and lose a family (`docs/recognizer.md`, "Tried and not
/// taken", 2026-12-07 fourth session).
#[test]
fn a_logs_end_reads_as_a_long_rest_would() {
    let (actions, knobs) = (shipped_reader(), noise_x3());
    let mut differ = Vec::new();
    for (i, &action) in Action::ALL.iter().enumerate() {
        for d in synth::examples(9_100 + i as u64, &knobs, action, 60, None) {
            let log = ending_soon(&d);
            let (at_end, resting) = (actions(&log), actions(&log.rested(3.0)));
            if at_end != resting {
                differ.push((action.name(), at_end, resting));
            }
        }
    }
    println!("differ: {} {differ:?}", differ.len());
    assert!(differ.len() <= 16, "{} differ: {differ:?}", differ.len());
}

/// `figurine simulate --rest SECONDS` reads a log as the figurine left resting that long after
/// it: on a kick whose log ends 0.1 s after it and which the end reads otherwise than a rest
/// (the test above), the command with `--rest 3` reports what the resting figurine does, and
/// without it what the end does. A rest outside 0–3600 s, or not a number, is refused.
#[test]
fn simulate_rest_reads_a_log_as_a_resting_figurine() {
    let (actions, knobs) = (shipped_reader(), noise_x3());
    let (log, at_end, resting) = synth::examples(9_105, &knobs, Action::Kick, 60, None)
        .into_iter()
        .map(|d| {
            let log = ending_soon(&d);
            let (a, r) = (actions(&log), actions(&log.rested(3.0)));
            (log, a, r)
        })
        .find(|(_, a, r)| a != r)
        .expect("a kick the log's end reads otherwise than a rest");
    let dir = Scratch::new("log-end", "rest");
    let path = dir.join("kick.csv");
    log.write_path(&path).unwrap();
    let path = path.to_str().unwrap();
    let cli = |extra: &[&str]| -> (bool, Vec<String>, String) {
        let out = Command::new(env!("CARGO_BIN_EXE_figurine"))
            .arg("simulate")
            .args(extra)
            .args(["--jsonl", path])
            .output()
            .unwrap();
        let events = read_events(&out.stdout[..], std::path::Path::new("stdout")).unwrap();
        (
            out.status.success(),
            events.into_iter().map(|e| e.action).collect(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    assert_eq!(cli(&[]), (true, at_end, String::new()));
    assert_eq!(cli(&["--rest", "3"]), (true, resting, String::new()));
    for bad in ["-1", "3601", "NaN"] {
        let (ok, _, err) = cli(&[&format!("--rest={bad}")]);
        assert!(!ok && err.contains("--rest"), "--rest={bad}: {err}");
    }
}
