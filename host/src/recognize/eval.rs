//! `figurine eval`: recognition and effort accuracy on synthetic doodles, like seed 000
//! Fig. 7–9.
//!
//! By default everything is fresh: each of the 12 actions is learnt from `--examples` (3)
//! generated performances (seed `--train-seed`), the effort model is trained on a generated
//! effort set (same seed), and the test set comes from `--seed` (different). `--library` /
//! `--effort` evaluate given files instead. Reported:
//! - isolated gestures: per action, the share whose main event (the one overlapping the
//!   performance most) is the right action, and the confusions;
//! - Time, Weight and state accuracy of the correctly recognised isolated gestures;
//! - sequences: events matched to labels (same action, overlapping in time, one-to-one),
//!   precision, recall and F1, and why the unmatched events did not match ([`ExtraKind`]);
//! - handling that plays no action ([`Handling`]: the toy carried elsewhere, lifted and set
//!   down; `--isolated` logs of each kind): the share on which nothing is reported;
//! - a toy held in a hand that talks ([`Handling::Talk`], `--isolated` logs): events per hour,
//!   and the actions they were read as;
//! - decision latency: when the event was emitted, after the performance's labelled end
//!   (median and 90th percentile);
//! - the isolated gestures, handling logs and sequences read again, each followed by
//!   [`RESTED_S`] of stillness ([`Figures::rested`]): a log is read to its end, 0.3–1.5 s
//!   after its motion, and the stream's end decides some phrases otherwise than a figurine
//!   left resting does.
//!
//! The benchmarks (`figurine eval rest | sweep | real | repeat`) are dispatched by
//! [`super::eval_cli`], each in its own module; they use what is here.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::effort_train::{gesture_features, train, Example, Trained};
use super::learn::learn_action;
use super::library::LibraryFile;
use super::scoring::{
    label_ok, notes_of, overlap, pair_events, prf, run_doodle, Ev, ExtraEvents, ExtraKind,
};
use super::simulate::load_effort;
use crate::synth::sequence::{Doodle, Label};
use crate::synth::{self, Action, Handling, Knobs, Range, TimeClass, WeightClass};
use figurine_recognizer::EffortModel;

/// Mixed into the test seed for the handling logs, so they are drawn apart from the gestures.
const HANDLING_SEED: u64 = 0x4a_4d1e;

/// Mixed into the test seed for the talking logs.
const TALK_SEED: u64 = 0x7a_1c3e;

/// Arguments of `figurine eval` (the accuracy tables).
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// Seed of the test set (use one nothing was trained on).
    #[arg(long, default_value_t = 1000)]
    pub seed: u64,
    /// Seed of the learning examples and effort training set.
    #[arg(long, default_value_t = 1)]
    pub train_seed: u64,
    /// Learning examples per action.
    #[arg(long, default_value_t = 3)]
    pub examples: usize,
    /// Effort training gestures per state.
    #[arg(long, default_value_t = 40)]
    pub effort_per_class: usize,
    /// Isolated test gestures per action.
    #[arg(long, default_value_t = 20)]
    pub isolated: usize,
    /// Test sequences.
    #[arg(long, default_value_t = 20)]
    pub sequences: usize,
    /// Actions per sequence.
    #[arg(long, default_value_t = 6)]
    pub sequence_len: usize,
    /// Evaluate this library instead of learning one.
    #[arg(long)]
    pub library: Option<PathBuf>,
    /// Evaluate this effort model instead of training one.
    #[arg(long)]
    pub effort: Option<PathBuf>,
    /// Save the learnt library here.
    #[arg(long)]
    pub save_library: Option<PathBuf>,
    /// Save the trained effort model here.
    #[arg(long)]
    pub save_effort: Option<PathBuf>,
    /// Print the token string of every misrecognised isolated gesture, and every sequence
    /// event that matched no gesture (with why).
    #[arg(long)]
    pub verbose: bool,
    /// Repeat the evaluation over this many independent seed pairs: pair i learns and trains
    /// with `--train-seed` + i and tests on `--seed` + 1000·i; prints a line per pair and
    /// the mean (with learning and training only, not with given files).
    #[arg(long, default_value_t = 1)]
    pub pairs: usize,
    /// The tracker and player of every generated log, learning and test alike (a user records
    /// examples with the tracker they play with): noise multiplier (default 0.5..1.5).
    #[arg(long)]
    pub noise: Option<Range>,
    /// Nominal tracker rate, Hz (default 30..240).
    #[arg(long)]
    pub rate: Option<Range>,
    /// Spatial scale of the doodles (default 0.5..2; at 1 a gesture is about 14 cm across).
    #[arg(long)]
    pub scale: Option<Range>,
}

