//! An evaluation's events against its labels: a doodle run through the device recognizer
//! ([`run_doodle`]), each label paired with the event that took it ([`pair_events`]), and why
//! an event that took none did not ([`ExtraKind`]). `figurine eval` and its benchmarks score
//! with these.

use anyhow::Result;
use figurine_recognizer::{EffortModel, Library, Recognizer};

use super::feed::{log_samples, recognize_log, Clock};
use super::simulate::{note_lines, simulate_log, NoteLine};
use crate::synth::{Doodle, Label, TimeClass, WeightClass};

/// One recognised event in log seconds.
#[derive(Debug, Clone)]
pub struct Ev {
    /// Action name.
    pub action: String,
    /// Start, s.
    pub start: f64,
    /// End, s.
    pub end: f64,
    /// Decision time, s.
    pub decided: f64,
    /// Lt.
    pub time: f64,
    /// Lw.
    pub weight: f64,
}

/// Runs the recognizer over a doodle.
pub fn run_doodle(
    d: &Doodle,
    names: &[String],
    blob: &[u8],
    effort: EffortModel,
) -> Result<Vec<Ev>> {
    let lib = Library::from_bytes(blob).map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut rec = Recognizer::new(lib, Some(effort));
    let (samples, _) = log_samples(&d.log);
    let clock = Clock::new(&d.log, &samples);
    Ok(recognize_log(&mut rec, &samples)
        .iter()
        .map(|e| Ev {
            action: names
                .get(usize::from(e.action))
                .cloned()
                .unwrap_or_default(),
            start: clock.time_of(e.start_seq),
            end: clock.time_of(e.end_seq),
            decided: clock.time_of(e.decided_seq),
            time: f64::from(e.time_q) / 127.0,
            weight: f64::from(e.weight_q) / 127.0,
        })
        .collect())
}

/// `eval --verbose`'s account of a doodle: the decision stage's notes on it
/// ([`super::simulate::note_lines`]).
pub(super) fn notes_of(
    d: &Doodle,
    names: &[String],
    blob: &[u8],
    effort: EffortModel,
) -> Result<Vec<NoteLine>> {
    let sim = simulate_log(&d.log, names, blob, Some(effort))?;
    Ok(note_lines(&sim.notes, names, &sim.clock))
}

/// How long spans `a0..a1` and `b0..b1` overlap, s (0 when apart).
pub fn overlap(a0: f64, a1: f64, b0: f64, b1: f64) -> f64 {
    (a1.min(b1) - a0.max(b0)).max(0.0)
}

/// Sequence events that match no label, counted by why.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ExtraEvents {
    /// Same action as a gesture it overlaps whose label already has its event (a split).
    pub split: usize,
    /// Overlaps a gesture, but names another action.
    pub wrong: usize,
    /// Overlaps no gesture (in a pause between them).
    pub spurious: usize,
    /// Overlaps no gesture but handling that plays no action ([`Handling`]).
    pub handled: usize,
}

/// Why a sequence event matched no label.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExtraKind {
    /// A second piece of a gesture whose label already has its event.
    Split,
    /// The wrong action over a gesture.
    Wrong,
    /// Over no gesture.
    Spurious,
    /// Over no gesture, but over handling that plays no action.
    Handled,
}

impl ExtraKind {
    /// Classifies an unmatched event `e` against the sequence's labels and its spans of
    /// `handled` toy.
    pub fn of(e: &Ev, labels: &[Label], handled: &[Label]) -> ExtraKind {
        let over = |l: &&Label| overlap(e.start, e.end, l.start, l.end) > 0.0;
        let mut under = labels.iter().filter(over).peekable();
        if under.peek().is_none() {
            if handled.iter().any(|h| over(&h)) {
                ExtraKind::Handled
            } else {
                ExtraKind::Spurious
            }
        } else if under.any(|l| l.action == e.action) {
            ExtraKind::Split
        } else {
            ExtraKind::Wrong
        }
    }

    /// How `eval --verbose` names it.
    pub fn name(self) -> &'static str {
        match self {
            ExtraKind::Split => "second piece",
            ExtraKind::Wrong => "wrong action",
            ExtraKind::Spurious => "between gestures",
            ExtraKind::Handled => "over handling",
        }
    }
}

