//! The recent token runs: what a committed segment's start, end and features are read from.
//!
//! A ring of the last [`HISTORY_RUNS`] runs (STILL runs included), each with its token, its
//! first and last input sample (sequence number and time), and its feature sums
//! ([`crate::features::Accum`]). Runs are addressed by an absolute index that counts every run
//! since the recognizer started (wrapping u32). A match reaching further back than the ring is
//! clipped to the oldest run still held (documented truncation; patterns are ≤ 32 tokens).
//! RAM: `HISTORY_RUNS × 280` bytes ≈ 10.9 KiB.

use crate::features::Accum;
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
}

impl Run {
    const EMPTY: Run = Run {
        token: STILL,
        start: (0, 0),
        end: (0, 0),
        acc: Accum::new(),
    };
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
}