impl EvalArgs {
    /// This evaluation's tracker and scale as `figurine synth` flags (" --noise 3"…), to
    /// regenerate one of its logs.
    pub fn knob_flags(&self) -> String {
        [
            ("noise", self.noise),
            ("rate", self.rate),
            ("scale", self.scale),
        ]
        .iter()
        .filter_map(|(name, r)| r.map(|r| format!(" --{name} {r}")))
        .collect()
    }

    /// The generator's knobs, with this evaluation's tracker and scale.
    pub fn knobs(&self) -> Knobs {
        let mut k = Knobs::default();
        if let Some(r) = self.noise {
            k.noise = r;
        }
        if let Some(r) = self.rate {
            k.rate_hz = r;
        }
        if let Some(r) = self.scale {
            k.scale = r;
        }
        k
    }
}

/// The `n` generated examples of `action` that [`learn_synth_library`] learns it from.
pub fn synth_examples(
    seed: u64,
    n: usize,
    knobs: &Knobs,
    action: Action,
) -> Vec<crate::poselog::PoseLog> {
    let index = Action::ALL.iter().position(|&a| a == action).unwrap_or(0) as u64;
    synth::examples(
        synth::sequence::item_seed(seed, 100 + index),
        knobs,
        action,
        n,
        None,
    )
    .into_iter()
    .map(|d| d.log)
    .collect()
}

/// Learns every synth action from `n` generated examples.
pub fn learn_synth_library(seed: u64, n: usize, knobs: &Knobs) -> Result<LibraryFile> {
    let mut lib = LibraryFile::default();
    for &action in Action::ALL.iter() {
        let logs = synth_examples(seed, n, knobs, action);
        lib.upsert(learn_action(action.name(), &logs, None, true)?);
    }
    for step in super::separate::separate(&mut lib)? {
        eprintln!("  {step}");
    }
    Ok(lib)
}

/// Trains the effort model on a generated effort set.
pub fn train_synth_effort(
    seed: u64,
    per_class: usize,
    knobs: &Knobs,
) -> Result<(Vec<Example>, Trained)> {
    let set = synth::effort_set(seed, knobs, per_class);
    let ex: Vec<Example> = set
        .iter()
        .filter_map(|(e, d)| {
            gesture_features(&d.log).map(|f| Example {
                f,
                sudden: e.time == TimeClass::Sudden,
                strong: e.weight == WeightClass::Strong,
            })
        })
        .collect();
    let t = train(&ex)?;
    Ok((ex, t))
}

/// Evaluation figures.
#[derive(Debug, Clone, Default)]
pub struct Figures {
    /// Per action: (correct, total) on isolated gestures.
    pub per_action: Vec<(String, usize, usize)>,
    /// Isolated accuracy.
    pub isolated: f64,
    /// Time / Weight / state accuracy over correctly recognised isolated gestures.
    pub time: f64,
    /// Weight accuracy.
    pub weight: f64,
    /// State accuracy.
    pub state: f64,
    /// Sequence precision, recall, F1.
    pub seq_prf: (f64, f64, f64),
    /// Decision latencies (s) of matched events.
    pub latencies: Vec<f64>,
    /// Confusions: (truth, recognised-as or "none", count).
    pub confusions: Vec<(String, String, usize)>,
    /// Sequence events that match no label (the false positives of the F1), by kind.
    pub extra: ExtraEvents,
    /// Per kind of handling that plays no action ([`Handling`]): (name, events reported,
    /// logs with any event, logs).
    pub handling: Vec<(String, usize, usize, usize)>,
    /// A toy held in a hand that talks ([`Handling::Talk`]): every event is a false one.
    pub talk: TalkCounts,
    /// The counts behind the effort accuracies.
    pub effort_counts: EffortCounts,
    /// The same isolated gestures, handling logs and sequences, each followed by [`RESTED_S`]
    /// of stillness: what a figurine left resting reports, where a log's end may read otherwise.
    pub rested: RestedCounts,
}

