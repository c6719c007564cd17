//! A figurine at rest stays silent under every tracker, and a gesture after a long noisy rest
//! is still read, as quickly: the recognizer's learnt noise floor, end to end through the
//! wire quantisation and the shipped library.

use figurine_host::link::blobs::{self, Blobs};
use figurine_host::recognize::simulate::simulate_log;
use figurine_host::synth::knobs::{Knobs, Range};
use figurine_host::synth::{
    gesture, rest_log, Action, Effort, RestKind, RestSpec, TimeClass, WeightClass, TRACKER_LEVELS,
};
use figurine_recognizer::EffortModel;

fn shipped() -> (Blobs, EffortModel) {
    let b = blobs::load(None, None).expect("shipped library and effort model");
    let e = EffortModel::from_bytes(&b.effort).expect("effort blob");
    (b, e)
}

/// A minute of every kind of rest under every tracker level: a figurine that does not move
/// gives no event, and one held in a hand gives none but where the hand fidgeted (a real
/// motion of a few millimetres and degrees, which only a per-action bound on how far a
/// performance may stray can tell from a gesture).
#[test]
fn rest_under_every_tracker_gives_no_event_but_at_a_fidget() {
    let (b, effort) = shipped();
    let mut fidget_events = 0;
    for (i, level) in TRACKER_LEVELS.iter().enumerate() {
        for kind in [RestKind::Table, RestKind::Mounted, RestKind::Hand] {
            let seed = 100 + i as u64;
            let rest = rest_log(
                seed,
                &RestSpec {
                    seconds: 60.0,
                    kind: Some(kind),
                    tracker: Some(*level),
                    ..RestSpec::default()
                },
            );
            let sim = simulate_log(&rest.log, &b.names, &b.library, Some(effort)).unwrap();
            for r in &sim.records {
                let at_fidget = rest
                    .info
                    .fidgets
                    .iter()
                    .any(|f| r.start < f.end + 0.3 && r.end > f.start - 0.3);
                assert!(
                    kind == RestKind::Hand && at_fidget,
                    "{} at {:.2}-{:.2} s on {kind:?} rest under {} (seed {seed}), no fidget there",
                    r.action,
                    r.start,
                    r.end,
                    level.name
                );
                fidget_events += 1;
            }
        }
    }
    eprintln!("events at fidgets: {fidget_events}");
}

/// The decision latency (s) of the first event, and its action.
fn first_event(log: &figurine_host::poselog::PoseLog, b: &Blobs, e: EffortModel) -> (String, f64) {
    let sim = simulate_log(log, &b.names, &b.library, Some(e)).unwrap();
    let ev = sim.events.first().expect("an event");
    let rec = sim.records.first().expect("a record");
    (
        rec.action.clone(),
        (ev.decided_us.saturating_sub(ev.end_us)) as f64 * 1e-6,
    )
}

#[test]
fn a_gesture_after_a_long_noisy_rest_is_read_as_quickly() {
    let (b, effort) = shipped();
    let strong = Effort::new(TimeClass::Sudden, WeightClass::Strong);
    for (seed, action) in [(1u64, Action::Jump), (2, Action::Punch), (3, Action::Walk)] {
        let knobs = |lead: f64| Knobs {
            noise: Range::fixed(3.0),
            lead_s: Range::fixed(lead),
            ..Knobs::default()
        };
        let short = gesture(seed, &knobs(1.0), action, strong);
        let long = gesture(seed, &knobs(60.0), action, strong);
        let (a, quick) = first_event(&short.log, &b, effort);
        let (c, late) = first_event(&long.log, &b, effort);
        assert_eq!(a, action.name(), "after 1 s of rest");
        assert_eq!(c, action.name(), "after a minute of rest");
        assert!(
            late <= quick + 0.05,
            "{action:?}: decided {late:.3} s after its end after a minute of rest, {quick:.3} s \
             after a second"
        );
    }
}
