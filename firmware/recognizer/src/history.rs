//! The recent token runs: what a committed segment's start, end and features are read from.
//!
//! A ring of the last [`HISTORY_RUNS`] runs (STILL runs included), each with its token, its
//! first and last input sample (sequence number and time), and its feature sums
//! ([`crate::features::Accum`]). Runs are addressed by an absolute index that counts every run
//! since the recognizer started (wrapping u32). A match reaching further back than the ring is
//! clipped to the oldest run still held (documented truncation; patterns are ≤ 32 tokens).
//! A STILL run also keeps where the figurine was truly at rest inside it
//! ([`crate::noise::NoiseFloor::quiet`]): its first quiet tick, where the motion before it had
//! settled, and its last, where the motion after it set off. An event is reported from the one
//! to the other, so a slow onset or settle below the "moving" threshold is part of its span.
//! RAM: `HISTORY_RUNS × 296` bytes ≈ 11.6 KiB.

use crate::features::Accum;
use crate::fmath;
use crate::token::{Token, STILL};

/// Runs kept.
pub const HISTORY_RUNS: usize = 40;

/// One token run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Run {
    /// The token.
    pub token: Token,
    /// Input sample (seq, µs) of the run's first tick.
    pub start: (u32, u64),
    /// Input sample (seq, µs) of the run's latest tick.
    pub end: (u32, u64),
    /// Feature sums over the run's ticks.
    pub acc: Accum,
    /// The first quiet tick, as an offset from `start` (see [`Quiet`]).
    pub first_quiet: Quiet,
    /// The last quiet tick, as an offset from `start`.
    pub last_quiet: Quiet,
    /// Sub-movements that began in the run ([`crate::sweep`]); two bytes that were padding.
    pub sweeps: Sweeps,
}

/// Sub-movements that began in a run ([`crate::sweep`]; saturating counts).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Sweeps {
    /// Speed peaks.
    pub peaks: u8,
    /// Bobs: a rise, then a fall.
    pub bobs: u8,
}

impl Sweeps {
    /// None yet.
    pub const NONE: Sweeps = Sweeps { peaks: 0, bobs: 0 };

    /// Adds the sub-movements of ticks that came after these.
    pub fn merge(&mut self, o: Sweeps) {
        self.peaks = self.peaks.saturating_add(o.peaks);
        self.bobs = self.bobs.saturating_add(o.bobs);
    }

    /// How many sub-movements these were: the more of the two counts.
    pub fn count(self) -> u8 {
        self.peaks.max(self.bobs)
    }
}

/// A tick inside a run as its offset from the run's first tick, in input samples;
/// [`Quiet::NONE`] when there is none, or it lies further from the start than the offset
/// reaches (65,534 samples: a rest of over a minute at 1 kHz reports the event from its
/// first moving run). Two bytes, so that a run takes no more room than without them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Quiet(u16);

impl Quiet {
    /// No such tick.
    pub const NONE: Quiet = Quiet(u16::MAX);

    /// Tick `at` (seq, µs) of a run that began at `start`; NONE past the offset's reach.
    fn of(start: (u32, u64), at: (u32, u64)) -> Quiet {
        Quiet(u16::try_from(at.0.wrapping_sub(start.0)).unwrap_or(u16::MAX))
    }

    /// The tick (seq, µs) in a run from `start` to `end`. Its time is interpolated between
    /// theirs by sample count: exact for a steady tracker, within its jitter otherwise.
    fn at(self, start: (u32, u64), end: (u32, u64)) -> Option<(u32, u64)> {
        if self == Quiet::NONE {
            return None;
        }
        let k = u64::from(self.0);
        let n = u64::from(end.0.wrapping_sub(start.0)).max(k).max(1);
        let t = start.1 + end.1.saturating_sub(start.1) * k / n;
        Some((start.0.wrapping_add(u32::from(self.0)), t))
    }
}

impl Run {
    const EMPTY: Run = Run {
        token: STILL,
        start: (0, 0),
        end: (0, 0),
        acc: Accum::new(),
        first_quiet: Quiet::NONE,
        last_quiet: Quiet::NONE,
        sweeps: Sweeps::NONE,
    };

