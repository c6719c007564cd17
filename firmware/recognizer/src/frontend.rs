//! Stages 0–3 and 7 wired together: samples in, token runs with feature sums out.
//!
//! The front end validates and resamples samples ([`crate::intake`]), filters
//! ([`crate::filter`]), moves to the object frame ([`crate::frame`]), tokenizes
//! ([`crate::token`]) and accumulates the per-tick feature quantities ([`crate::features`])
//! into the run each tick belongs to, keeping the recent runs in a [`History`]. Ticks of a
//! token candidate are held in a side accumulator until the candidate is confirmed (they open
//! the new run) or dropped (they go to the current run), so run boundaries and feature sums
//! agree exactly. The host's learner and effort trainer use this same front end. Each run
//! also counts the sub-movements that began in it ([`crate::sweep`]), against the tracker's
//! noise: a performance's by [`EVENT_MARGIN`] × its rms, an example's by [`LEARN_MARGIN`] ×
//! ([`Frontend::push_example`]).

use crate::features::{Accum, FeatureExtractor, SPEED};
use crate::filter::SavGol;
use crate::frame::{kinematics, Kinematics};
use crate::history::{History, Sweeps};
use crate::intake::{Accept, Intake, IntakeCounters, Sample};
use crate::sweep::{SweepCounter, EVENT_MARGIN, LEARN_MARGIN};
use crate::token::{Token, TokenStep, Tokenizer, STILL};

/// What one sample did to the run structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrontEvent {
    /// A long gap restarted the pipeline: runs before it must not be joined to later ones.
    Gap,
    /// A new run opened (absolute history index); the previous run is now final.
    Opened {
        /// Absolute run index.
        index: u32,
        /// Its token.
        token: Token,
    },
}

/// Sample → token runs.
#[derive(Debug, Clone, Default)]
pub struct Frontend {
    intake: Intake,
    filter: SavGol,
    features: FeatureExtractor,
    tokenizer: Tokenizer,
    history: History,
    cand: Accum,
    cand_start: (u32, u64),
    cand_end: (u32, u64),
    /// The first and last quiet ticks among the candidate's.
    cand_quiet: Option<((u32, u64), (u32, u64))>,
    sweep: SweepCounter,
    ticks: u32,
    last_tick_us: u64,
}

impl Frontend {
    /// A fresh front end.
    pub const fn new() -> Self {
        Frontend {
            intake: Intake::new(),
            filter: SavGol::new(),
            features: FeatureExtractor::new(),
            tokenizer: Tokenizer::new(),
            history: History::new(),
            cand: Accum::new(),
            cand_start: (0, 0),
            cand_end: (0, 0),
            cand_quiet: None,
            sweep: SweepCounter::new(),
            ticks: 0,
            last_tick_us: 0,
        }
    }

    /// Input counters.
    pub fn counters(&self) -> IntakeCounters {
        self.intake.counters()
    }

    /// Filtered ticks processed.
    pub fn ticks(&self) -> u32 {
        self.ticks
    }

    /// Time of the latest filtered tick, µs.
    pub fn last_tick_us(&self) -> u64 {
        self.last_tick_us
    }

    /// The noise rms of translation (m/s) and rotation (rad/s) learnt at rest so far.
    pub fn noise_rms(&self) -> (f32, f32) {
        self.tokenizer.noise_rms()
    }

    /// The run history.
    pub fn history(&self) -> &History {
        &self.history
    }

    /// Feeds one sample; `on` sees each run opening (at most a few per sample).
    pub fn push(&mut self, s: &Sample, on: impl FnMut(&Self, FrontEvent)) {
        self.push_counting(s, EVENT_MARGIN, on);
    }

    /// [`Frontend::push`] for a sample of an action's example: a rise or dip of the speed
    /// counts as a sub-movement only when it also exceeds [`LEARN_MARGIN`] × the noise rms
    /// learnt so far, so that what the examples require of a performance stands out of the
    /// noise ([`crate::sweep`]).
    pub fn push_example(&mut self, s: &Sample, on: impl FnMut(&Self, FrontEvent)) {
        self.push_counting(s, LEARN_MARGIN, on);
    }

