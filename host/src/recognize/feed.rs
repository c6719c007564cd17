//! Pose logs into the recognizer, through the wire quantisation.
//!
//! Host simulation must see exactly the numbers the MCU sees, so every log sample goes through
//! [`WireFeed::wire_sample`]: quantised into a `figurine_protocol::Pose` (0.1 mm, smallest-three
//! quaternion, u32 µs, u16 seq) and decoded back with the same routines the firmware uses
//! (including the wrap-extending time and sequence unwrappers). Samples the wire cannot carry
//! (NaN, beyond ±100 m, zero quaternion) are dropped here and counted, as the link would.

use anyhow::Result;
use figurine_protocol::pose::{Pose, SeqUnwrapper, TimeUnwrapper};
use figurine_recognizer::features::Accum;
use figurine_recognizer::frontend::{FrontEvent, Frontend};
use figurine_recognizer::history::Run;
use figurine_recognizer::noise::{ON_FACTOR, V_FLOOR_M_S, W_FLOOR_RAD_S};
use figurine_recognizer::token::STILL;
use figurine_recognizer::{ActionEvent, EffortModel, Library, Note, Recognizer, Sample};

use crate::events::fold_revision;
use crate::poselog::PoseLog;

/// Turns log samples into device samples, as the link would deliver them.
#[derive(Debug, Default, Clone)]
pub struct WireFeed {
    time: TimeUnwrapper,
    seq: SeqUnwrapper,
    /// Log samples the wire could not carry.
    pub unsendable: u64,
}

impl WireFeed {
    /// Quantises log sample `index` (its seq is `index` mod 2¹⁶ on the wire) and decodes it as
    /// the firmware does. `None` if the wire cannot carry it.
    pub fn wire_sample(
        &mut self,
        index: usize,
        t_s: f64,
        pos: [f64; 3],
        quat: [f64; 4],
    ) -> Option<Sample> {
        match Pose::quantize(index as u16, t_s, pos, quat) {
            Ok(p) => Some(Sample {
                seq: self.seq.unwrap(p.seq),
                t_us: self.time.unwrap(p.t_us),
                pos: p.position_m(),
                quat: p.orientation(),
            }),
            Err(_) => {
                self.unsendable += 1;
                None
            }
        }
    }
}

/// The device samples of a whole log, with the index of the log sample each came from.
pub fn log_samples(log: &PoseLog) -> (Vec<(usize, Sample)>, u64) {
    let mut feed = WireFeed::default();
    let out = log
        .samples
        .iter()
        .enumerate()
        .filter_map(|(i, s)| feed.wire_sample(i, s.t, s.pos, s.quat).map(|x| (i, x)))
        .collect();
    (out, feed.unsendable)
}

/// Maps device sequence numbers back to log times (seconds on the log's clock).
#[derive(Debug, Clone)]
pub struct Clock {
    first_seq: u32,
    times: Vec<f64>,
}

impl Clock {
    /// The clock of a log whose samples were fed with [`log_samples`].
    pub fn new(log: &PoseLog, samples: &[(usize, Sample)]) -> Self {
        let first_seq = samples.first().map_or(0, |(_, s)| s.seq);
        let first_idx = samples.first().map_or(0, |(i, _)| *i);
        Clock {
            first_seq: first_seq.wrapping_sub(first_idx as u32),
            times: log.samples.iter().map(|s| s.t).collect(),
        }
    }

    /// Log time of the sample with device sequence number `seq`.
    pub fn time_of(&self, seq: u32) -> f64 {
        let i = seq.wrapping_sub(self.first_seq) as usize;
        self.times.get(i).copied().unwrap_or(f64::NAN)
    }
}

/// Runs the recognizer over a whole log; returns the actions in time order, each revision
/// ([`ActionEvent::revises`]) in place of the event it revises (so an event carries the
/// decision time of its last version).
pub fn recognize_log(rec: &mut Recognizer<'_>, samples: &[(usize, Sample)]) -> Vec<ActionEvent> {
    let mut events = Vec::new();
    for (_, s) in samples {
        rec.push(s, |e| fold_revision(&mut events, e, e.revises));
    }
    rec.flush(|e| fold_revision(&mut events, e, e.revises));
    events
}

/// [`recognize_log`], and the decision stage's notes on the matches it dropped or re-read
/// ([`figurine_recognizer::note`]), in the order they were made.
pub fn recognize_log_noted(
    rec: &mut Recognizer<'_>,
    samples: &[(usize, Sample)],
) -> (Vec<ActionEvent>, Vec<Note>) {
    let mut events = Vec::new();
    let mut notes = Vec::new();
    for (_, s) in samples {
        rec.push_noted(
            s,
            |e| fold_revision(&mut events, e, e.revises),
            |n| notes.push(n),
        );
    }
    rec.flush_noted(
        |e| fold_revision(&mut events, e, e.revises),
        |n| notes.push(n),
    );
    (events, notes)
}