/// Stillness appended to each isolated gesture, handling log and sequence for
/// [`Figures::rested`], s: longer than any hold a decision waits for and than the 2.5 s after
/// which partial matches are forgotten, so nothing is left for the stream's end to decide.
pub const RESTED_S: f64 = 3.0;

/// [`Figures::rested`]: isolated gestures read as played, handling logs with any event and
/// sequence events matched, when each log is followed by [`RESTED_S`] of stillness.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RestedCounts {
    /// Isolated gestures whose main event names the action played.
    pub isolated_ok: usize,
    /// Handling logs (every kind but the hand that talks) with any event.
    pub handling_loud: usize,
    /// Sequences: labels matched by an event, events, labels (as for [`Figures::seq_prf`]).
    pub seq: (usize, usize, usize),
}

impl RestedCounts {
    /// Sums two counts (seed pairs).
    pub fn add(&mut self, o: RestedCounts) {
        self.isolated_ok += o.isolated_ok;
        self.handling_loud += o.handling_loud;
        self.seq.0 += o.seq.0;
        self.seq.1 += o.seq.1;
        self.seq.2 += o.seq.2;
    }

    /// Sequence F1 from [`Self::seq`], 0 when nothing matched.
    pub fn seq_f1(&self) -> f64 {
        let (matched, events, labels) = self.seq;
        prf(matched, events, labels).2
    }

    /// These counts in words, out of `isolated` gestures and `handling` logs.
    pub fn words(&self, isolated: usize, handling: usize) -> String {
        format!(
            "left resting {RESTED_S} s after each log: isolated {} of {isolated} read as \
             played, handling silent on {} of {handling} logs, sequence F1 {:.1}%",
            self.isolated_ok,
            handling - self.handling_loud.min(handling),
            100.0 * self.seq_f1()
        )
    }
}

/// The event of `evs` that overlaps label `l` most, if any overlaps it.
fn main_event<'a>(evs: &'a [Ev], l: &Label) -> Option<&'a Ev> {
    evs.iter()
        .max_by(|a, b| {
            overlap(a.start, a.end, l.start, l.end)
                .total_cmp(&overlap(b.start, b.end, l.start, l.end))
        })
        .filter(|e| overlap(e.start, e.end, l.start, l.end) > 0.0)
}

/// `d` with [`RESTED_S`] of stillness after its log.
pub(super) fn rested(d: &Doodle) -> Doodle {
    let mut r = d.clone();
    r.log = d.log.rested(RESTED_S);
    r
}

/// How many correctly recognised isolated gestures there were, and of them how many had their
/// Time, their Weight and both right: the counts behind [`Figures::time`] and its kin. An
/// accuracy can fall merely because one more gesture is recognised; the counts tell.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EffortCounts {
    /// Isolated gestures recognised as the action played.
    pub read: usize,
    /// Of them, Time right.
    pub time: usize,
    /// Weight right.
    pub weight: usize,
    /// Both right.
    pub state: usize,
}

/// Events over logs of a toy held in a hand that talks, and how long the talking lasted: a
/// rate per hour, as `eval rest` and `eval real` give theirs; and which actions the events
/// were, since each action's rule is what a fix for them would change.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TalkCounts {
    /// Events reported (every one false).
    pub events: usize,
    /// Logs played.
    pub logs: usize,
    /// Seconds of talking (the handled spans), summed.
    pub seconds: f64,
    /// The events by the action they were reported as.
    pub by_action: BTreeMap<String, usize>,
}