    /// [`Frontend::push`], a sub-movement counting when it also rises or dips by `margin` ×
    /// the noise rms learnt so far.
    fn push_counting(&mut self, s: &Sample, margin: f32, mut on: impl FnMut(&Self, FrontEvent)) {
        match self.intake.push(s) {
            Accept::Rejected => return,
            Accept::Accepted => {}
            Accept::AcceptedAfterGap => {
                self.restart();
                on(self, FrontEvent::Gap);
            }
        }
        while let Some(tick) = self.intake.next_tick() {
            let Some(sm) = self.filter.push(tick) else {
                continue;
            };
            let k = kinematics(&sm);
            let q = self.features.quantities(&k);
            let rise = k.world_v[1] * crate::intake::TICK_S;
            let at = (k.tick.seq, k.tick.sample_t_us);
            self.ticks = self.ticks.saturating_add(1);
            self.last_tick_us = k.tick.t_us;
            let step = self.tokenizer.step(&k);
            // After the step, the current token is the new one's (a TURN marker's rotation).
            let moving = self.tokenizer.current().is_some_and(|t| t != STILL);
            let tokenizer = &self.tokenizer;
            // The speed is the features' own |world v| (one square root a tick, not two).
            let began = self.sweep.step(q[SPEED], k.world_v[1], moving, || {
                margin * tokenizer.noise_rms().0
            });
            // Only a tick that may belong to a STILL run is checked (none of a moving run's).
            let may_rest = self.tokenizer.current() == Some(STILL) || step != TokenStep::Run;
            let quiet = may_rest && self.tokenizer.quiet(&k);
            match step {
                TokenStep::Run => self.extend_current(&q, rise, &k, at, quiet, began),
                TokenStep::Candidate => {
                    if self.cand.n == 0 {
                        self.cand_start = at;
                    }
                    self.sweep.defer(began);
                    self.cand_end = at;
                    self.cand.add(&q, rise);
                    self.cand.travel(k.world_v, k.w);
                    self.note_cand_quiet(at, quiet);
                }
                TokenStep::BlipMerged { starts_candidate } => {
                    let blip = core::mem::take(&mut self.cand);
                    let blip_end = self.cand_end;
                    let blip_quiet = self.cand_quiet.take();
                    let blip_sweeps = self.sweep.take_deferred();
                    if let Some(r) = self.history.newest_mut() {
                        r.acc.merge(&blip);
                        r.sweeps.merge(blip_sweeps);
                        r.end = blip_end;
                        if let (STILL, Some((first, last))) = (r.token, blip_quiet) {
                            r.mark_quiet(first);
                            r.mark_quiet(last);
                        }
                    }
                    if starts_candidate {
                        self.sweep.defer(began);
                        self.cand_start = at;
                        self.cand_end = at;
                        self.cand.add(&q, rise);
                        self.cand.travel(k.world_v, k.w);
                        self.note_cand_quiet(at, quiet);
                    } else {
                        self.extend_current(&q, rise, &k, at, quiet, began);
                    }
                }
                TokenStep::NewToken { token } => {
                    let start = if self.cand.n > 0 { self.cand_start } else { at };
                    let mut acc = core::mem::take(&mut self.cand);
                    let cand_quiet = self.cand_quiet.take();
                    let mut sweeps = self.sweep.take_deferred();
                    sweeps.merge(began);
                    acc.add(&q, rise);
                    if token != STILL {
                        acc.travel(k.world_v, k.w);
                    }
                    let index = self.history.open(token, start, acc);
                    if let Some(r) = self.history.newest_mut() {
                        r.end = at;
                        r.sweeps = sweeps;
                        if token == STILL {
                            if let Some((first, last)) = cand_quiet {
                                r.mark_quiet(first);
                                r.mark_quiet(last);
                            }
                            if quiet {
                                r.mark_quiet(at);
                            }
                        }
                    }
                    on(self, FrontEvent::Opened { index, token });
                }
            }
        }
    }

    fn extend_current(
        &mut self,
        q: &[f32; crate::features::QUANTITIES],
        rise: f32,
        k: &Kinematics,
        at: (u32, u64),
        quiet: bool,
        began: Sweeps,
    ) {
        if let Some(r) = self.history.newest_mut() {
            r.acc.add(q, rise);
            r.sweeps.merge(began);
            if r.token != STILL {
                r.acc.travel(k.world_v, k.w);
            } else if quiet {
                r.mark_quiet(at);
            }
            r.end = at;
        }
    }