    /// Records a quiet tick `at` (seq, µs) of this run.
    pub fn mark_quiet(&mut self, at: (u32, u64)) {
        let q = Quiet::of(self.start, at);
        if self.first_quiet == Quiet::NONE {
            self.first_quiet = q;
        }
        self.last_quiet = q;
    }

    /// The first quiet tick (seq, µs): where the motion before this rest had settled.
    pub fn settled(&self) -> Option<(u32, u64)> {
        self.first_quiet.at(self.start, self.end)
    }

    /// The last quiet tick (seq, µs): where the motion after this rest set off.
    pub fn set_off(&self) -> Option<(u32, u64)> {
        self.last_quiet.at(self.start, self.end)
    }

    /// How long the figurine had rested in this run by `until` (µs of the input clock),
    /// counted from its first quiet tick: 0 before the motion ahead of it settled. A stroke's
    /// slow tail, under a noisy tracker's floor, makes a STILL run but is no rest.
    pub fn rested_us(&self, until: u64) -> u64 {
        self.settled().map_or(0, |s| until.saturating_sub(s.1))
    }
}

/// Ring of recent runs.
#[derive(Debug, Clone)]
pub struct History {
    runs: [Run; HISTORY_RUNS],
    /// Absolute index of the next run to be opened.
    next: u32,
    /// Number of runs held (≤ HISTORY_RUNS).
    held: u32,
}

impl Default for History {
    fn default() -> Self {
        Self::new()
    }
}

impl History {
    /// An empty history.
    pub const fn new() -> Self {
        History {
            runs: [Run::EMPTY; HISTORY_RUNS],
            next: 0,
            held: 0,
        }
    }

    /// Forgets all runs (indices keep counting).
    pub fn clear(&mut self) {
        self.held = 0;
    }

    /// Opens a new run; returns its absolute index.
    pub fn open(&mut self, token: Token, start: (u32, u64), acc: Accum) -> u32 {
        let idx = self.next;
        if let Some(r) = self.runs.get_mut(idx as usize % HISTORY_RUNS) {
            *r = Run {
                token,
                start,
                end: start,
                acc,
                first_quiet: Quiet::NONE,
                last_quiet: Quiet::NONE,
                sweeps: Sweeps::NONE,
            };
        }
        self.next = self.next.wrapping_add(1);
        self.held = (self.held + 1).min(HISTORY_RUNS as u32);
        idx
    }

    /// Absolute index of the newest run, if any.
    pub fn newest(&self) -> Option<u32> {
        (self.held > 0).then(|| self.next.wrapping_sub(1))
    }

    /// Absolute index of the oldest run held, if any.
    pub fn oldest(&self) -> Option<u32> {
        (self.held > 0).then(|| self.next.wrapping_sub(self.held))
    }

    /// True when run `idx` is still held.
    pub fn holds(&self, idx: u32) -> bool {
        self.next.wrapping_sub(1).wrapping_sub(idx) < self.held
    }

    /// Run `idx`, if still held.
    pub fn get(&self, idx: u32) -> Option<&Run> {
        if !self.holds(idx) {
            return None;
        }
        self.runs.get(idx as usize % HISTORY_RUNS)
    }

    /// The newest run, mutable.
    pub fn newest_mut(&mut self) -> Option<&mut Run> {
        let idx = self.newest()?;
        self.runs.get_mut(idx as usize % HISTORY_RUNS)
    }

