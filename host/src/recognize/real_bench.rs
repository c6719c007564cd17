//! `figurine eval real`: recognition on real doodles — motion-capture takes of people, turned
//! into figurine logs ([`super::doodle`]) and labelled by hand.
//!
//! The takes are the motion capture `cargo xtask setup` fetches (DeepMimic's clips, the BVH
//! files); which take, which body landmark the figurine follows, which span and which actions
//! it holds are listed in `host/assets/real_takes.json`, each with a note on how it was cut. A
//! recognised event is a hit when it names a labelled action and overlaps its span by at least
//! [`MIN_OVERLAP`] of the shorter of the two; every other event is a false one. Recall and
//! precision are over all takes.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use serde::Deserialize;

use super::doodle::{doodle, Doodle, DoodleSpec};
use super::eval::{learn_synth_library, RESTED_S};
use super::learn::learn_action;
use super::library::LibraryFile;
use super::separate::separate;
use super::simulate::{load_effort, load_library, simulate_log};
use crate::poselog::PoseLog;
use crate::synth::Knobs;

/// The labelled takes, compiled in.
pub const REAL_TAKES_JSON: &str = include_str!("../../assets/real_takes.json");

/// Share of the shorter of an event and a label by which they must overlap to match.
pub const MIN_OVERLAP: f64 = 0.3;

/// One labelled take (see `host/assets/real_takes.json`).
#[derive(Debug, Clone, Deserialize)]
pub struct RealTake {
    /// The file, under the data folder (`deepmimic/humanoid3d_walk.txt`, `bvh/…`).
    pub take: String,
    /// The body landmark the figurine follows (a role or a joint name).
    #[serde(default = "hips")]
    pub joint: String,
    /// First and last second of the take to use (absent: all of it).
    #[serde(default)]
    pub start: Option<f64>,
    /// Last second of the take to use.
    #[serde(default)]
    pub end: Option<f64>,
    /// Factor on every position (a figurine doodled at this share of the performer's size).
    #[serde(default = "one")]
    pub scale: f32,
    /// The actions played, each over seconds of the take (absent: the whole span used).
    pub actions: Vec<RealLabel>,
    /// How the take was cut and labelled.
    pub note: String,
}

/// One labelled action of a take.
#[derive(Debug, Clone, Deserialize)]
pub struct RealLabel {
    /// The action's name.
    pub action: String,
    /// Its span in seconds of the take (absent: the whole span used).
    #[serde(default)]
    pub span: Option<(f64, f64)>,
}

fn hips() -> String {
    "hips".into()
}

fn one() -> f32 {
    1.0
}

/// The compiled-in takes.
pub fn real_takes() -> Result<Vec<RealTake>> {
    serde_json::from_str(REAL_TAKES_JSON).context("host/assets/real_takes.json")
}

/// `figurine eval real`.
#[derive(Debug, Args, Clone)]
pub struct RealBenchArgs {
    /// The action library (default: the shipped one).
    #[arg(long)]
    pub library: Option<PathBuf>,
    /// Also write each doodle here (one CSV per take, with its label lines).
    #[arg(long)]
    pub save: Option<PathBuf>,
    /// Learn this many libraries from the generator instead, as the shipped one is learnt
    /// (`--examples` per action, train seeds `--train-seed` on), and report over all of them:
    /// what one library reads is partly the luck of its examples.
    #[arg(long, conflicts_with_all = ["library", "save"], value_parser = clap::value_parser!(u64).range(1..))]
    pub libraries: Option<u64>,
    /// First train seed of `--libraries` (the shipped library's is 1).
    #[arg(long, default_value_t = 1, requires = "libraries")]
    pub train_seed: u64,
    /// Examples per action of each `--libraries` library (the shipped library's: 3).
    #[arg(long, default_value_t = 3, requires = "libraries")]
    pub examples: usize,
    /// Teach the library with real performances, as a user with motion capture would: each
    /// take is read by a library in which every action that other takes play alone (one
    /// label, cut to its span) is learnt from up to [`TAUGHT_EXAMPLES`] of them — never from
    /// the take being read — and the other actions as the shipped library's are.
    #[arg(long, conflicts_with_all = ["library", "libraries"])]
    pub taught: bool,
}

