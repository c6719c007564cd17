//! `figurine eval repeat`: one action played several times back to back.
//!
//! A child jumps the figurine three times, or punches twice, with no more than a breath between:
//! that is three jumps, two punches. A walk played on is a longer walk, not several (nor is a
//! run, steps to the side, a wave or a turn resumed: [`Action::continues`]). Each doodle plays one action 2–4
//! times in a row with the same effort and a short pause between ([`DEFAULT_PAUSE_S`]); its
//! truth is one label per repetition, or one label over the whole bout for an action that
//! continues. Events are matched to labels as `figurine eval` matches sequences (same action,
//! overlapping; [`pair_events`]). Printed per action: the share of doodles whose events are
//! exactly the truth (as many events of the action as labels, and nothing else), and how many
//! events of the action came per doodle against how many were due; then precision, recall and
//! F1 over all doodles.

use anyhow::{bail, Result};
use clap::Args;
use rayon::prelude::*;

use super::eval::{learn_synth_library, rested, RESTED_S};
use super::scoring::{pair_events, prf, run_doodle, Ev};
use super::simulate::load_effort;
use crate::synth::{self, Action, Knobs, Label, Range};

/// Default pause between repetitions, seconds: a breath, or none to speak of.
pub const DEFAULT_PAUSE_S: Range = Range { lo: 0.05, hi: 0.4 };
/// Repetitions per doodle cycle through 2, 3 and 4.
pub const REPETITIONS: [usize; 3] = [2, 3, 4];

/// Arguments of `figurine eval repeat`.
#[derive(Args, Debug, Clone)]
pub struct RepeatArgs {
    /// Doodles per action and seed pair.
    #[arg(long, default_value_t = 12)]
    pub per_action: usize,
    /// Seed pairs: pair i learns its library at --train-seed + i (3 examples per action) and
    /// plays its doodles at --seed + 1000·i.
    #[arg(long, default_value_t = 3)]
    pub pairs: usize,
    /// Test seed of the first pair.
    #[arg(long, default_value_t = 7000)]
    pub seed: u64,
    /// Train seed of the first pair.
    #[arg(long, default_value_t = 1)]
    pub train_seed: u64,
    /// Pause between repetitions, seconds: `V` or `LO..HI`.
    #[arg(long, default_value_t = DEFAULT_PAUSE_S)]
    pub pause: Range,
    /// Print every doodle whose events are not exactly its truth.
    #[arg(long)]
    pub verbose: bool,
}

/// One doodle's outcome.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
struct Outcome {
    /// Labels (events due).
    due: usize,
    /// Events of the played action.
    of_action: usize,
    /// Events of any other action.
    other: usize,
    /// Labels matched by an event.
    matched: usize,
}

impl Outcome {
    /// Adds another doodle's counts.
    fn add(&mut self, o: &Outcome) {
        self.due += o.due;
        self.of_action += o.of_action;
        self.other += o.other;
        self.matched += o.matched;
    }

    fn exact(&self) -> bool {
        self.of_action == self.due && self.other == 0 && self.matched == self.due
    }
}

/// The truth of `n` repetitions of `action`: one label each, or, for an action that
/// continues, one label over them all.
fn truth(action: Action, labels: &[Label]) -> Vec<Label> {
    match (action.continues(), labels.first(), labels.last()) {
        (true, Some(first), Some(last)) => vec![Label {
            end: last.end,
            ..first.clone()
        }],
        _ => labels.to_vec(),
    }
}

fn outcome(action: Action, truth: &[Label], evs: &[Ev]) -> Outcome {
    let of_action = evs.iter().filter(|e| e.action == action.name()).count();
    Outcome {
        due: truth.len(),
        of_action,
        other: evs.len() - of_action,
        matched: pair_events(truth, evs).iter().flatten().count(),
    }
}

