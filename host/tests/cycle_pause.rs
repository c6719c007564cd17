//! A cyclic action's pause between cycles counts from where its strokes settled
//! (`figurine_recognizer::history::Run::rested_us`).
//!
//! Under a noisy tracker the floor stands higher, so the slow end of one stride and the slow
//! start of the next fall under it: a sidestep whose steps the generator joins with 0–60 ms
//! holds shows still runs of half a second and more between them at noise ×3. Counted from
//! the run's start, such a run outlasted the half second after which a next cycle no longer
//! continues the event, and one sidestep was reported as two.

use figurine_host::link::blobs;
use figurine_host::recognize::simulate::{load_effort, simulate_log};
use figurine_host::synth::sequence::item_seed;
use figurine_host::synth::{self, Action, Effort, Knobs, Range, TimeClass, WeightClass};

/// Sustained, light sidesteps, walks and turns at noise ×3, 60 each, read by the shipped
/// library: how many were reported as two or more events of their own action. Counted from
/// the still run's start, as before, 17 were; from where the strokes settled, 10.
#[test]
fn a_noisy_strides_slow_tail_is_no_pause() {
    let b = blobs::load(None, None).expect("shipped library and effort model");
    let effort = load_effort(None).expect("shipped effort model");
    let knobs = Knobs {
        noise: Range::new(3.0, 3.0),
        ..Knobs::default()
    };
    let mut split = Vec::new();
    let sustained = Effort::new(TimeClass::Sustained, WeightClass::Light);
    for action in [Action::Sidestep, Action::Walk, Action::Turn] {
        for k in 0..60 {
            let seed = item_seed(77, k);
            let d = synth::examples(seed, &knobs, action, 1, Some(sustained))
                .pop()
                .expect("one performance");
            let sim = simulate_log(&d.log, &b.names, &b.library, Some(effort)).unwrap();
            let own = sim
                .records
                .iter()
                .filter(|r| r.action == action.name())
                .count();
            if own >= 2 {
                split.push((action.name(), seed, own));
            }
        }
    }
    println!("split: {} {split:?}", split.len());
    assert!(split.len() <= 13, "{} split: {split:?}", split.len());
}