/// Take `t` cut to label `l`'s span (all of `t` when the label has none).
fn labelled_span(t: &RealTake, l: &RealLabel) -> RealTake {
    let (start, end) = l.span.map_or((t.start, t.end), |(a, b)| (Some(a), Some(b)));
    RealTake {
        start,
        end,
        ..t.clone()
    }
}

/// Real performances a `--taught` library learns an action from, at most.
pub const TAUGHT_EXAMPLES: usize = 3;

/// The real performances a `--taught` library may learn from: every take that plays one action
/// alone (one label), as (take index, action, its doodle cut to the label's span), in the
/// takes' order. Made once, whichever take is then left out.
pub fn taught_examples(takes: &[RealTake]) -> Result<Vec<(usize, String, PoseLog)>> {
    let mut out = Vec::new();
    for (i, t) in takes.iter().enumerate() {
        if let [only] = t.actions.as_slice() {
            let log = take_doodle(&labelled_span(t, only))?.0.log;
            out.push((i, only.action.clone(), log));
        }
    }
    Ok(out)
}

/// The library take `leave_out` is read with under `--taught`: `base` (learnt from the
/// generator), with every action that other takes play alone relearnt from up to
/// [`TAUGHT_EXAMPLES`] of their [`taught_examples`] (in the takes' order), then separated
/// again; and the actions so taught.
pub fn taught_library(
    examples: &[(usize, String, PoseLog)],
    leave_out: usize,
    base: &LibraryFile,
) -> Result<(LibraryFile, Vec<String>)> {
    let mut by_action: std::collections::BTreeMap<&str, Vec<PoseLog>> = Default::default();
    for (_, action, log) in examples.iter().filter(|(i, ..)| *i != leave_out) {
        let logs = by_action.entry(action.as_str()).or_default();
        if logs.len() < TAUGHT_EXAMPLES {
            logs.push(log.clone());
        }
    }
    let mut lib = base.clone();
    let mut taught = Vec::new();
    for (action, logs) in by_action {
        lib.upsert(learn_action(action, &logs, None, true)?);
        taught.push(action.to_string());
    }
    separate(&mut lib)?;
    Ok((lib, taught))
}

/// One take's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct TakeScore {
    /// The take's file.
    pub take: String,
    /// Labelled actions.
    pub labels: Vec<String>,
    /// Recognised actions, in order.
    pub events: Vec<String>,
    /// Per label, whether an event matched it.
    pub found: Vec<bool>,
    /// Length of the take's doodle, seconds.
    pub seconds: f64,
    /// [`Self::events`], the take followed by [`RESTED_S`] of stillness: what a figurine left
    /// resting reports, where the take's end may decide otherwise.
    pub rested_events: Vec<String>,
    /// [`Self::found`], the take followed by [`RESTED_S`] of stillness.
    pub rested_found: Vec<bool>,
}

impl TakeScore {
    /// Labels matched by an event.
    pub fn hits(&self) -> usize {
        self.found.iter().filter(|&&f| f).count()
    }

    /// This take as a figurine left resting after it reads it.
    pub fn rested(&self) -> TakeScore {
        TakeScore {
            events: self.rested_events.clone(),
            found: self.rested_found.clone(),
            ..self.clone()
        }
    }
}

/// Whether spans `a` and `b` (seconds) overlap by [`MIN_OVERLAP`] of the shorter.
fn overlaps(a: (f64, f64), b: (f64, f64)) -> bool {
    let common = a.1.min(b.1) - a.0.max(b.0);
    let shorter = (a.1 - a.0).min(b.1 - b.0).max(1e-3);
    common >= MIN_OVERLAP * shorter
}

/// A take's labelled actions, as (action, span in seconds of its doodle's log).
pub type Labels = Vec<(String, (f64, f64))>;