/// The share of exact doodles (all, one-shot actions, continuing ones) and the events'
/// precision, recall and F1 over `outcomes`, each with the action it played.
fn scores<'a>(outcomes: impl Iterator<Item = (Action, &'a Outcome)>) -> [f64; 6] {
    let (mut all, mut by_kind) = (Outcome::default(), [(0usize, 0usize); 2]);
    for (action, o) in outcomes {
        let k = &mut by_kind[usize::from(action.continues())];
        k.0 += usize::from(o.exact());
        k.1 += 1;
        all.add(o);
    }
    let share = |a: usize, b: usize| a as f64 / b.max(1) as f64;
    let (p, r, f1) = prf(all.matched, all.of_action + all.other, all.due);
    let [one, on] = by_kind;
    [
        share(one.0 + on.0, one.1 + on.1),
        share(one.0, one.1),
        share(on.0, on.1),
        p,
        r,
        f1,
    ]
}

/// Outcomes of every doodle of one seed pair, by action (in [`Action::ALL`] order): as the
/// log ends, and followed by [`RESTED_S`] of stillness (a figurine left resting).
fn run_pair(args: &RepeatArgs, pair: usize) -> Result<Vec<Vec<(Outcome, Outcome)>>> {
    let knobs = Knobs {
        pause_s: args.pause,
        ..Knobs::default()
    };
    let mut lib = learn_synth_library(args.train_seed + pair as u64, 3, &Knobs::default())?;
    let names = lib.names();
    let blob = lib.blob()?;
    let effort = load_effort(None)?;
    let test_seed = args.seed + 1000 * pair as u64;
    Action::ALL
        .iter()
        .enumerate()
        .map(|(ai, &action)| {
            (0..args.per_action)
                .map(|k| {
                    let seed = synth::sequence::item_seed(test_seed, (ai * 10_000 + k) as u64);
                    let n = REPETITIONS[k % REPETITIONS.len()];
                    let e = synth::sequence::random_state_for(seed);
                    let d = synth::sequence::render(seed, &knobs, &vec![(action, e); n]);
                    let t = truth(action, &d.labels);
                    let evs = run_doodle(&d, &names, &blob, effort)?;
                    let o = outcome(action, &t, &evs);
                    let at_rest =
                        outcome(action, &t, &run_doodle(&rested(&d), &names, &blob, effort)?);
                    if args.verbose && !o.exact() {
                        let got: Vec<String> = evs
                            .iter()
                            .map(|e| format!("{} {:.2}-{:.2}", e.action, e.start, e.end))
                            .collect();
                        let due: Vec<String> = t
                            .iter()
                            .map(|l| format!("{:.2}-{:.2}", l.start, l.end))
                            .collect();
                        let played = vec![action.name(); n].join(",");
                        eprintln!(
                            "{action} ×{n}: due [{}], got [{}]\n    figurine synth sequence \
                             --seed {seed} --actions {played} --effort {} --pause {} \
                             --out R.csv --labels R.json (library: train seed {})",
                            due.join(", "),
                            got.join(", "),
                            e.name(),
                            args.pause,
                            args.train_seed + pair as u64
                        );
                    }
                    Ok((o, at_rest))
                })
                .collect()
        })
        .collect()
}