impl TalkCounts {
    /// The counts of one log: its events' action names and how long the talking lasted (s).
    pub fn of_log<'a>(actions: impl IntoIterator<Item = &'a str>, seconds: f64) -> Self {
        let mut c = TalkCounts {
            logs: 1,
            seconds,
            ..TalkCounts::default()
        };
        for a in actions {
            c.events += 1;
            *c.by_action.entry(a.to_string()).or_default() += 1;
        }
        c
    }

    /// Adds `o`'s counts.
    pub fn add(&mut self, o: &TalkCounts) {
        self.events += o.events;
        self.logs += o.logs;
        self.seconds += o.seconds;
        for (a, n) in &o.by_action {
            *self.by_action.entry(a.clone()).or_default() += n;
        }
    }

    /// `read as A n, B m, …`, the most frequent first (ties by name); `None` without events.
    pub fn actions_words(&self) -> Option<String> {
        let mut all: Vec<(&String, &usize)> = self.by_action.iter().collect();
        all.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
        let shown: Vec<String> = all.iter().map(|(a, n)| format!("{a} {n}")).collect();
        (!shown.is_empty()).then(|| format!("read as {}", shown.join(", ")))
    }

    /// Events per hour of talking (0 when nothing was played).
    pub fn per_hour(&self) -> f64 {
        if self.seconds > 0.0 {
            self.events as f64 * 3600.0 / self.seconds
        } else {
            0.0
        }
    }

    /// `E events in M minutes, R per hour`.
    pub fn words(&self) -> String {
        format!(
            "{} events in {:.1} minutes, {:.0} per hour",
            self.events,
            self.seconds / 60.0,
            self.per_hour()
        )
    }
}

impl EffortCounts {
    /// Adds `o`'s counts.
    pub fn add(&mut self, o: EffortCounts) {
        self.read += o.read;
        self.time += o.time;
        self.weight += o.weight;
        self.state += o.state;
    }
}

impl Figures {
    /// Share of handling logs on which nothing was reported (1 when there were none).
    pub fn silent(&self) -> f64 {
        let (loud, n) = self
            .handling
            .iter()
            .fold((0, 0), |a, h| (a.0 + h.2, a.1 + h.3));
        1.0 - loud as f64 / n.max(1) as f64
    }
}