    /// Notes a candidate tick `at`, quiet or not: the candidate's ticks may yet join a STILL
    /// run.
    fn note_cand_quiet(&mut self, at: (u32, u64), quiet: bool) {
        if quiet {
            let first = self.cand_quiet.map_or(at, |(f, _)| f);
            self.cand_quiet = Some((first, at));
        }
    }

    fn restart(&mut self) {
        self.sweep = SweepCounter::new();
        self.filter.reset();
        self.features.reset();
        self.tokenizer.restart();
        self.history.clear();
        self.cand = Accum::new();
        self.cand_quiet = None;
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::noise::tests::Noise;
    use core::f32::consts::PI;
    use std::vec::Vec;

    /// The toy moved 30 cm across in `pushes` minimum-jerk pushes over 0.8 s, lifted 4 cm and
    /// set down in each, after 2 s at rest and before 1.5 s more, at 120 Hz: a hand's 9 Hz
    /// tremor of `tremor` m along the motion (half as much up), each coordinate jittered
    /// uniformly by ±`jitter` m; the rest lets the front end learn that noise.
    fn handled(pushes: u32, jitter: f32, tremor: f32, seed: u32) -> Vec<Sample> {
        let mut noise = Noise(u64::from(seed));
        let mut jittered = move || jitter * (2.0 * noise.uniform() - 1.0);
        let n = pushes as f32;
        (0..(4.3 * 120.0) as u32)
            .map(|i| {
                let t = i as f32 / 120.0;
                let along = ((t - 2.0) / 0.8).clamp(0.0, 1.0) * n;
                let done = libm::floorf(along).min(n - 1.0);
                let s = along - done;
                let reach = (done + s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)) / n;
                let lift = 0.04 * libm::sinf(PI * s);
                let shake = tremor * libm::sinf(2.0 * PI * 9.0 * t + seed as f32);
                Sample {
                    seq: i,
                    t_us: u64::from(i) * 1_000_000 / 120,
                    pos: [
                        0.3 * reach + shake + jittered(),
                        1.0 + lift + 0.5 * shake + jittered(),
                        jittered(),
                    ],
                    quat: [1.0, 0.0, 0.0, 0.0],
                }
            })
            .collect()
    }

    /// The sub-movements counted over every run of `samples`, each rise or dip held to
    /// `margin` × the learnt noise rms.
    fn counted(samples: &[Sample], margin: f32) -> u8 {
        let mut f = Frontend::new();
        for s in samples {
            f.push_counting(s, margin, |_, _| {});
        }
        let h = f.history();
        let (Some(from), Some(to)) = (h.oldest(), h.newest()) else {
            return 0;
        };
        let mut made = Sweeps::NONE;
        h.runs(from, to).for_each(|r| made.merge(r.sweeps));
        made.count()
    }

    #[test]
    fn a_performance_counts_its_pushes_out_of_the_noise() {
        // A 2 mm tremor ripples a carry's one sweep: counted raw, the ripple makes pushes of
        // its own; at the quiet level fewer, and never more.
        let (mut raw, mut quiet) = (0, 0);
        for seed in 1..=8 {
            let carry = handled(1, 0.0005, 0.002, seed);
            let (r, q) = (counted(&carry, 0.0), counted(&carry, EVENT_MARGIN));
            assert!((1..=r).contains(&q), "seed {seed}: {q}, raw {r}");
            raw += u32::from(r);
            quiet += u32::from(q);
        }
        assert!(quiet + 3 <= raw, "{quiet} pushes counted, raw {raw}");
        // Three pushes under the same noise are three, and a clean carry one, either way.
        for seed in 1..=8 {
            assert!(counted(&handled(3, 0.0005, 0.002, seed), EVENT_MARGIN) >= 3);
        }
        assert_eq!(counted(&handled(1, 0.0, 0.0, 1), EVENT_MARGIN), 1);
        assert_eq!(counted(&handled(1, 0.0, 0.0, 1), 0.0), 1);
    }
}