/// The doodle of take `t` (its file under the data folder) and its labels on the doodle's
/// clock. An error names a take that is not fetched.
pub fn take_doodle(t: &RealTake) -> Result<(Doodle, Labels)> {
    let path = crate::data::data_dir().join(&t.take);
    if !path.is_file() {
        anyhow::bail!(
            "{} not found: run `cargo xtask setup` to fetch the motion capture",
            path.display()
        );
    }
    let clip = crate::motion::read_take(&path, None)?;
    let spec = DoodleSpec {
        joint: t.joint.clone(),
        span: (t.start, t.end),
        scale: t.scale,
        ..DoodleSpec::default()
    };
    let d = doodle(&clip, &spec, &t.take)?;
    // Take seconds → log seconds.
    let shift = d.motion.0 - t.start.unwrap_or(0.0);
    let labels = t
        .actions
        .iter()
        .map(|l| {
            let span = l
                .span
                .map(|(a, b)| (a + shift, b + shift))
                .unwrap_or(d.motion);
            (l.action.clone(), span)
        })
        .collect();
    Ok((d, labels))
}

/// The seconds of the take used, when not all of it (" 32-48 s"), else "".
fn window(t: &RealTake) -> String {
    match (t.start, t.end) {
        (None, None) => String::new(),
        (s, e) => format!(
            " {}-{} s",
            s.map_or("start".into(), |s| s.to_string()),
            e.map_or("end".into(), |e| e.to_string())
        ),
    }
}

/// Recognises every take with the library `names`/`blob`; `save` keeps the doodles.
pub fn score_takes(
    takes: &[RealTake],
    names: &[String],
    blob: &[u8],
    effort: Option<figurine_recognizer::EffortModel>,
    save: Option<&std::path::Path>,
) -> Result<Vec<TakeScore>> {
    let mut out = Vec::new();
    for t in takes {
        let (d, labels) = take_doodle(t)?;
        if let Some(dir) = save {
            std::fs::create_dir_all(dir)?;
            let mut text = String::new();
            for (a, (s, e)) in &labels {
                text.push_str(&format!("# label {a} {s:.6}..{e:.6}\n"));
            }
            let mut body = Vec::new();
            d.log.write(&mut body)?;
            text.push_str(&String::from_utf8_lossy(&body));
            let stem = format!("{}{}", t.take, window(t)).replace(['/', '.', ' '], "_");
            std::fs::write(dir.join(format!("{stem}_{}.csv", t.joint)), text)?;
        }
        // The events read in `log`, and per label whether one of them matched it.
        let read = |log: &PoseLog| -> Result<(Vec<String>, Vec<bool>)> {
            let sim = simulate_log(log, names, blob, effort)?;
            let mut used = vec![false; sim.records.len()];
            let mut found = Vec::with_capacity(labels.len());
            for (action, span) in &labels {
                let hit = sim.records.iter().enumerate().position(|(i, r)| {
                    !used[i] && &r.action == action && overlaps((r.start, r.end), *span)
                });
                if let Some(i) = hit {
                    used[i] = true;
                }
                found.push(hit.is_some());
            }
            Ok((sim.records.into_iter().map(|r| r.action).collect(), found))
        };
        let (events, found) = read(&d.log)?;
        let (rested_events, rested_found) = read(&d.log.rested(RESTED_S))?;
        out.push(TakeScore {
            take: format!("{}{} ({})", t.take, window(t), t.joint),
            labels: labels.into_iter().map(|(a, _)| a).collect(),
            events,
            found,
            seconds: d.log.samples.last().map_or(0.0, |l| l.t)
                - d.log.samples.first().map_or(0.0, |f| f.t),
            rested_events,
            rested_found,
        });
    }
    Ok(out)
}

/// Recall and precision over takes' scores (1 where nothing was there to find or report).
pub fn recall_precision<'a>(scores: impl IntoIterator<Item = &'a TakeScore>) -> (f64, f64) {
    let (hits, labels, events) = scores.into_iter().fold((0, 0, 0), |(h, l, e), s| {
        (h + s.hits(), l + s.labels.len(), e + s.events.len())
    });
    let ratio = |n: usize, d: usize| if d == 0 { 1.0 } else { n as f64 / d as f64 };
    (ratio(hits, labels), ratio(hits, events))
}