/// Evaluates a library and effort model on a fresh synthetic test set.
pub fn evaluate(
    args: &EvalArgs,
    lib: &mut LibraryFile,
    effort: EffortModel,
    knobs: &Knobs,
) -> Result<Figures> {
    let names = lib.names();
    let blob = lib.blob()?;
    let mut f = Figures::default();
    let (mut eff_n, mut t_ok, mut w_ok, mut s_ok) = (0usize, 0usize, 0usize, 0usize);
    let mut conf = std::collections::BTreeMap::<(String, String), usize>::new();
    for (ai, &action) in Action::ALL.iter().enumerate() {
        let mut ok = 0;
        for k in 0..args.isolated {
            let seed = synth::sequence::item_seed(args.seed, (ai * 10_000 + k) as u64);
            let d = synth::examples(seed, knobs, action, 1, None).remove(0);
            let l = &d.labels[0];
            let evs = run_doodle(&d, &names, &blob, effort)?;
            let main = main_event(&evs, l);
            let got = main.map_or("none".to_string(), |e| e.action.clone());
            let at_rest = run_doodle(&rested(&d), &names, &blob, effort)?;
            f.rested.isolated_ok +=
                usize::from(main_event(&at_rest, l).is_some_and(|e| e.action == l.action));
            if got == l.action {
                ok += 1;
                let (t, w) = label_ok(l, main.unwrap_or(&evs[0]));
                eff_n += 1;
                t_ok += usize::from(t);
                w_ok += usize::from(w);
                s_ok += usize::from(t && w);
                f.latencies.push(main.map_or(0.0, |e| e.decided - l.end));
            } else {
                if args.verbose {
                    let t = super::learn::tokenize_gesture(&d.log);
                    let v = &d.variation;
                    eprintln!(
                        "{} -> {got}: {}",
                        l.action,
                        super::library::tokens_to_string(&super::intent::tokens_only(&t))
                    );
                    eprintln!(
                        "    played at {:.0} Hz, scale {:.2}, speed {:.2}, noise {:.2}, {:?}/{:?} \
                         (figurine synth examples --action {} --count 1 --seed {seed}{})",
                        v.rate_hz,
                        v.scale,
                        v.speed,
                        v.noise,
                        l.time_class,
                        l.weight_class,
                        l.action,
                        args.knob_flags()
                    );
                    for e in &evs {
                        eprintln!(
                            "    event {} {:.2}-{:.2} (gesture {:.2}-{:.2})",
                            e.action, e.start, e.end, l.start, l.end
                        );
                    }
                    for n in notes_of(&d, &names, &blob, effort)? {
                        eprintln!(
                            "    why: {} {:.2}-{:.2}: {}",
                            n.action, n.start, n.end, n.words
                        );
                    }
                }
                *conf.entry((l.action.clone(), got)).or_default() += 1;
            }
        }
        f.per_action
            .push((action.name().to_string(), ok, args.isolated));
    }
    let (ok, n): (usize, usize) = f
        .per_action
        .iter()
        .fold((0, 0), |a, x| (a.0 + x.1, a.1 + x.2));
    f.isolated = ok as f64 / n.max(1) as f64;
    f.time = t_ok as f64 / eff_n.max(1) as f64;
    f.weight = w_ok as f64 / eff_n.max(1) as f64;
    f.state = s_ok as f64 / eff_n.max(1) as f64;
    f.effort_counts = EffortCounts {
        read: eff_n,
        time: t_ok,
        weight: w_ok,
        state: s_ok,
    };
    f.confusions = conf.into_iter().map(|((a, b), c)| (a, b, c)).collect();
    // Handling: any event is a false one.
    for (hi, &kind) in Handling::BETWEEN_PLAYS.iter().enumerate() {
        let (mut events, mut loud) = (0, 0);
        for k in 0..args.isolated {
            let seed =
                synth::sequence::item_seed(args.seed ^ HANDLING_SEED, (hi * 10_000 + k) as u64);
            let d = synth::handled(seed, knobs, kind);
            let evs = run_doodle(&d, &names, &blob, effort)?;
            events += evs.len();
            loud += usize::from(!evs.is_empty());
            f.rested.handling_loud +=
                usize::from(!run_doodle(&rested(&d), &names, &blob, effort)?.is_empty());
            if args.verbose && !evs.is_empty() {
                let t = super::learn::tokenize_gesture(&d.log);
                let got: Vec<&str> = evs.iter().map(|e| e.action.as_str()).collect();
                eprintln!(
                    "{kind} -> {}: {}\n    played at scale {:.2} (figurine synth handling \
                     --kind {kind} --seed {seed}{})",
                    got.join(" "),
                    super::library::tokens_to_string(&super::intent::tokens_only(&t)),
                    d.variation.scale,
                    args.knob_flags()
                );
            }
        }
        f.handling
            .push((kind.name().to_string(), events, loud, args.isolated));
    }
    // Talking with the toy in hand, drawn apart from the kinds above.
    for k in 0..args.isolated {
        let seed = synth::sequence::item_seed(args.seed ^ TALK_SEED, k as u64);
        let d = synth::handled(seed, knobs, Handling::Talk);
        let evs = run_doodle(&d, &names, &blob, effort)?;
        let got: Vec<&str> = evs.iter().map(|e| e.action.as_str()).collect();
        f.talk.add(&TalkCounts::of_log(
            got.iter().copied(),
            d.handled.iter().map(|h| h.end - h.start).sum(),
        ));
        if args.verbose && !got.is_empty() {
            eprintln!(
                "talk -> {} (figurine synth handling --kind talk --seed {seed}{})",
                got.join(" "),
                args.knob_flags()
            );
        }
    }
    // Sequences.
    let (mut matched, mut n_ev, mut n_lab) = (0usize, 0usize, 0usize);
    for k in 0..args.sequences {
        let seed = synth::sequence::item_seed(args.seed ^ 0x5e9_5e9, k as u64);
        let d = synth::sequence(seed, knobs, args.sequence_len, None);
        let evs = run_doodle(&d, &names, &blob, effort)?;
        n_ev += evs.len();
        n_lab += d.labels.len();
        let at_rest = run_doodle(&rested(&d), &names, &blob, effort)?;
        f.rested.seq.0 += pair_events(&d.labels, &at_rest).iter().flatten().count();
        f.rested.seq.1 += at_rest.len();
        f.rested.seq.2 += d.labels.len();
        if args.verbose && k < 3 {
            for l in &d.labels {
                eprintln!("  label {:<9} {:7.2} {:7.2}", l.action, l.start, l.end);
            }
            for e in &evs {
                eprintln!("  event {:<9} {:7.2} {:7.2}", e.action, e.start, e.end);
            }
        }
        let pairs = pair_events(&d.labels, &evs);
        if args.verbose
            && (pairs.iter().any(Option::is_none) || pairs.iter().flatten().count() < evs.len())
        {
            eprintln!(
                "  sequence {k}: figurine synth sequence --seed {seed} --count {}{} --out s.csv \
                 --labels s.json",
                args.sequence_len,
                args.knob_flags()
            );
        }
        let mut used = vec![false; evs.len()];
        for (l, &i) in d.labels.iter().zip(&pairs) {
            if let Some(i) = i {
                used[i] = true;
                matched += 1;
                f.latencies.push(evs[i].decided - l.end);
            } else if args.verbose {
                eprintln!(
                    "  sequence {k}: missed {} {:.2}-{:.2}",
                    l.action, l.start, l.end
                );
                for n in notes_of(&d, &names, &blob, effort)?
                    .iter()
                    .filter(|n| overlap(n.start, n.end, l.start, l.end) > 0.0)
                {
                    eprintln!(
                        "    why: {} {:.2}-{:.2}: {}",
                        n.action, n.start, n.end, n.words
                    );
                }
            }
        }
        for (e, _) in evs.iter().zip(&used).filter(|(_, u)| !**u) {
            let kind = ExtraKind::of(e, &d.labels, &d.handled);
            f.extra.add(kind);
            if args.verbose {
                let under: Vec<String> = d
                    .labels
                    .iter()
                    .filter(|l| overlap(e.start, e.end, l.start, l.end) > 0.0)
                    .map(|l| format!("{} {:.2}-{:.2}", l.action, l.start, l.end))
                    .collect();
                eprintln!(
                    "  sequence {k}: extra event ({}) {} {:.2}-{:.2} over [{}]",
                    kind.name(),
                    e.action,
                    e.start,
                    e.end,
                    under.join(", ")
                );
            }
        }
    }
    f.seq_prf = prf(matched, n_ev, n_lab);
    Ok(f)
}

