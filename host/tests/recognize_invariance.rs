//! The recognizer's invariances, on synthetic performances of every action: moving the
//! figurine elsewhere in the room, turning it to face another way, doodling at half or double
//! size, and sampling at 30–240 Hz with jittery clocks give the same recognised actions.
//! Each variant changes one nuisance knob of the generator and keeps the performance itself
//! (the same plan seed), so any difference is the recognizer's.

use figurine_host::recognize::feed::{gesture_runs, log_runs, log_samples};
use figurine_host::recognize::simulate::{load_effort, load_library, simulate_log};
use figurine_host::synth::{self, Action, Effort, Knobs, Range};
use figurine_recognizer::token::STILL;

fn actions(knobs: &Knobs, action: Action, seed: u64) -> (Vec<String>, Vec<u16>) {
    let d = synth::gesture(seed, knobs, action, Effort::NEUTRAL);
    let (lib, blob) = load_library(None).unwrap();
    let sim = simulate_log(
        &d.log,
        &lib.names(),
        &blob,
        Some(load_effort(None).unwrap()),
    )
    .unwrap();
    let (samples, _) = log_samples(&d.log);
    let runs = log_runs(&samples);
    let tokens = gesture_runs(&runs)
        .iter()
        .map(|r| r.token)
        .filter(|&t| t != STILL)
        .collect();
    // The actions recognised, in order; a cyclic action cut into consecutive events is one.
    let mut names: Vec<String> = sim.records.into_iter().map(|r| r.action).collect();
    names.dedup();
    (names, tokens)
}

/// Runs every action under `base` and `variant`; returns how many gave the same actions.
fn same_actions(variant: impl Fn(&mut Knobs), label: &str) -> usize {
    let base = Knobs::canonical();
    let mut other = Knobs::canonical();
    variant(&mut other);
    let mut same = 0;
    for (i, &a) in Action::ALL.iter().enumerate() {
        let seed = 40 + i as u64;
        let (x, tx) = actions(&base, a, seed);
        let (y, ty) = actions(&other, a, seed);
        if x == y {
            same += 1;
        } else {
            eprintln!(
                "{label}: {} gave {x:?} / {y:?}\n  tokens {tx:?}\n  vs     {ty:?}",
                a.name()
            );
        }
    }
    same
}

#[test]
fn position_in_the_room_does_not_matter() {
    let n = same_actions(|k| k.room_m = Range::fixed(3.0), "offset");
    assert_eq!(n, Action::ALL.len());
}

#[test]
fn heading_does_not_matter() {
    for h in [90.0, -137.0] {
        let n = same_actions(|k| k.heading_deg = Range::fixed(h), "heading");
        assert_eq!(n, Action::ALL.len(), "heading {h}°");
    }
}

#[test]
fn size_does_not_matter() {
    for s in [0.5, 2.0] {
        let n = same_actions(|k| k.scale = Range::fixed(s), "scale");
        // A bow or wave pivots about the figurine's feet: doubling the doodle doubles that
        // lever arm, and past `token::ARM_M` (10 cm) the swing becomes real translation. One
        // such action may change; everything else must not.
        assert!(
            n + 1 >= Action::ALL.len(),
            "scale ×{s}: {n} of 12 actions unchanged"
        );
    }
}

#[test]
fn sample_rate_and_jitter_do_not_matter() {
    for r in [30.0, 240.0] {
        let n = same_actions(
            |k| {
                k.rate_hz = Range::fixed(r);
                k.jitter = Range::fixed(0.2);
            },
            "rate",
        );
        assert_eq!(n, Action::ALL.len(), "{r} Hz");
    }
}