/// Events per hour on the takes that play no action (a person standing and talking, a
/// cartwheel…), with their count and the takes' hours: the real-motion twin of `eval rest`.
pub fn idle_per_hour<'a>(scores: impl IntoIterator<Item = &'a TakeScore>) -> (f64, usize, f64) {
    let (events, seconds) = scores
        .into_iter()
        .filter(|s| s.labels.is_empty())
        .fold((0, 0.0), |(e, t), s| (e + s.events.len(), t + s.seconds));
    let hours = seconds / 3600.0;
    let rate = if hours > 0.0 {
        events as f64 / hours
    } else {
        0.0
    };
    (rate, events, hours)
}

/// Runs `figurine eval real`.
pub fn run(args: &RealBenchArgs) -> Result<()> {
    let takes = real_takes()?;
    let effort = load_effort(None)?;
    let runs = match args.libraries {
        None if args.taught => {
            let base = learn_synth_library(1, 3, &Knobs::default())?;
            let examples = taught_examples(&takes)?;
            let mut scores = Vec::new();
            for (i, take) in takes.iter().enumerate() {
                let (mut lib, taught) = taught_library(&examples, i, &base)?;
                eprintln!(
                    "{}: {} taught by other takes",
                    take.take,
                    if taught.is_empty() {
                        "no action".to_string()
                    } else {
                        taught.join(", ")
                    }
                );
                let save = args.save.as_deref();
                let one = std::slice::from_ref(take);
                scores.extend(score_takes(
                    one,
                    &lib.names(),
                    &lib.blob()?,
                    Some(effort),
                    save,
                )?);
            }
            vec![scores]
        }
        None => {
            let (lib, blob) = load_library(args.library.as_deref())?;
            vec![score_takes(
                &takes,
                &lib.names(),
                &blob,
                Some(effort),
                args.save.as_deref(),
            )?]
        }
        Some(n) => {
            let mut runs = Vec::new();
            for seed in args.train_seed..args.train_seed.saturating_add(n) {
                eprintln!("learning a library at train seed {seed}…");
                let mut lib = learn_synth_library(seed, args.examples, &Knobs::default())?;
                runs.push(score_takes(
                    &takes,
                    &lib.names(),
                    &lib.blob()?,
                    Some(effort),
                    None,
                )?);
            }
            runs
        }
    };
    print!("{}", report(&runs));
    Ok(())
}

