//! Handling that plays no action — the toy lifted to be looked at and set back down, or carried
//! elsewhere — is no action: end to end through the wire quantisation and the shipped library.

use figurine_host::link::blobs;
use figurine_host::recognize::simulate::simulate_log;
use figurine_host::synth::sequence::item_seed;
use figurine_host::synth::{handled, sequence, Handling, Knobs};
use figurine_recognizer::EffortModel;

/// Lifts at the generator's every scale, tempo, rate and noise: up, a look, down. Each strays
/// from every action's pattern and moves like none of their examples, so none may be read as
/// the action its tokens happen to come nearest (before, nearly all were: a throw, a walk).
#[test]
fn a_toy_lifted_and_set_down_is_no_action() {
    let b = blobs::load(None, None).expect("shipped library and effort model");
    let effort = EffortModel::from_bytes(&b.effort).expect("effort blob");
    let knobs = Knobs::default();
    let mut loud = Vec::new();
    const LIFTS: u64 = 20;
    for k in 0..LIFTS {
        let seed = item_seed(29, k);
        let d = handled(seed, &knobs, Handling::Lift);
        assert_eq!(d.labels.len(), 0);
        assert_eq!(d.handled.len(), 1);
        let sim = simulate_log(&d.log, &b.names, &b.library, Some(effort)).unwrap();
        if let Some(r) = sim.records.first() {
            loud.push(format!("seed {seed}: {}", r.action));
        }
    }
    // Some still spell a jump closely enough (`u d`, a jump straight up: 7 of these 20).
    assert!(loud.len() as u64 <= LIFTS / 2, "{loud:?}");
}

/// A sequence may hold one handling between its actions; the actions are drawn as they would
/// be without it, and the handling's span lies apart from every action's.
#[test]
fn a_sequence_holds_handling_apart_from_its_actions() {
    let with = Knobs {
        handling: 1.0,
        ..Knobs::default()
    };
    let without = Knobs {
        handling: 0.0,
        ..Knobs::default()
    };
    for seed in 0..6 {
        let a = sequence(seed, &with, 4, None);
        let b = sequence(seed, &without, 4, None);
        assert_eq!(a.handled.len(), 1);
        assert!(b.handled.is_empty());
        let names = |d: &figurine_host::synth::Doodle| -> Vec<String> {
            d.labels.iter().map(|l| l.action.clone()).collect()
        };
        assert_eq!(names(&a), names(&b));
        let h = &a.handled[0];
        assert!(h.end > h.start);
        for l in &a.labels {
            assert!(l.end <= h.start || l.start >= h.end, "{l:?} over {h:?}");
        }
    }
}
