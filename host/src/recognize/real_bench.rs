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
use super::simulate::{load_effort, load_library, simulate_log};

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
    /// Labels matched by an event.
    pub hits: usize,
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
        let sim = simulate_log(&d.log, names, blob, effort)?;
        let mut used = vec![false; sim.records.len()];
        let mut hits = 0;
        for (action, span) in &labels {
            let hit = sim.records.iter().enumerate().position(|(i, r)| {
                !used[i] && &r.action == action && overlaps((r.start, r.end), *span)
            });
            if let Some(i) = hit {
                used[i] = true;
                hits += 1;
            }
        }
        out.push(TakeScore {
            take: format!("{}{} ({})", t.take, window(t), t.joint),
            labels: labels.into_iter().map(|(a, _)| a).collect(),
            events: sim.records.iter().map(|r| r.action.clone()).collect(),
            hits,
        });
    }
    Ok(out)
}

/// Recall and precision over takes' scores (1 where nothing was there to find or report).
pub fn recall_precision(scores: &[TakeScore]) -> (f64, f64) {
    let hits: usize = scores.iter().map(|s| s.hits).sum();
    let labels: usize = scores.iter().map(|s| s.labels.len()).sum();
    let events: usize = scores.iter().map(|s| s.events.len()).sum();
    let ratio = |n: usize, d: usize| if d == 0 { 1.0 } else { n as f64 / d as f64 };
    (ratio(hits, labels), ratio(hits, events))
}

/// Runs `figurine eval real`.
pub fn run(args: &RealBenchArgs) -> Result<()> {
    let takes = real_takes()?;
    let (lib, blob) = load_library(args.library.as_deref())?;
    let effort = load_effort(None)?;
    let scores = score_takes(
        &takes,
        &lib.names(),
        &blob,
        Some(effort),
        args.save.as_deref(),
    )?;
    println!(
        "Real doodles: {} takes of real motion capture, figurine at the body landmark named",
        scores.len()
    );
    println!(
        "{:<56} {:<24} {:<30} hits",
        "take (landmark)", "labels", "events"
    );
    for s in &scores {
        println!(
            "{:<56} {:<24} {:<30} {}/{}",
            s.take,
            s.labels.join(" "),
            if s.events.is_empty() {
                "(none)".to_string()
            } else {
                s.events.join(" ")
            },
            s.hits,
            s.labels.len()
        );
    }
    let (recall, precision) = recall_precision(&scores);
    println!(
        "real doodles: recall {:.1}%, precision {:.1}%",
        100.0 * recall,
        100.0 * precision
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn overlap_is_a_share_of_the_shorter_span() {
        assert!(overlaps((0.0, 1.0), (0.6, 3.0)));
        assert!(!overlaps((0.0, 1.0), (0.8, 3.0)));
        assert!(overlaps((1.0, 1.2), (0.0, 5.0)));
        let s = |labels: usize, events: usize, hits| TakeScore {
            take: String::new(),
            labels: vec![String::new(); labels],
            events: vec![String::new(); events],
            hits,
        };
        assert_eq!(recall_precision(&[s(2, 4, 1), s(2, 0, 0)]), (0.25, 0.25));
        assert_eq!(recall_precision(&[]), (1.0, 1.0));
    }
}
