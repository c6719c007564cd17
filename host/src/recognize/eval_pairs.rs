//! `figurine eval --pairs K`: the whole evaluation over K independent (train, test) seed
//! pairs, so a change in the recognizer or the learner is judged on more than one draw of
//! the generator. One evaluation is a few hundred generated gestures; which performances a
//! draw happens to contain moves its figures by several points, more than many changes do.

use std::collections::BTreeMap;

use anyhow::{bail, Result};

use super::eval::{
    evaluate, prepare, quantiles, EffortCounts, EvalArgs, Figures, RestedCounts, TalkCounts,
};

/// Test seeds of successive pairs are this far apart (the training seeds are consecutive).
pub const TEST_SEED_STEP: u64 = 1000;

/// Misreads [`Tally::misreads_line`] names, the most frequent first.
pub const MISREADS_SHOWN: usize = 8;

/// The figures of one pair, as printed: isolated, F1, Time, Weight, state (shares), median
/// latency (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairLine {
    /// Isolated-gesture accuracy.
    pub isolated: f64,
    /// Sequence F1.
    pub f1: f64,
    /// Time accuracy.
    pub time: f64,
    /// Weight accuracy.
    pub weight: f64,
    /// State accuracy.
    pub state: f64,
    /// Median decision latency, seconds.
    pub latency_s: f64,
    /// Share of handling logs (no action played) given no event.
    pub silent: f64,
}

impl PairLine {
    /// The summary of one evaluation.
    pub fn of(f: &Figures) -> PairLine {
        PairLine {
            isolated: f.isolated,
            f1: f.seq_prf.2,
            time: f.time,
            weight: f.weight,
            state: f.state,
            latency_s: quantiles(&f.latencies).0,
            silent: f.silent(),
        }
    }

    fn fields(&self) -> [f64; 7] {
        [
            100.0 * self.isolated,
            100.0 * self.f1,
            100.0 * self.time,
            100.0 * self.weight,
            100.0 * self.state,
            1000.0 * self.latency_s,
            100.0 * self.silent,
        ]
    }
}

/// The counts under the pairs' shares, summed over the pairs: what a mean of percentages
/// hides (one more gesture read moves every effort share), and which misreads make the
/// isolated share (one pair's confusions are a handful; the pairs' sum shows a pattern).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tally {
    /// Isolated gestures read as the action played.
    pub isolated_ok: usize,
    /// Isolated gestures played.
    pub isolated: usize,
    /// The effort of those read.
    pub effort: EffortCounts,
    /// Handling logs given no event.
    pub silent: usize,
    /// Handling logs.
    pub handling: usize,
    /// A toy held in a hand that talks: events, logs and seconds.
    pub talk: TalkCounts,
    /// Isolated gestures by (action played, read as or "none"), read as another.
    pub misreads: BTreeMap<(String, String), usize>,
    /// The same isolated gestures, handling logs and sequences, each followed by stillness.
    pub rested: RestedCounts,
}

impl Tally {
    /// Adds one evaluation's counts.
    pub fn add(&mut self, f: &Figures) {
        for (_, ok, n) in &f.per_action {
            self.isolated_ok += ok;
            self.isolated += n;
        }
        self.effort.add(f.effort_counts);
        for (_, _, loud, n) in &f.handling {
            self.silent += n - loud.min(n);
            self.handling += n;
        }
        self.talk.add(&f.talk);
        self.rested.add(f.rested);
        for (played, read, n) in &f.confusions {
            *self
                .misreads
                .entry((played.clone(), read.clone()))
                .or_default() += n;
        }
    }

    /// One line naming the [`MISREADS_SHOWN`] most frequent misreads over the pairs (ties by
    /// name), or `None` when every isolated gesture was read as played.
    pub fn misreads_line(&self) -> Option<String> {
        let mut all: Vec<(&(String, String), &usize)> = self.misreads.iter().collect();
        all.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
        let shown: Vec<String> = all
            .iter()
            .take(MISREADS_SHOWN)
            .map(|((played, read), n)| format!("{played} -> {read} {n}"))
            .collect();
        (!shown.is_empty()).then(|| {
            format!(
                "most frequent misreads over the pairs: {} (of {} misread)",
                shown.join(", "),
                self.misreads.values().sum::<usize>()
            )
        })
    }