/// `figurine eval repeat`.
pub fn run(args: &RepeatArgs) -> Result<()> {
    if args.pairs == 0 || args.per_action == 0 {
        bail!("--pairs and --per-action must be at least 1");
    }
    eprintln!(
        "learning {} libraries and playing {} doodles per action each…",
        args.pairs, args.per_action
    );
    let pairs: Vec<Vec<Vec<(Outcome, Outcome)>>> = (0..args.pairs)
        .into_par_iter()
        .map(|p| run_pair(args, p))
        .collect::<Result<_>>()?;
    println!(
        "Repetitions: each doodle plays one action {:?} times back to back, pauses {}–{} s \
         ({} doodles per action over {} seed pairs).",
        REPETITIONS,
        args.pause.lo,
        args.pause.hi,
        args.per_action * args.pairs,
        args.pairs
    );
    println!(
        "{:<10} {:<10} {:>7} {:>16} {:>8}",
        "action", "truth", "exact", "events/doodle", "others"
    );
    for (ai, &action) in Action::ALL.iter().enumerate() {
        let os: Vec<&Outcome> = pairs.iter().flat_map(|p| &p[ai]).map(|o| &o.0).collect();
        let n = os.len();
        let ex = os.iter().filter(|o| o.exact()).count();
        let mut sum = Outcome::default();
        os.iter().for_each(|o| sum.add(o));
        println!(
            "{:<10} {:<10} {:>6.0}% {:>7.2} of {:<6.2} {:>8}",
            action.name(),
            if action.continues() {
                "one bout"
            } else {
                "each one"
            },
            100.0 * ex as f64 / n.max(1) as f64,
            sum.of_action as f64 / n.max(1) as f64,
            sum.due as f64 / n.max(1) as f64,
            sum.other
        );
    }
    let played = |end: bool| {
        let pairs = &pairs;
        Action::ALL
            .iter()
            .enumerate()
            .flat_map(move |(ai, &action)| {
                pairs
                    .iter()
                    .flat_map(move |p| &p[ai])
                    .map(move |o| (action, if end { &o.0 } else { &o.1 }))
            })
    };
    let [ex, one, on, p, r, f1] = scores(played(true)).map(|v| 100.0 * v);
    println!("exact: {ex:.1}% of doodles (one-shot actions {one:.1}%, continuing ones {on:.1}%)");
    println!("repeat: precision {p:.1}%  recall {r:.1}%  F1 {f1:.1}%");
    let [ex, one, on, p, r, f1] = scores(played(false)).map(|v| 100.0 * v);
    println!(
        "as a figurine left resting {RESTED_S} s after each doodle: exact {ex:.1}% (one-shot \
         {one:.1}%, continuing {on:.1}%), precision {p:.1}%  recall {r:.1}%  F1 {f1:.1}%"
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recognize::scoring::tests::{ev, label};

    #[test]
    fn a_bout_of_a_continuing_action_is_one_label_and_one_shot_repeats_are_each_one() {
        let played = [label("walk", 1.0, 2.0), label("walk", 2.2, 3.0)];
        let t = truth(Action::Walk, &played);
        assert_eq!(t.len(), 1);
        assert_eq!((t[0].start, t[0].end), (1.0, 3.0));
        let jumps = [label("jump", 1.0, 2.0), label("jump", 2.2, 3.0)];
        assert_eq!(truth(Action::Jump, &jumps).len(), 2);
    }

    #[test]
    fn merged_split_and_stray_events_are_not_exact() {
        let jumps = [label("jump", 1.0, 2.0), label("jump", 2.2, 3.0)];
        let right = [ev("jump", 1.1, 2.0), ev("jump", 2.3, 3.0)];
        assert!(outcome(Action::Jump, &jumps, &right).exact());
        // Two jumps reported as one.
        let merged = outcome(Action::Jump, &jumps, &[ev("jump", 1.0, 3.0)]);
        assert_eq!((merged.of_action, merged.matched), (1, 1));
        assert!(!merged.exact());
        // A stray other action.
        let stray = [
            ev("jump", 1.1, 2.0),
            ev("jump", 2.3, 3.0),
            ev("crouch", 3.0, 3.2),
        ];
        assert!(!outcome(Action::Jump, &jumps, &stray).exact());
        // A walk split in two.
        let walk = [label("walk", 1.0, 3.0)];
        let split = outcome(
            Action::Walk,
            &walk,
            &[ev("walk", 1.0, 2.0), ev("walk", 2.2, 3.0)],
        );
        assert_eq!((split.due, split.of_action, split.matched), (1, 2, 1));
        assert!(!split.exact());
    }

    #[test]
    fn scores_split_exact_doodles_by_kind_and_count_events_over_all() {
        let o = |due, of_action, other, matched| Outcome {
            due,
            of_action,
            other,
            matched,
        };
        let (exact, merged, walk) = (o(2, 2, 0, 2), o(2, 1, 1, 1), o(1, 1, 0, 1));
        let played = [
            (Action::Jump, &exact),
            (Action::Jump, &merged),
            (Action::Walk, &walk),
        ];
        let [all, one, on, p, r, f1] = scores(played.into_iter());
        assert_eq!((all, one, on), (2.0 / 3.0, 0.5, 1.0));
        assert_eq!((p, r), (4.0 / 5.0, 4.0 / 5.0));
        assert!((f1 - 0.8).abs() < 1e-12);
        assert_eq!(scores(std::iter::empty()), [0.0; 6]);
    }
}
