//! A one-shot action played again after a breath is a second event, not more of the first
//! (`figurine_recognizer`'s `Recognizer::first_of_two`).
//!
//! While a punch waits out a longer action that may begin with it, its `b+` column reads the
//! next punch's wind-up into its retraction, and its edits then take in the whole next punch:
//! one match over two punches. Where the runs on either side of a stillness inside one match
//! are each a whole match of its action and cost less apart, the match is two performances.

use figurine_host::link::blobs;
use figurine_host::recognize::repeat_bench::DEFAULT_PAUSE_S;
use figurine_host::recognize::simulate::{load_effort, simulate_log};
use figurine_host::synth::sequence::{item_seed, random_state_for, render};
use figurine_host::synth::{Action, Knobs};

/// Punches and crouches, each played 2, 3 or 4 times back to back with breaths of 0.05–0.4 s
/// (`figurine eval repeat`'s), 40 doodles of each read by the shipped library: how many
/// doodles gave exactly one event of the action per performance and nothing else. Read as one
/// match across a stillness whatever it cost, 25 did; cut where apart costs less, 32.
#[test]
fn a_one_shot_action_played_again_is_another_event() {
    let b = blobs::load(None, None).expect("shipped library and effort model");
    let effort = load_effort(None).expect("shipped effort model");
    let knobs = Knobs {
        pause_s: DEFAULT_PAUSE_S,
        ..Knobs::default()
    };
    let mut exact = 0;
    let mut wrong = Vec::new();
    for (i, action) in [Action::Punch, Action::Crouch].into_iter().enumerate() {
        for k in 0..40u64 {
            let seed = item_seed(7_000 + i as u64, k);
            let n = 2 + (k % 3) as usize;
            let d = render(seed, &knobs, &vec![(action, random_state_for(seed)); n]);
            let sim = simulate_log(&d.log, &b.names, &b.library, Some(effort)).unwrap();
            let got: Vec<&str> = sim.records.iter().map(|r| r.action.as_str()).collect();
            if got.len() == n && got.iter().all(|&a| a == action.name()) {
                exact += 1;
            } else {
                wrong.push((action.name(), seed, n, got.join(" ")));
            }
        }
    }
    println!("exact: {exact} of 80; wrong: {wrong:?}");
    assert!(exact >= 30, "{exact} of 80 exact; wrong: {wrong:?}");
}