/// Median and 90th percentile.
pub fn quantiles(v: &[f64]) -> (f64, f64) {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    (s[s.len() / 2], s[(s.len() * 9 / 10).min(s.len() - 1)])
}

/// The library and effort model `eval` measures: given files, or learnt and trained from
/// `--train-seed` (saved where `--save-library` / `--save-effort` say).
pub fn prepare(args: &EvalArgs, knobs: &Knobs) -> Result<(LibraryFile, EffortModel)> {
    let mut lib = match &args.library {
        Some(p) => LibraryFile::read(p)?,
        None => {
            eprintln!(
                "learning {} actions from {} examples each (seed {})…",
                Action::ALL.len(),
                args.examples,
                args.train_seed
            );
            learn_synth_library(args.train_seed, args.examples, knobs)?
        }
    };
    if let Some(p) = &args.save_library {
        lib.write(p)?;
    }
    let effort = match &args.effort {
        Some(p) => load_effort(Some(p))?,
        None => {
            eprintln!(
                "training effort on {} gestures per state (seed {})…",
                args.effort_per_class, args.train_seed
            );
            let (_, t) = train_synth_effort(args.train_seed, args.effort_per_class, knobs)?;
            if let Some(p) = &args.save_effort {
                t.file.write(p)?;
            }
            t.file.model()?
        }
    };
    Ok((lib, effort))
}