    /// One line: `counts over the pairs: …`.
    pub fn line(&self) -> String {
        format!(
            "counts over the pairs: isolated {} of {} read as played, of them Time right {}, \
             Weight {}, both {}; handling silent on {} of {} logs; held in a hand that \
             talks, {}; {}",
            self.isolated_ok,
            self.isolated,
            self.effort.time,
            self.effort.weight,
            self.effort.state,
            self.silent,
            self.handling,
            self.talk.words(),
            self.rested.words(self.isolated, self.handling)
        )
    }
}

/// Per field: mean, smallest, largest over `lines` (percent, latency in ms).
pub fn summarise(lines: &[PairLine]) -> [(f64, f64, f64); 7] {
    let mut out = [(0.0, f64::INFINITY, f64::NEG_INFINITY); 7];
    for l in lines {
        for (o, v) in out.iter_mut().zip(l.fields()) {
            o.0 += v / lines.len() as f64;
            o.1 = o.1.min(v);
            o.2 = o.2.max(v);
        }
    }
    out
}

fn header() {
    println!(
        "{:>5} {:>6} {:>6}  {:>8} {:>6} {:>6} {:>6} {:>6} {:>8} {:>6}",
        "pair", "train", "test", "isolated", "F1", "Time", "Weight", "state", "latency", "silent"
    );
}