    /// The runs `from..=to` that are still held, oldest first. The walk is bounded: a
    /// reversed or stale range costs at most one ring's worth of steps.
    pub fn runs(&self, from: u32, to: u32) -> impl Iterator<Item = &Run> + '_ {
        let mut i = from;
        let mut done = false;
        (0..=HISTORY_RUNS)
            .map_while(move |_| {
                if done {
                    return None;
                }
                let run = self.get(i);
                done = i == to;
                i = i.wrapping_add(1);
                Some(run)
            })
            .flatten()
    }

    /// How far below the lowest rest before it the figurine ended at the end of run `end`, m:
    /// below where run `start` began and below either end of every STILL run before that
    /// which the ring still holds (negative when one of them lies lower; 0 when none is held).
    /// A crouch's descent ends lower than any rest it set off from; a toy set back down after
    /// a lift ends where it rested before. A rest's lower end, because the tokens lag the
    /// motion: a lift's first centimetres are still inside the rest before it.
    pub fn sunk_below_rests(&self, start: u32, end: u32) -> f32 {
        // Heights relative to the end of `end`, walking back run by run.
        let mut h = 0.0f32;
        let mut lowest: Option<f32> = None;
        let mut low = |x: f32| lowest = Some(lowest.map_or(x, |l| fmath::min(l, x)));
        let mut i = end;
        for _ in 0..HISTORY_RUNS {
            let Some(r) = self.get(i) else { break };
            let rest = r.token == STILL && i.wrapping_sub(start) > end.wrapping_sub(start);
            if rest {
                low(h);
            }
            h -= r.acc.rise;
            if rest || i == start {
                low(h);
            }
            i = i.wrapping_sub(1);
        }
        lowest.unwrap_or(0.0)
    }

    /// Sum of the feature accumulators of runs `from..=to` (those still held).
    pub fn accum(&self, from: u32, to: u32) -> Accum {
        let mut acc = Accum::new();
        for r in self.runs(from, to) {
            acc.merge(&r.acc);
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_holds_the_newest_runs() {
        let mut h = History::new();
        assert!(h.newest().is_none());
        for i in 0..100u32 {
            let idx = h.open(i as Token, (i, u64::from(i)), Accum::new());
            assert_eq!(idx, i);
        }
        assert_eq!(h.newest(), Some(99));
        assert_eq!(h.oldest(), Some(100 - HISTORY_RUNS as u32));
        assert!(h.get(59).is_none());
        assert_eq!(h.get(60).unwrap().token, 60);
        let mut a = Accum::new();
        a.n = 3;
        h.newest_mut().unwrap().acc = a;
        assert_eq!(h.accum(98, 99).n, 3);
        h.clear();
        assert!(h.get(99).is_none());
    }

    #[test]
    fn a_descent_is_measured_against_the_lowest_rest_before_it() {
        // Runs as (token, rise m): rest, up 10 cm (its onset 2 cm inside the rest), rest at
        // the top, down 12 cm.
        let mut h = History::new();
        for (token, rise) in [(STILL, 0.02), (1, 0.08), (STILL, 0.0), (2, -0.12)] {
            let mut a = Accum::new();
            a.rise = rise;
            h.open(token, (0, 0), a);
        }
        // From the top it ended 2 cm below where it rested before the lift: the rest's lower
        // end, not the height it had risen to when the rest ended.
        assert!((h.sunk_below_rests(3, 3) - 0.02).abs() < 1e-6);
        // The whole lift began where it rested: no lower than that.
        assert!((h.sunk_below_rests(1, 3) - 0.02).abs() < 1e-6);
        // Ending at the top is 10 cm above the rest before it.
        assert!((h.sunk_below_rests(1, 1) + 0.10).abs() < 1e-6);
        // Runs no longer held tell nothing.
        assert_eq!(h.sunk_below_rests(99, 99), 0.0);
    }

    #[test]
    fn a_run_keeps_its_first_and_last_quiet_ticks() {
        let mut h = History::new();
        h.open(STILL, (1_000, 5_000_000), Accum::new());
        let r = h.newest_mut().unwrap();
        assert_eq!((r.settled(), r.set_off()), (None, None));
        // Not yet settled: no rest at all, however long the run.
        assert_eq!(r.rested_us(5_400_000), 0);
        r.end = (1_010, 5_100_000);
        r.mark_quiet((1_003, 5_030_000));
        // Rested from its first quiet tick on, not from its start.
        assert_eq!(r.rested_us(5_100_000), 70_000);
        r.mark_quiet((1_009, 5_090_000));
        assert_eq!(r.settled(), Some((1_003, 5_030_000)));
        assert_eq!(r.set_off(), Some((1_009, 5_090_000)));
        // Past the offset's reach (over a minute into the rest at 1 kHz): none, never a
        // wrong tick.
        r.end = (71_000, 75_000_000);
        r.mark_quiet((70_000, 74_000_000));
        assert_eq!(r.set_off(), None);
        assert_eq!(r.settled(), Some((1_003, 5_003_000)));
    }
}
