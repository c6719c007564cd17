//! Stages 0–3 and 7 wired together: samples in, token runs with feature sums out.
//!
//! The front end validates and resamples samples ([`crate::intake`]), filters
//! ([`crate::filter`]), moves to the object frame ([`crate::frame`]), tokenizes
//! ([`crate::token`]) and accumulates the per-tick feature quantities ([`crate::features`])
//! into the run each tick belongs to, keeping the recent runs in a [`History`]. Ticks of a
//! token candidate are held in a side accumulator until the candidate is confirmed (they open
//! the new run) or dropped (they go to the current run), so run boundaries and feature sums
//! agree exactly. The host's learner and effort trainer use this same front end.

use crate::features::{Accum, FeatureExtractor};
use crate::filter::SavGol;
use crate::frame::{kinematics, Kinematics};
use crate::history::History;
use crate::intake::{Accept, Intake, IntakeCounters, Sample};
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
    pub fn push(&mut self, s: &Sample, mut on: impl FnMut(&Self, FrontEvent)) {
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
            // Only a tick that may belong to a STILL run is checked (none of a moving run's).
            let may_rest = self.tokenizer.current() == Some(STILL) || step != TokenStep::Run;
            let quiet = may_rest && self.tokenizer.quiet(&k);
            match step {
                TokenStep::Run => self.extend_current(&q, rise, &k, at, quiet),
                TokenStep::Candidate => {
                    if self.cand.n == 0 {
                        self.cand_start = at;
                    }
                    self.cand_end = at;
                    self.cand.add(&q, rise);
                    self.cand.travel(k.world_v, k.w);
                    self.note_cand_quiet(at, quiet);
                }
                TokenStep::BlipMerged { starts_candidate } => {
                    let blip = core::mem::take(&mut self.cand);
                    let blip_end = self.cand_end;
                    let blip_quiet = self.cand_quiet.take();
                    if let Some(r) = self.history.newest_mut() {
                        r.acc.merge(&blip);
                        r.end = blip_end;
                        if let (STILL, Some((first, last))) = (r.token, blip_quiet) {
                            r.mark_quiet(first);
                            r.mark_quiet(last);
                        }
                    }
                    if starts_candidate {
                        self.cand_start = at;
                        self.cand_end = at;
                        self.cand.add(&q, rise);
                        self.cand.travel(k.world_v, k.w);
                        self.note_cand_quiet(at, quiet);
                    } else {
                        self.extend_current(&q, rise, &k, at, quiet);
                    }
                }
                TokenStep::NewToken { token } => {
                    let start = if self.cand.n > 0 { self.cand_start } else { at };
                    let mut acc = core::mem::take(&mut self.cand);
                    let cand_quiet = self.cand_quiet.take();
                    acc.add(&q, rise);
                    if token != STILL {
                        acc.travel(k.world_v, k.w);
                    }
                    let index = self.history.open(token, start, acc);
                    if let Some(r) = self.history.newest_mut() {
                        r.end = at;
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
    ) {
        if let Some(r) = self.history.newest_mut() {
            r.acc.add(q, rise);
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
        self.filter.reset();
        self.features.reset();
        self.tokenizer.restart();
        self.history.clear();
        self.cand = Accum::new();
        self.cand_quiet = None;
    }
}
