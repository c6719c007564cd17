//! What moves while a match waits at a pause is still read once the match is committed.
//!
//! A pending match may be held through a pause (its cyclic action could go on, or a longer
//! action could still take it over). Strokes that came meanwhile without changing it used to
//! be consumed by the matcher and forgotten when the pause committed it, so the next action
//! was never matched. Generated with the project's own generator and a library learnt from
//! it, as `figurine eval` does (train seed 1, test seed 1000).

use figurine_host::recognize::eval::learn_synth_library;
use figurine_host::recognize::scoring::run_doodle;
use figurine_host::recognize::simulate::load_effort;
use figurine_host::synth::{self, Knobs};

#[test]
fn an_action_played_while_the_last_one_was_held_is_recognised() {
    let knobs = Knobs::default();
    let mut lib = learn_synth_library(1, 3, &knobs).unwrap();
    let names = lib.names();
    let blob = lib.blob().unwrap();
    let effort = load_effort(None).unwrap();
    // `figurine eval`'s sequence 6: a turn played 0.5 s after a run, while the run's match
    // was held for its next stride. Before, the turn was never matched.
    let seed = synth::sequence::item_seed(1000 ^ 0x5e9_5e9, 6);
    let d = synth::sequence(seed, &knobs, 6, None);
    let evs = run_doodle(&d, &names, &blob, effort).unwrap();
    let found = |action: &str| {
        let l = d.labels.iter().find(|l| l.action == action).unwrap();
        evs.iter()
            .any(|e| e.action == action && e.start < l.end && e.end > l.start)
    };
    assert!(found("run"), "{:?}\n{evs:?}", d.labels);
    assert!(found("turn"), "{:?}\n{evs:?}", d.labels);
}