/// The table of `figurine eval real` over one library's scores or several's (one `runs`
/// entry per library, takes in the same order): per take its labels, its events (their count
/// over several libraries) and its hits, then recall per action and over all.
pub fn report(runs: &[Vec<TakeScore>]) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let n = runs.len();
    let Some(first) = runs.first() else {
        return out;
    };
    let _ = writeln!(
        out,
        "Real doodles: {} takes of real motion capture, figurine at the body landmark named{}",
        first.len(),
        if n > 1 {
            format!("; hits and events summed over {n} libraries")
        } else {
            String::new()
        }
    );
    let _ = writeln!(
        out,
        "{:<56} {:<24} {:<30} hits",
        "take (landmark)", "labels", "events"
    );
    let mut per_action: std::collections::BTreeMap<&str, (usize, usize)> = Default::default();
    for (i, s) in first.iter().enumerate() {
        let of_take = runs.iter().filter_map(|r| r.get(i));
        let (hits, events) = of_take
            .clone()
            .fold((0, 0), |(h, e), t| (h + t.hits(), e + t.events.len()));
        for t in of_take {
            for (label, &f) in t.labels.iter().zip(&t.found) {
                let e = per_action.entry(label.as_str()).or_default();
                e.0 += usize::from(f);
                e.1 += 1;
            }
        }
        let events = match (n, s.events.is_empty()) {
            (1, true) => "(none)".to_string(),
            (1, false) => s.events.join(" "),
            _ => format!("{events}"),
        };
        let _ = writeln!(
            out,
            "{:<56} {:<24} {:<30} {hits}/{}",
            s.take,
            s.labels.join(" "),
            events,
            s.labels.len() * n
        );
    }
    let recall: Vec<String> = per_action
        .iter()
        .map(|(a, (h, l))| format!("{a} {h}/{l}"))
        .collect();
    let _ = writeln!(out, "found per action: {}", recall.join(", "));
    let (recall, precision) = recall_precision(runs.iter().flatten());
    let _ = writeln!(
        out,
        "real doodles: recall {:.1}%, precision {:.1}%",
        100.0 * recall,
        100.0 * precision
    );
    let (rate, events, hours) = idle_per_hour(runs.iter().flatten());
    let _ = writeln!(
        out,
        "takes that play no action: {events} events in {:.1} minutes, {rate:.0} per hour",
        hours * 60.0
    );
    let rested: Vec<TakeScore> = runs.iter().flatten().map(TakeScore::rested).collect();
    let (recall, precision) = recall_precision(&rested);
    let (rate, events, _) = idle_per_hour(&rested);
    let _ = writeln!(
        out,
        "as a figurine left resting {RESTED_S} s after each take: recall {:.1}%, precision \
         {:.1}%; the takes that play no action {events} events, {rate:.0} per hour",
        100.0 * recall,
        100.0 * precision
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        real: RealBenchArgs,
    }

    #[test]
    fn learnt_libraries_take_as_many_examples_as_asked() {
        let cli = Cli::try_parse_from(["real", "--libraries", "2", "--examples", "6"]).unwrap();
        assert_eq!((cli.real.libraries, cli.real.examples), (Some(2), 6));
        let cli = Cli::try_parse_from(["real", "--libraries", "2"]).unwrap();
        assert_eq!(cli.real.examples, 3);
        // Examples are for learnt libraries only: with the shipped one they mean nothing.
        assert!(Cli::try_parse_from(["real", "--examples", "6"]).is_err());
    }

    #[test]
    fn the_takes_parse_and_name_known_actions() {
        let takes = real_takes().unwrap();
        assert!(!takes.is_empty());
        let (lib, _) = load_library(None).unwrap();
        let names = lib.names();
        for t in &takes {
            assert!(!t.note.is_empty(), "{}: say how it was cut", t.take);
            for l in &t.actions {
                assert!(names.contains(&l.action), "{}: {}", t.take, l.action);
            }
        }
    }

    #[test]
    fn every_label_lies_inside_its_takes_window() {
        for t in real_takes().unwrap() {
            let (lo, hi) = (t.start.unwrap_or(0.0), t.end.unwrap_or(f64::INFINITY));
            assert!(lo < hi, "{}: window {lo}-{hi}", t.take);
            for l in &t.actions {
                if let Some((a, b)) = l.span {
                    assert!(
                        lo <= a && a < b && b <= hi,
                        "{} {}: {a}-{b}",
                        t.take,
                        l.action
                    );
                }
            }
        }
    }

    #[test]
    fn a_taught_library_never_learns_from_the_take_it_reads() {
        let takes = real_takes().unwrap();
        if let Err(e) = takes.iter().try_for_each(|t| take_doodle(t).map(|_| ())) {
            eprintln!("skipping: {e}");
            return;
        }
        let alone = |action: &str| -> Vec<usize> {
            (0..takes.len())
                .filter(|&i| matches!(takes[i].actions.as_slice(), [l] if l.action == action))
                .collect()
        };
        let tokens = |i: usize| {
            let [only] = takes[i].actions.as_slice() else {
                unreachable!()
            };
            let log = take_doodle(&labelled_span(&takes[i], only)).unwrap().0.log;
            let t = super::super::learn::tokenize_gesture(&log);
            super::super::library::tokens_to_string(&super::super::intent::tokens_only(&t))
        };
        let base = learn_synth_library(1, 1, &Knobs::default()).unwrap();
        let examples = taught_examples(&takes).unwrap();
        // The one take that runs alone teaches a run to every other take's library, not its own.
        let [run] = alone("run")[..] else {
            panic!("one take runs alone")
        };
        let (_, taught) = taught_library(&examples, run, &base).unwrap();
        assert!(!taught.contains(&"run".to_string()), "{taught:?}");
        let (_, taught) = taught_library(&examples, (run + 1) % takes.len(), &base).unwrap();
        assert!(taught.contains(&"run".to_string()), "{taught:?}");
        // A walk is read with a walk learnt from the first three other walks, in order.
        let walks = alone("walk");
        assert!(walks.len() > TAUGHT_EXAMPLES, "{walks:?}");
        let read = walks[1];
        let (lib, _) = taught_library(&examples, read, &base).unwrap();
        let walk = lib.actions.iter().find(|a| a.name == "walk").unwrap();
        let want: Vec<String> = walks
            .iter()
            .filter(|&&i| i != read)
            .take(TAUGHT_EXAMPLES)
            .map(|&i| tokens(i))
            .collect();
        assert_eq!(walk.examples, want);
    }

    #[test]
    fn overlap_is_a_share_of_the_shorter_span() {
        assert!(overlaps((0.0, 1.0), (0.6, 3.0)));
        assert!(!overlaps((0.0, 1.0), (0.8, 3.0)));
        assert!(overlaps((1.0, 1.2), (0.0, 5.0)));
        let s = |labels: usize, events: usize, hits| TakeScore {
            take: String::new(),
            labels: vec![String::new(); labels],
            events: vec![String::new(); events],
            found: (0..labels).map(|i| i < hits).collect(),
            seconds: 1.0,
            rested_events: Vec::new(),
            rested_found: Vec::new(),
        };
        assert_eq!(recall_precision(&[s(2, 4, 1), s(2, 0, 0)]), (0.25, 0.25));
        assert_eq!(recall_precision(&[]), (1.0, 1.0));
    }

    #[test]
    fn a_take_read_at_rest_keeps_its_labels_and_length() {
        let mut t = score(&["turn", "turn"], &["turn", "turn"], &[true, true]);
        t.rested_events = vec!["turn".into()];
        t.rested_found = vec![true, false];
        let r = t.rested();
        assert_eq!((r.labels, r.seconds), (t.labels.clone(), t.seconds));
        assert_eq!(recall_precision(&[t.rested()]), (0.5, 1.0));
        assert_eq!((r.events, r.found), (t.rested_events, t.rested_found));
    }

    fn score(labels: &[&str], events: &[&str], found: &[bool]) -> TakeScore {
        TakeScore {
            take: "t".into(),
            labels: labels.iter().map(|l| l.to_string()).collect(),
            events: events.iter().map(|e| e.to_string()).collect(),
            found: found.to_vec(),
            seconds: 36.0,
            rested_events: Vec::new(),
            rested_found: Vec::new(),
        }
    }

    #[test]
    fn a_report_over_libraries_sums_each_takes_hits_and_events() {
        let one = vec![
            score(&["turn", "walk"], &["turn", "run"], &[true, false]),
            score(&[], &["run"], &[]),
        ];
        let two = vec![
            score(&["turn", "walk"], &["walk"], &[false, true]),
            score(&[], &[], &[]),
        ];
        let text = report(&[one.clone(), two]);
        assert!(text.contains("summed over 2 libraries"), "{text}");
        assert!(
            text.contains("found per action: turn 1/2, walk 1/2"),
            "{text}"
        );
        // 2 hits of 4 labels; 2 of 4 events.
        assert!(text.contains("recall 50.0%, precision 50.0%"), "{text}");
        let row: Vec<&str> = text.lines().nth(2).unwrap().split_whitespace().collect();
        assert_eq!(row, ["t", "turn", "walk", "3", "2/4"], "{text}");
        // One library lists its events by name.
        assert!(report(&[one]).contains("turn run"));
        // The take that plays nothing: 1 event in 2 × 36 s, 50 an hour.
        assert!(
            text.contains("takes that play no action: 1 events in 1.2 minutes, 50 per hour"),
            "{text}"
        );
    }

    #[test]
    fn idle_rate_counts_only_takes_without_labels() {
        let takes = [
            score(&["walk"], &["walk", "run"], &[true]),
            score(&[], &["run", "run"], &[]),
            score(&[], &[], &[]),
        ];
        // 2 events in the 72 s of the two takes that play nothing.
        let (rate, events, hours) = idle_per_hour(&takes);
        assert_eq!(events, 2);
        assert!((hours - 0.02).abs() < 1e-12 && (rate - 100.0).abs() < 1e-9);
        assert_eq!(idle_per_hour(&takes[..1]), (0.0, 0, 0.0));
    }
}