/// `figurine eval --pairs K`.
pub fn run(args: &EvalArgs) -> Result<()> {
    if args.library.is_some()
        || args.effort.is_some()
        || args.save_library.is_some()
        || args.save_effort.is_some()
    {
        bail!(
            "--pairs learns and trains anew for every pair; it does not take --library, \
             --effort, --save-library or --save-effort"
        );
    }
    let knobs = args.knobs();
    let mut lines = Vec::new();
    let mut rows = Vec::new();
    let mut tally = Tally::default();
    for i in 0..args.pairs as u64 {
        let pair = EvalArgs {
            seed: args.seed.wrapping_add(TEST_SEED_STEP.wrapping_mul(i)),
            train_seed: args.train_seed.wrapping_add(i),
            pairs: 1,
            library: None,
            effort: None,
            save_library: None,
            save_effort: None,
            ..*args
        };
        let (mut lib, effort) = prepare(&pair, &knobs)?;
        let figures = evaluate(&pair, &mut lib, effort, &knobs)?;
        tally.add(&figures);
        let line = PairLine::of(&figures);
        rows.push((pair.train_seed, pair.seed));
        lines.push(line);
    }
    println!(
        "{} seed pairs, {} isolated gestures per action and {} sequences each:",
        args.pairs, args.isolated, args.sequences
    );
    header();
    for (k, ((train, test), l)) in rows.iter().zip(&lines).enumerate() {
        let v = l.fields();
        println!(
            "{:>5} {:>6} {:>6}  {:>7.1}% {:>5.1}% {:>5.1}% {:>5.1}% {:>5.1}% {:>5.0} ms {:>5.1}%",
            k + 1,
            train,
            test,
            v[0],
            v[1],
            v[2],
            v[3],
            v[4],
            v[5],
            v[6]
        );
    }
    let s = summarise(&lines);
    println!(
        "{:>5} {:>6} {:>6}  {:>7.1}% {:>5.1}% {:>5.1}% {:>5.1}% {:>5.1}% {:>5.0} ms {:>5.1}%",
        "mean", "", "", s[0].0, s[1].0, s[2].0, s[3].0, s[4].0, s[5].0, s[6].0
    );
    println!(
        "range: isolated {:.1}–{:.1}%, F1 {:.1}–{:.1}%, Time {:.1}–{:.1}%, Weight {:.1}–{:.1}%, \
         state {:.1}–{:.1}%, latency {:.0}–{:.0} ms, silent {:.1}–{:.1}%",
        s[0].1,
        s[0].2,
        s[1].1,
        s[1].2,
        s[2].1,
        s[2].2,
        s[3].1,
        s[3].2,
        s[4].1,
        s[4].2,
        s[5].1,
        s[5].2,
        s[6].1,
        s[6].2
    );
    println!("{}", tally.line());
    if let Some(line) = tally.misreads_line() {
        println!("{line}");
    }
    if let Some(words) = tally.talk.actions_words() {
        println!("a hand that talks, over the pairs: {words}");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_summary_is_the_mean_and_range_of_each_figure() {
        let a = PairLine {
            isolated: 0.8,
            f1: 0.7,
            time: 0.9,
            weight: 0.85,
            state: 0.75,
            latency_s: 0.140,
            silent: 1.0,
        };
        let b = PairLine {
            isolated: 0.9,
            f1: 0.8,
            time: 0.8,
            weight: 0.95,
            state: 0.85,
            latency_s: 0.160,
            silent: 0.9,
        };
        let s = summarise(&[a, b]);
        let close = |x: f64, y: f64| (x - y).abs() < 1e-9;
        assert!(close(s[0].0, 85.0) && close(s[0].1, 80.0) && close(s[0].2, 90.0));
        assert!(close(s[1].0, 75.0));
        assert!(close(s[2].1, 80.0) && close(s[2].2, 90.0));
        assert!(close(s[5].0, 150.0) && close(s[5].1, 140.0) && close(s[5].2, 160.0));
        assert!(close(s[6].0, 95.0) && close(s[6].1, 90.0));
    }

    #[test]
    fn the_tally_sums_the_counts_under_the_shares() {
        let f = |ok: usize, read: usize, loud: usize| Figures {
            per_action: vec![("walk".into(), ok, 10), ("jump".into(), 10, 10)],
            effort_counts: EffortCounts {
                read,
                time: read - 1,
                weight: read - 2,
                state: read - 3,
            },
            handling: vec![("lift".into(), 7, loud, 20)],
            talk: {
                let mut talk = TalkCounts {
                    logs: 19,
                    seconds: 60.0,
                    ..TalkCounts::default()
                };
                talk.add(&TalkCounts::of_log(["turn", "sidestep", "turn"], 30.0));
                talk
            },
            confusions: vec![
                ("walk".into(), "run".into(), 10 - ok),
                ("jump".into(), "none".into(), 1),
            ],
            rested: RestedCounts {
                isolated_ok: ok + 9,
                handling_loud: loud + 1,
                seq: (9, 10, 12),
            },
            ..Figures::default()
        };
        let mut t = Tally::default();
        t.add(&f(8, 18, 5));
        t.add(&f(9, 19, 2));
        assert_eq!((t.isolated_ok, t.isolated), (37, 40));
        assert_eq!(
            t.effort,
            EffortCounts {
                read: 37,
                time: 35,
                weight: 33,
                state: 31
            }
        );
        assert_eq!((t.silent, t.handling), (33, 40));
        assert_eq!(
            t.line(),
            "counts over the pairs: isolated 37 of 40 read as played, of them Time right 35, \
             Weight 33, both 31; handling silent on 33 of 40 logs; held in a hand that talks, \
             6 events in 3.0 minutes, 120 per hour; left resting 3 s after each log: \
             isolated 35 of 40 read as played, handling silent on 31 of 40 logs, sequence F1 \
             81.8%"
        );
        assert_eq!(
            t.misreads_line().as_deref(),
            Some(
                "most frequent misreads over the pairs: walk -> run 3, jump -> none 2 \
                 (of 5 misread)"
            )
        );
        assert_eq!(Tally::default().misreads_line(), None);
        assert_eq!(
            t.talk.actions_words().as_deref(),
            Some("read as turn 4, sidestep 2")
        );
        assert_eq!(Tally::default().talk.actions_words(), None);
    }
}