/// `figurine eval` with one seed pair: prints the accuracy tables.
pub fn run(args: &EvalArgs) -> Result<()> {
    let knobs = args.knobs();
    let (mut lib, effort) = prepare(args, &knobs)?;
    let f = evaluate(args, &mut lib, effort, &knobs)?;
    println!(
        "Isolated gestures (seed {}), {} per action:",
        args.seed, args.isolated
    );
    println!("{:<10} {:>8}", "action", "correct");
    for (a, ok, n) in &f.per_action {
        println!(
            "{:<10} {:>7.1}%",
            a,
            100.0 * *ok as f64 / (*n).max(1) as f64
        );
    }
    println!("{:<10} {:>7.1}%", "ALL", 100.0 * f.isolated);
    if !f.confusions.is_empty() {
        println!("confusions (truth -> recognised: count):");
        for (a, b, c) in &f.confusions {
            println!("  {a} -> {b}: {c}");
        }
    }
    println!("Laban effort on recognised isolated gestures:");
    println!(
        "  Time {:.1}%   Weight {:.1}%   state {:.1}%",
        100.0 * f.time,
        100.0 * f.weight,
        100.0 * f.state
    );
    println!(
        "Sequences ({} × {} actions): precision {:.1}%  recall {:.1}%  F1 {:.1}%",
        args.sequences,
        args.sequence_len,
        100.0 * f.seq_prf.0,
        100.0 * f.seq_prf.1,
        100.0 * f.seq_prf.2
    );
    println!(
        "  events matching no gesture: {} second pieces of a gesture, {} wrong action, {} \
         between gestures, {} over handling",
        f.extra.split, f.extra.wrong, f.extra.spurious, f.extra.handled
    );
    let kinds: Vec<String> = f
        .handling
        .iter()
        .map(|(k, e, l, n)| format!("{k} {e} events on {l} of {n}"))
        .collect();
    println!(
        "Handling that plays no action: silent on {:.1}% ({})",
        100.0 * f.silent(),
        kinds.join(", ")
    );
    let (isolated, handling) = (
        f.per_action.iter().map(|a| a.2).sum(),
        f.handling.iter().map(|h| h.3).sum(),
    );
    println!(
        "As a figurine {} (the figures above read each log to its end)",
        f.rested.words(isolated, handling)
    );
    println!(
        "Held in a hand that talks, playing no action ({} logs): {}{}",
        f.talk.logs,
        f.talk.words(),
        f.talk
            .actions_words()
            .map_or(String::new(), |w| format!(" ({w})"))
    );
    let (med, p90) = quantiles(&f.latencies);
    println!(
        "Decision latency after the gesture ends: median {:.0} ms, 90th percentile {:.0} ms",
        1000.0 * med,
        1000.0 * p90
    );
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn the_regenerate_flags_name_the_tracker_and_scale_asked() {
        #[derive(clap::Parser)]
        struct Cli {
            #[command(flatten)]
            eval: EvalArgs,
        }
        let flags = |argv: &[&str]| {
            let cli = <Cli as clap::Parser>::try_parse_from(argv).unwrap();
            cli.eval.knob_flags()
        };
        assert_eq!(flags(&["eval"]), "");
        assert_eq!(
            flags(&["eval", "--noise", "3", "--scale", "0.1..0.3"]),
            " --noise 3 --scale 0.1..0.3"
        );
        // The flags parse back to the same knobs.
        let back = <Cli as clap::Parser>::try_parse_from(
            ["eval"]
                .into_iter()
                .chain(" --noise 3 --scale 0.1..0.3".split_whitespace()),
        )
        .unwrap();
        assert_eq!(back.eval.knobs().scale, Range::new(0.1, 0.3));
    }
}