impl ExtraEvents {
    /// Counts one event of `kind`.
    pub fn add(&mut self, kind: ExtraKind) {
        match kind {
            ExtraKind::Split => self.split += 1,
            ExtraKind::Wrong => self.wrong += 1,
            ExtraKind::Spurious => self.spurious += 1,
            ExtraKind::Handled => self.handled += 1,
        }
    }
}

/// Precision, recall and F1 of `matched` labels out of `events` reported and `labels` due
/// (a share of nothing is 0).
pub fn prf(matched: usize, events: usize, labels: usize) -> (f64, f64, f64) {
    let p = matched as f64 / events.max(1) as f64;
    let r = matched as f64 / labels.max(1) as f64;
    let f1 = if p + r > 0.0 {
        2.0 * p * r / (p + r)
    } else {
        0.0
    };
    (p, r, f1)
}

/// For each label in order, the event it is matched to: the not yet matched event of its
/// action that overlaps it most (none if no event of its action overlaps it).
pub fn pair_events(labels: &[Label], evs: &[Ev]) -> Vec<Option<usize>> {
    let mut used = vec![false; evs.len()];
    labels
        .iter()
        .map(|l| {
            let best = evs
                .iter()
                .enumerate()
                .filter(|(i, e)| {
                    !used[*i]
                        && e.action == l.action
                        && overlap(e.start, e.end, l.start, l.end) > 0.0
                })
                .max_by(|a, b| {
                    overlap(a.1.start, a.1.end, l.start, l.end)
                        .total_cmp(&overlap(b.1.start, b.1.end, l.start, l.end))
                })
                .map(|(i, _)| i);
            if let Some(i) = best {
                used[i] = true;
            }
            best
        })
        .collect()
}

/// Whether event `ev` got label `l`'s Time and Weight right.
pub(super) fn label_ok(l: &Label, ev: &Ev) -> (bool, bool) {
    (
        (ev.time > 0.0) == (l.time_class == TimeClass::Sudden),
        (ev.weight > 0.0) == (l.weight_class == WeightClass::Strong),
    )
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A sudden-strong label of `action` over `start..end` s.
    pub(crate) fn label(action: &str, start: f64, end: f64) -> Label {
        Label {
            action: action.into(),
            start,
            end,
            time_class: TimeClass::Sudden,
            weight_class: WeightClass::Strong,
        }
    }

    /// An event of `action` over `start..end` s, decided at its end.
    pub(crate) fn ev(action: &str, start: f64, end: f64) -> Ev {
        Ev {
            action: action.into(),
            start,
            end,
            decided: end,
            time: 0.0,
            weight: 0.0,
        }
    }

    #[test]
    fn unmatched_events_are_told_apart() {
        let labels = [label("run", 1.0, 3.0), label("jump", 4.0, 5.0)];
        let handled = [label("lift", 6.0, 7.5)];
        assert_eq!(
            ExtraKind::of(&ev("run", 2.2, 2.9), &labels, &handled),
            ExtraKind::Split
        );
        assert_eq!(
            ExtraKind::of(&ev("punch", 4.5, 4.8), &labels, &handled),
            ExtraKind::Wrong
        );
        // Over the end of the run and the start of the jump: it is a piece of the run.
        assert_eq!(
            ExtraKind::of(&ev("run", 2.5, 4.2), &labels, &handled),
            ExtraKind::Split
        );
        assert_eq!(
            ExtraKind::of(&ev("jump", 3.2, 3.8), &labels, &handled),
            ExtraKind::Spurious
        );
        assert_eq!(
            ExtraKind::of(&ev("jump", 6.2, 7.0), &labels, &handled),
            ExtraKind::Handled
        );
        let mut n = ExtraEvents::default();
        for k in [
            ExtraKind::Split,
            ExtraKind::Split,
            ExtraKind::Spurious,
            ExtraKind::Handled,
        ] {
            n.add(k);
        }
        assert_eq!(
            n,
            ExtraEvents {
                split: 2,
                wrong: 0,
                spurious: 1,
                handled: 1
            }
        );
    }
}