/// The events each library's recognizer reports on `log`, as [`recognize_log`] gives them
/// (the log is quantised once and fed to every library; `eval rest` counts them).
pub fn log_events(
    log: &PoseLog,
    blobs: &[&[u8]],
    effort: EffortModel,
) -> Result<Vec<Vec<ActionEvent>>> {
    let (samples, _) = log_samples(log);
    blobs
        .iter()
        .map(|blob| {
            let lib = Library::from_bytes(blob)
                .map_err(|e| anyhow::anyhow!("library blob refused: {e}"))?;
            let mut rec = Recognizer::new(lib, Some(effort));
            Ok(recognize_log(&mut rec, &samples))
        })
        .collect()
}

/// All token runs of a log (STILL included), in order, with their feature sums and their
/// sub-movements counted as an example's are ([`Frontend::push_example`]).
pub fn log_runs(samples: &[(usize, Sample)]) -> Vec<Run> {
    log_runs_and_noise(samples).0
}

/// What a log that read as no motion at all would have needed, in words: the least stroke
/// (cm/s) and twist (°/s) that stand out — the fixed floors, or [`ON_FACTOR`] × the noise the
/// front end learnt from the log (`lin_rms` m/s, `rot_rms` rad/s, from
/// [`log_runs_and_noise`]).
pub fn nothing_moved_words(lin_rms: f32, rot_rms: f32) -> String {
    format!(
        "nothing moved: a stroke must pass {:.1} cm/s or a twist {:.0}°/s — the floors, or \
         {ON_FACTOR} × the tracker's noise the device learnt from the stream ({:.1} cm/s, \
         {:.0}°/s rms); play bigger or faster",
        100.0 * V_FLOOR_M_S.max(ON_FACTOR * lin_rms),
        W_FLOOR_RAD_S.max(ON_FACTOR * rot_rms).to_degrees(),
        100.0 * lin_rms,
        rot_rms.to_degrees()
    )
}

/// [`log_runs`], and the tracker's noise the front end learnt from the log by its end: rms
/// of translation (m/s) and rotation (rad/s), as `Frontend::noise_rms` gives them.
pub fn log_runs_and_noise(samples: &[(usize, Sample)]) -> (Vec<Run>, (f32, f32)) {
    let mut front = Frontend::new();
    let mut runs = Vec::new();
    for (_, s) in samples {
        front.push_example(s, |f, ev| {
            if let FrontEvent::Opened { index, .. } = ev {
                if let Some(prev) = f.history().get(index.wrapping_sub(1)) {
                    runs.push(*prev);
                }
            }
        });
    }
    if let Some(last) = front
        .history()
        .newest()
        .and_then(|i| front.history().get(i))
    {
        runs.push(*last);
    }
    // A gap clears the history, so consecutive duplicates cannot arise; keep order as seen.
    (runs, front.noise_rms())
}

/// The runs of a one-performance log's gesture, through the wire as the device sees them
/// ([`gesture_runs`]); empty without motion.
pub fn log_gesture(log: &PoseLog) -> Vec<Run> {
    let (samples, _) = log_samples(log);
    gesture_runs(&log_runs(&samples)).to_vec()
}

/// Feature sums over the gesture of a one-performance log (its runs from the first to the
/// last motion); None without motion.
pub fn gesture_accum(log: &PoseLog) -> Option<Accum> {
    let g = log_gesture(log);
    let first = g.first()?.acc;
    Some(g.iter().skip(1).fold(first, |mut acc, r| {
        acc.merge(&r.acc);
        acc
    }))
}

/// The runs of a one-gesture log between its first and last motion (leading and trailing
/// STILL removed).
pub fn gesture_runs(runs: &[Run]) -> &[Run] {
    let first = runs.iter().position(|r| r.token != STILL);
    let last = runs.iter().rposition(|r| r.token != STILL);
    match (first, last) {
        (Some(a), Some(b)) => &runs[a..=b],
        _ => &[],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recognize::simulate::{load_effort, load_library};
    use crate::synth::{gesture, rest_log, Action, Knobs, Range, RestKind, RestSpec, TrackerLevel};

    fn shipped() -> (Vec<u8>, EffortModel) {
        let (_, blob) = load_library(None).unwrap();
        (blob, load_effort(None).unwrap())
    }

    #[test]
    fn a_gesture_raises_an_event_and_a_table_rest_none() {
        let (blob, effort) = shipped();
        let d = gesture(
            3,
            &Knobs::canonical(),
            Action::Jump,
            "sudden-strong".parse().unwrap(),
        );
        let ev = log_events(&d.log, &[&blob], effort).unwrap();
        assert!(!ev[0].is_empty(), "a jump raised no event");
        let spec = RestSpec {
            seconds: 120.0,
            kind: Some(RestKind::Table),
            tracker: TrackerLevel::by_name("lighthouse"),
            rate_hz: Some(Range::fixed(240.0)),
            knobs: Knobs::default(),
        };
        let r = rest_log(5, &spec);
        let ev = log_events(&r.log, &[&blob, &blob], effort).unwrap();
        assert_eq!(ev.len(), 2);
        assert!(ev.iter().all(|e| e.is_empty()), "{ev:?}");
    }
}
