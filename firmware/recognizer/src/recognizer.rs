//! The whole recognizer: samples in, [`ActionEvent`]s out.
//!
//! Front end (stages 0–3, 7) → automata over the library (5) → segment decision (6) → effort
//! classification (8) at commit time. No allocation, no clock: every time comes in with the
//! samples. RAM (see `capacities` in the crate docs): front end ≈ 11 KiB, automata 1.75 KiB,
//! effort model 0.6 KiB, the last event (open to continuation, [`crate::follow`]), the state
//! before a provisional report and the last stand-alone phrase's nearest action 0.6 KiB —
//! 16.4 KiB in all (16,744 B by `size_of`, measured by a test) with 32 actions loaded.

use crate::alignment::{prefix_cost, FULL};
use crate::automaton::{best_start, prefix_alive, top_level, MatcherBank, Matches};
use crate::bayes::{quantise, EffortModel};
use crate::extent::{far_enough, noise_reach, span_extent};
use crate::features::segment_features;
use crate::follow::{follow, Follow, Held};
use crate::frontend::{FrontEvent, Frontend};
use crate::history::{History, HISTORY_RUNS};
use crate::intake::{IntakeCounters, Sample, TICK_S};
use crate::nearest::{nearest_action, reread, whole_phrase, Nearest, OPEN_PHRASE_US};
use crate::note::{Note, Why};
use crate::pattern::{Library, MAX_ACTIONS};
use crate::segment::{
    edits_fit, Candidate, Decider, Decision, BRIEF_TURN_RAD, CONTINUE_US, GAPPED_HOLD_US,
    LONG_PAUSE_US, MIN_ACTION_US, PAUSE_US,
};
use crate::shape::{shape_cost, shape_of};
use crate::token::{Token, STILL};

/// Most token runs one sample can open: a sample closes at most `MAX_GAP_US / TICK_US` = 25
/// ticks, and a tick opens at most one run.
pub const MAX_RUNS_PER_SAMPLE: usize =
    (crate::intake::MAX_GAP_US / crate::intake::TICK_US) as usize + 2;

/// A recognised action, as the device reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ActionEvent {
    /// Action index in the loaded library.
    pub action: u8,
    /// Sequence number of the first sample of the segment.
    pub start_seq: u32,
    /// Time of that sample, µs.
    pub start_us: u64,
    /// Sequence number of the last sample of the segment.
    pub end_seq: u32,
    /// Time of that sample, µs.
    pub end_us: u64,
    /// Laban Time Lt quantised: value = q / 127, > 0 sudden.
    pub time_q: i8,
    /// Laban Weight Lw quantised: value = q / 127, > 0 strong.
    pub weight_q: i8,
    /// Edit distance of the match, whole edits (a near substitution counts half; rounded up).
    pub distance: u8,
    /// Sequence number of the sample at which the decision was taken.
    pub decided_seq: u32,
    /// Time of that sample, µs (decision latency = this − `end_us`).
    pub decided_us: u64,
    /// This event revises the previous one, which a consumer replaces with it: what came
    /// after a short pause extended it — the next cycles of a cyclic action, the second piece
    /// of a one-shot one, or its rest ([`crate::follow`]; same action and start, a later end,
    /// effort and distance over all of it) — or a longer action took over a candidate that
    /// had been reported early while it might still be part of one (a run's strides that
    /// turned out to be a punch held at full reach).
    pub revises: bool,
}

/// Running statistics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Input validation counters.
    pub intake: IntakeCounters,
    /// Filtered 100 Hz ticks processed.
    pub ticks: u32,
    /// Non-STILL tokens fed to the automata (replays included).
    pub tokens: u32,
    /// Events emitted.
    pub events: u32,
}

/// The online recognizer over a borrowed library blob (e.g. in flash).
#[derive(Debug, Clone)]
pub struct Recognizer<'lib> {
    library: Library<'lib>,
    effort: Option<EffortModel>,
    front: Frontend,
    bank: MatcherBank,
    decider: Decider,
    floor: u32,
    /// Where a stand-alone phrase ([`nearest_action`]) may begin at the earliest: after the
    /// last event emitted (a match too brief to emit leaves it), and whether it is a phrase
    /// boundary of its own — where the stream began, a gap cut it, or a long pause passed.
    phrase_floor: (u32, bool),
    /// [`Self::phrase_floor`] as it was before the provisional report, if one is out: the
    /// reported candidate's phrase begins after it.
    report_floor: (u32, bool),
    tokens: u32,
    events: u32,
    now_us: u64,
    now_seq: u32,
    held: Option<Held>,
    /// The pending candidate already reported while it may still change, with the held event
    /// as it was before the report and whether the report continued it.
    provisional: Option<(Candidate, Option<Held>, bool)>,
    /// The STILL run last checked for a longer action in progress, and the answer.
    hold: Option<(u32, bool)>,
    /// The STILL run after which the phrase before it was last offered to [`nearest_action`],
    /// and the answer (None once acted on).
    nearest: Option<(u32, Option<Nearest>)>,
}

impl<'lib> Recognizer<'lib> {
    /// A recognizer for `library`; without an effort model Lt = Lw = 0.
    pub fn new(library: Library<'lib>, effort: Option<EffortModel>) -> Self {
        Recognizer {
            library,
            effort,
            front: Frontend::new(),
            bank: MatcherBank::new(),
            decider: Decider::new(),
            floor: 0,
            phrase_floor: (0, true),
            report_floor: (0, true),
            tokens: 0,
            events: 0,
            now_us: 0,
            now_seq: 0,
            held: None,
            provisional: None,
            hold: None,
            nearest: None,
        }
    }

    /// Replaces the library (e.g. after an upload); partial matches are dropped.
    pub fn set_library(&mut self, library: Library<'lib>) {
        self.library = library;
        self.restart_matching();
    }

    /// Replaces the effort model.
    pub fn set_effort(&mut self, effort: Option<EffortModel>) {
        self.effort = effort;
    }

    /// Statistics so far.
    pub fn stats(&self) -> Stats {
        Stats {
            intake: self.front.counters(),
            ticks: self.front.ticks(),
            tokens: self.tokens,
            events: self.events,
        }
    }

    fn restart_matching(&mut self) {
        self.bank.reset();
        self.decider.clear();
        self.provisional = None;
        self.floor = self
            .front
            .history()
            .newest()
            .map_or(0, |n| n.wrapping_add(1));
        self.phrase_floor = (self.floor, true);
    }

    /// Feeds one sample; `emit` receives each action committed by it (in time order).
    pub fn push(&mut self, s: &Sample, emit: impl FnMut(ActionEvent)) {
        self.push_to(s, &mut Quiet(emit));
    }

    /// [`Self::push`], and `note` receives why each match committed by the sample was dropped
    /// or reported as another action ([`crate::note`]); the events are the same.
    pub fn push_noted(
        &mut self,
        s: &Sample,
        emit: impl FnMut(ActionEvent),
        note: impl FnMut(Note),
    ) {
        self.push_to(s, &mut Noted { event: emit, note });
    }

    fn push_to(&mut self, s: &Sample, out: &mut impl Sink) {
        self.now_us = s.t_us;
        self.now_seq = s.seq;
        let mut opened: [Option<(u32, Token)>; MAX_RUNS_PER_SAMPLE] = [None; MAX_RUNS_PER_SAMPLE];
        let mut n_opened = 0usize;
        let mut gap = false;
        self.front.push(s, |_, ev| match ev {
            FrontEvent::Gap => gap = true,
            FrontEvent::Opened { index, token } => {
                if let Some(slot) = opened.get_mut(n_opened) {
                    *slot = Some((index, token));
                    n_opened += 1;
                }
            }
        });
        if gap {
            // Runs before the gap are gone from history: commit what can be committed.
            self.decider.clear();
            self.bank.reset();
            self.provisional = None;
            self.floor = self.front.history().oldest().unwrap_or(0);
            self.phrase_floor = (self.floor, true);
        }
        for (index, token) in opened.iter().flatten().copied() {
            if token != STILL {
                self.feed_from(index, out);
            }
        }
        // Stillness: commit after a short pause, forget partial matches after a long one.
        let hist = self.front.history();
        let newest = hist.newest();
        if let Some(r) = newest.and_then(|i| hist.get(i)) {
            if r.token == STILL {
                let still = self.front.last_tick_us().saturating_sub(r.start.1);
                // The first sample of the pause that may commit: nothing moves during a pause,
                // so what is checked then holds for all of it.
                let mut first = false;
                let longer = match (self.decider.pending(), newest) {
                    (Some(p), Some(run)) if (PAUSE_US..GAPPED_HOLD_US).contains(&still) => {
                        match self.hold {
                            Some((r, v)) if r == run => v,
                            _ => {
                                let v = self.longer_in_progress(&p);
                                self.hold = Some((run, v));
                                first = true;
                                v
                            }
                        }
                    }
                    _ => false,
                };
                if let Decision::Commit(c) = self.decider.stillness(still, longer) {
                    let (floor, bounds) = if self.provisional.is_some() {
                        self.report_floor
                    } else {
                        self.phrase_floor
                    };
                    let c = newest
                        .and_then(|run| {
                            whole_phrase(
                                &self.library,
                                self.front.history(),
                                floor,
                                bounds,
                                run.wrapping_sub(1),
                                &c,
                            )
                        })
                        .unwrap_or(c);
                    self.commit(c, out);
                    // What moved after it while it was held (a turn begun while a run's match
                    // waited for its next stride; a crouch right after a wave's last stroke) is
                    // read afresh, as after a commit at a token.
                    self.feed_from(self.floor, out);
                } else if let Some(p) = self.decider.pending().filter(|p| longer || p.cyclic) {
                    // Held for a longer action that may yet take it over, or for the next
                    // cycle of a cyclic one: reported after the usual pause (weighed once per
                    // pause, not on every sample of it), and revised if it is taken over or
                    // goes on.
                    if first {
                        self.report_provisional(p, out);
                    }
                } else if still >= LONG_PAUSE_US && self.decider.pending().is_none() {
                    self.restart_matching();
                }
                // A stand-alone gesture no action matched closely enough: its nearest action,
                // if near (once per pause).
                let idle = self.decider.pending().is_none() && self.provisional.is_none();
                if let (true, true, Some(run)) = (still >= PAUSE_US, idle, newest) {
                    let closed = still >= OPEN_PHRASE_US;
                    let found = match self.nearest {
                        // Weighed again once, when the pause closes an open phrase.
                        Some((r, n)) if r == run && !(closed && n.is_some_and(|n| n.open)) => n,
                        _ => {
                            let n = self.nearest_to(run.wrapping_sub(1), closed);
                            self.nearest = Some((run, n));
                            n
                        }
                    };
                    if let Some(Nearest {
                        candidate: Some(c),
                        open: false,
                    }) = found
                    {
                        self.nearest = Some((run, None));
                        out.note(|| self.note_of(&c, Why::Nearest));
                        self.commit(c, out);
                    }
                }
                // As long as its action's examples held still inside, and no shorter.
                let keep = self.held.map_or(CONTINUE_US, |h| {
                    CONTINUE_US.max(self.library.hold_us(usize::from(h.action)))
                });
                if still >= keep {
                    self.held = None;
                }
            }
        }
        // Nor once its runs are leaving the history. (A next cycle of many runs — a walk's
        // two hops — is still under way well past a few runs; what moved in between is
        // checked by `follow`.)
        if let (Some(h), Some(n)) = (self.held, newest) {
            if n.wrapping_sub(h.end_run) >= HISTORY_RUNS as u32 {
                self.held = None;
            }
        }
    }

    /// Whether another action's match began with `p` (its own first part skipped) and is still
    /// under way: then a pause after `p` is a hold inside that longer gesture — a punch held at
    /// full reach after its forward stroke. When `p` needed a whole edit, a match under way
    /// that is not exact but costs less than `p` ([`prefix_cost`]) counts too, begun with `p`
    /// or at its second token: a crouch held low, whose descent a jump explained by taking a
    /// sideways wobble before it as its lead-in and leaving its hop out.
    // Once per pause at most: kept out of the per-sample path (flash, not speed).
    #[cold]
    #[inline(never)]
    fn longer_in_progress(&self, p: &Candidate) -> bool {
        // The moving runs from the floor to the newest, oldest first.
        let hist = self.front.history();
        let Some(newest) = hist.newest() else {
            return false;
        };
        let mut tok = [STILL; HISTORY_RUNS];
        let mut n = 0usize;
        let mut at_start = None;
        let mut i = self.floor;
        for _ in 0..2 * HISTORY_RUNS {
            if let Some(r) = hist.get(i).filter(|r| r.token != STILL) {
                if i == p.start {
                    at_start = Some(n);
                }
                if let Some(t) = tok.get_mut(n) {
                    *t = r.token;
                    n += 1;
                }
            }
            if i == newest {
                break;
            }
            i = i.wrapping_add(1);
        }
        let Some(ps) = at_start else { return false };
        let moving = tok.get(..n).unwrap_or(&[]);
        // When `p` itself needed a whole edit, another action that explains the same tokens
        // more cheaply and is not finished is as good a reason to wait: a crouch held low
        // after going down with a wobble, where a jump without its hop matched the descent.
        let tolerance = if p.cost >= FULL { p.cost - 1 } else { 0 };
        let alive_from = |from: usize, skip_first: bool| {
            let tokens = moving.get(from..).unwrap_or(&[]);
            under_way(&self.library, p.action, tokens, skip_first, tolerance)
        };
        // Begun with the pending candidate, but without its own first part; or, tolerantly,
        // with it or one token into it.
        alive_from(ps, true)
            || (tolerance > 0 && (alive_from(ps, false) || alive_from(ps + 1, false)))
    }

    fn emit_held(&mut self, h: Held, revises: bool, out: &mut impl Sink) {
        let (lt, lw) = match &self.effort {
            Some(m) => m.classify(&segment_features(&h.acc)),
            None => (0.0, 0.0),
        };
        out.event(ActionEvent {
            action: h.action,
            start_seq: h.start.0,
            start_us: h.start.1,
            end_seq: h.end.0,
            end_us: h.end.1,
            time_q: quantise(lt),
            weight_q: quantise(lw),
            distance: h.distance,
            decided_seq: self.now_seq,
            decided_us: self.now_us,
            revises,
        });
        self.events = self.events.saturating_add(1);
    }

    /// Commits the pending candidate, if any (end of stream); then, if no event took the
    /// stream's last phrase, reports its nearest action as after a pause (a log that ends
    /// right after a gesture no action matched closely keeps that gesture).
    pub fn flush(&mut self, emit: impl FnMut(ActionEvent)) {
        self.flush_to(&mut Quiet(emit));
    }

    /// [`Self::flush`], with notes as [`Self::push_noted`] gives them.
    pub fn flush_noted(&mut self, emit: impl FnMut(ActionEvent), note: impl FnMut(Note)) {
        self.flush_to(&mut Noted { event: emit, note });
    }

    fn flush_to(&mut self, out: &mut impl Sink) {
        if let Some(c) = self.decider.pending() {
            self.commit(c, out);
        }
        let hist = self.front.history();
        if let Some(newest) = hist.newest() {
            let still = hist.get(newest).is_some_and(|r| r.token == STILL);
            let last = if still {
                newest.wrapping_sub(1)
            } else {
                newest
            };
            if let Some(Nearest {
                candidate: Some(c),
                open: false,
            }) = self.nearest_to(last, true)
            {
                out.note(|| self.note_of(&c, Why::Nearest));
                self.commit(c, out);
            }
        }
        self.held = None;
    }

    /// [`nearest_action`] for the phrase ending at run `last`, from where a phrase may begin.
    // Two call sites, once per pause and at the end: inlined, as the call was (flash).
    #[inline(always)]
    fn nearest_to(&self, last: u32, closed: bool) -> Option<Nearest> {
        let (floor, bounds) = self.phrase_floor;
        nearest_action(
            &self.library,
            self.front.history(),
            floor,
            bounds,
            last,
            closed,
        )
    }

    /// Feeds runs `from..=newest` (non-STILL ones) to the automata, committing as decided.
    fn feed_from(&mut self, from: u32, out: &mut impl Sink) {
        let mut i = from;
        // Each commit moves the floor forward, so this ends within a few ring lengths.
        for _ in 0..4 * HISTORY_RUNS {
            let Some(newest) = self.front.history().newest() else {
                return;
            };
            if i.wrapping_sub(self.floor) > newest.wrapping_sub(self.floor) {
                return;
            }
            let token = match self.front.history().get(i) {
                Some(r) => r.token,
                None => STILL,
            };
            if token == STILL {
                i = i.wrapping_add(1);
                continue;
            }
            self.tokens = self.tokens.saturating_add(1);
            let mut m: Matches = [u8::MAX; MAX_ACTIONS];
            let best = if self.bank.step(&self.library, token, &mut m) {
                self.best_candidate(i, &m)
            } else {
                None
            };
            match self.decider.offer(best, self.floor) {
                Decision::Wait => i = i.wrapping_add(1),
                Decision::Commit(c) => {
                    self.commit(c, out);
                    i = self.floor;
                }
            }
        }
    }

    fn best_candidate(&self, end: u32, m: &Matches) -> Option<Candidate> {
        // The non-STILL runs from `end` back to the floor, newest at the end of `tok`, so
        // that a match's tokens are one slice in reading order.
        let hist: &History = self.front.history();
        let mut idx = [0u32; HISTORY_RUNS];
        let mut tok = [STILL; HISTORY_RUNS];
        let mut n = 0usize;
        let mut i = end;
        for _ in 0..HISTORY_RUNS {
            if i.wrapping_sub(self.floor) > end.wrapping_sub(self.floor) {
                break;
            }
            let Some(r) = hist.get(i) else { break };
            if r.token != STILL {
                if let (Some(x), Some(t)) = (
                    idx.get_mut(n),
                    tok.get_mut(HISTORY_RUNS.wrapping_sub(1 + n)),
                ) {
                    *x = i;
                    *t = r.token;
                    n += 1;
                }
            }
            i = i.wrapping_sub(1);
        }
        // Token `j` back from the newest.
        let back = |j: usize| {
            if j < n {
                tok.get(HISTORY_RUNS.wrapping_sub(1 + j)).copied()
            } else {
                None
            }
        };
        let mut best: Option<Candidate> = None;
        for (a, &d) in m.iter().enumerate() {
            if d == u8::MAX {
                continue;
            }
            let Some(p) = self.library.pattern(a) else {
                continue;
            };
            // The match of the highest merit ending here at up to one edit more than the
            // lowest cost `d`: a crouch whose descent wobbled once outranks a jump that
            // explains the descent for free and leaves out its landing, and a run's many
            // strides with a wobble among them outrank the few exact ones after it. (At the
            // lowest cost only, for one-shot actions, isolated gestures were 0.3–0.6 points
            // worse; every cost up to the bound was no better than this.) Held to the share of
            // edits per token (in half-edits) as well as to the action's bound.
            let min_len = p.min_len();
            let reach = usize::from(d) + usize::from(FULL);
            let Some((j, cost, _)) = best_start(
                &p,
                reach.min(top_level(&p)).min(255) as u8,
                back,
                |j, v| edits_fit(v, (j + 1).max(min_len)).then(|| Candidate::merit_of(j + 1, v)),
                |best| Candidate::max_cost_beating(best, n),
            ) else {
                continue;
            };
            let start = idx.get(j).copied().unwrap_or(end);
            let c = Candidate {
                action: a as u8,
                start,
                end,
                cost,
                len: (j + 1) as u16,
                min_len: p.min_len().min(255) as u8,
                positions: p.positions().min(255) as u8,
                cyclic: p.cyclic(),
                shape: shape_cost(
                    shape_of(&self.library, a, hist, start, end).unwrap_or(0),
                    j + 1,
                ),
            };
            if best.is_none_or(|b| c.beats(&b)) {
                best = Some(c);
            }
        }
        best
    }

    /// Reports the pending candidate `p` before it is committed (once): the figurine has
    /// paused after it for as long as commits an action, and only a longer action in progress
    /// or the next cycle of a cyclic one could still change it. A consumer has the likely
    /// answer after the usual pause instead of after the hold; the commit revises the report
    /// if it did change (see [`ActionEvent::revises`]).
    fn report_provisional(&mut self, p: Candidate, out: &mut impl Sink) {
        if self.provisional.is_some() {
            return;
        }
        let before = self.held;
        if let Ok((ev, continues, held)) = self.outcome(&p, before) {
            self.provisional = Some((p, before, continues));
            self.held = held;
            self.report_floor = self.phrase_floor;
            self.phrase_floor = (p.end.wrapping_add(1), false);
            self.emit_held(ev, continues, out);
        }
    }

    /// What committing `c` after the held event `held` emits — the event, and whether it
    /// continues (revises) `held` — and the held event after it ([`crate::follow`]); or why
    /// there is none: `c` is too brief, is the held event's settling, or is a new event whose
    /// motion did not go as far as its action's examples ([`far_enough`]: a fidget).
    fn outcome(
        &self,
        c: &Candidate,
        held: Option<Held>,
    ) -> Result<(Held, bool, Option<Held>), Why> {
        let (ev, (from, to)) = self.event_of(c)?;
        // Only a new event is held to its action's extent; a continuation's went before. A
        // fidget seems to go as far as the tracker's noise takes it besides.
        let hist = self.front.history();
        let noise = noise_reach(self.front.noise_rms());
        let new = |ev: Held| match self.library.extent(usize::from(ev.action)) {
            Some(least) if !far_enough(span_extent(hist, from, to), least, noise) => {
                Err(Why::NotFarEnough)
            }
            _ => Ok((ev, false, Some(ev))),
        };
        let Some(mut h) = held else {
            return new(ev);
        };
        // Past the usual pause, only the rest of a hold its action's examples made (a crouch
        // held low, then risen from) continues it.
        let gap = c.start.wrapping_sub(h.end_run);
        let late = gap <= HISTORY_RUNS as u32
            && (1..gap)
                .filter_map(|k| hist.get(h.end_run.wrapping_add(k)))
                .any(|r| r.token == STILL && r.end.1.saturating_sub(r.start.1) >= CONTINUE_US);
        match follow(&self.library, hist, &h, c, late) {
            Follow::New => return new(ev),
            Follow::Settles => return Err(Why::Settles),
            Follow::Continues => h.distance = h.distance.max(c.distance()),
            Follow::Completes(cost) => {
                h.cost = cost;
                h.distance = cost.div_ceil(FULL);
            }
        }
        h.end = ev.end;
        h.end_run = c.end;
        h.acc.merge(&ev.acc);
        Ok((h, true, Some(h)))
    }

    /// The event `c` would be, and the runs of its motion phrase; or why there is none (its
    /// runs are gone, or it is too brief to be a gesture).
    fn event_of(&self, c: &Candidate) -> Result<(Held, (u32, u32)), Why> {
        let hist = self.front.history();
        let start = hist.get(c.start).ok_or(Why::Lost)?.start;
        let end = hist.get(c.end).ok_or(Why::Lost)?.end;
        if end.1.saturating_sub(start.1) < MIN_ACTION_US
            && hist.accum(c.start, c.end).turn_sum() * TICK_S < BRIEF_TURN_RAD
        {
            // A flicker of a token or two that happens to spell a short pattern: no child's
            // gesture is this brief, unless it turned the figurine a quarter turn. (Checked
            // first, before the phrase around the match is gathered for its effort; once per
            // report or commit, not per sample.)
            return Err(Why::TooBrief);
        }
        // Effort is read over the whole motion phrase around the match — out to the stillness
        // on either side (not before the previous commit) — as in training, where a gesture's
        // features span all of its motion.
        let mut from = c.start;
        for _ in 0..HISTORY_RUNS {
            let prev = from.wrapping_sub(1);
            if prev.wrapping_sub(self.floor) > c.start.wrapping_sub(self.floor) {
                break;
            }
            match hist.get(prev) {
                Some(r) if r.token != STILL => from = prev,
                _ => break,
            }
        }
        let mut to = c.end;
        if let Some(newest) = hist.newest() {
            for _ in 0..HISTORY_RUNS {
                if to == newest {
                    break;
                }
                match hist.get(to.wrapping_add(1)) {
                    Some(r) if r.token != STILL => to = to.wrapping_add(1),
                    _ => break,
                }
            }
        }
        let acc = hist.accum(from, to);
        // Reported from where the figurine set off from the rest before the match to where it
        // settled in the rest after it (or, still settling, to now): a slow onset or settle
        // below the "moving" threshold is part of the action.
        let start = hist
            .get(c.start.wrapping_sub(1))
            .filter(|r| r.token == STILL)
            .and_then(|r| r.set_off())
            .unwrap_or(start);
        let end = match hist.get(c.end.wrapping_add(1)) {
            Some(r) if r.token == STILL => r.settled().unwrap_or(r.end),
            _ => end,
        };
        let ev = Held {
            action: c.action,
            start_run: c.start,
            start,
            end,
            end_run: c.end,
            distance: c.distance(),
            cost: c.cost,
            acc,
        };
        Ok((ev, (from, to)))
    }

    /// A note on candidate `c` (None when its runs are gone).
    fn note_of(&self, c: &Candidate, why: Why) -> Option<Note> {
        let hist = self.front.history();
        let (start, end) = (hist.get(c.start)?.start, hist.get(c.end)?.end);
        Some(Note {
            action: c.action,
            start_seq: start.0,
            start_us: start.1,
            end_seq: end.0,
            end_us: end.1,
            why,
        })
    }

    /// Commits a candidate and emits it: as a new event, as the continuation of the held
    /// cyclic one (the next cycle after a short pause), or as the revision of the provisional
    /// report of another candidate it took over (nothing, when it is that reported candidate).
    /// A cyclic action's event stays held so that its next cycle can continue it. A candidate
    /// whose shape is as unlike its action's as the penalty measures is first offered to
    /// [`reread`].
    fn commit(&mut self, c: Candidate, out: &mut impl Sink) {
        // After a provisional report, `c` is judged against what the consumer had before it:
        // the held event as it was, if the report continued it; nothing, if the report was a
        // new event (which `c` replaces).
        // A match whose motion is plainly unlike its action's is read as the action whose
        // pattern nearly fits it and whose examples moved as it did, if one does.
        let c = match reread(&self.library, self.front.history(), &c) {
            Some(r) => {
                out.note(|| self.note_of(&r, Why::Reread { matched: c.action }));
                r
            }
            None => c,
        };
        let provisional = self.provisional.take();
        let before = match provisional {
            Some((_, held, true)) => held,
            Some((_, _, false)) => None,
            None => self.held,
        };
        let outcome = self.outcome(&c, before);
        self.bank.reset();
        self.decider.clear();
        // The pause's answer was about the match now committed: what is pending next is
        // weighed afresh.
        self.hold = None;
        self.floor = c.end.wrapping_add(1);
        // Its runs are consumed either way; a too-brief one is not emitted (and a report of
        // another candidate stands).
        let (ev, revises, held) = match outcome {
            Ok(o) => o,
            Err(why) => {
                out.note(|| self.note_of(&c, why));
                return;
            }
        };
        self.phrase_floor = (self.floor, false);
        self.held = held;
        match provisional {
            // Reported already, exactly so.
            Some((pv, _, _)) if pv == c => {}
            // The report extended the held event: put that back, then `c`.
            Some((_, before, true)) => {
                if let Some(b) = before {
                    self.emit_held(b, true, out);
                }
                self.emit_held(ev, revises, out);
            }
            // The report was a new event: `c` replaces it.
            Some((_, _, false)) => self.emit_held(ev, true, out),
            None => self.emit_held(ev, revises, out),
        }
    }
}

/// Where a recognizer's output goes: events always, notes only when a reader asked.
trait Sink {
    /// An event, as [`crate::Recognizer::push`] emits it.
    fn event(&mut self, e: ActionEvent);
    /// A note, built by `make` only if it is wanted.
    fn note(&mut self, make: impl FnOnce() -> Option<Note>);
}

/// Events to one closure, notes to another.
struct Noted<E, N> {
    /// Receives the events.
    event: E,
    /// Receives the notes.
    note: N,
}

impl<E: FnMut(ActionEvent), N: FnMut(Note)> Sink for Noted<E, N> {
    fn event(&mut self, e: ActionEvent) {
        (self.event)(e);
    }
    fn note(&mut self, make: impl FnOnce() -> Option<Note>) {
        if let Some(n) = make() {
            (self.note)(n);
        }
    }
}

/// Events to a closure; notes not built.
struct Quiet<E>(E);

impl<E: FnMut(ActionEvent)> Sink for Quiet<E> {
    fn event(&mut self, e: ActionEvent) {
        (self.0)(e);
    }
    #[inline(always)]
    fn note(&mut self, _: impl FnOnce() -> Option<Note>) {}
}

/// Whether an action other than `skip` has `tokens` (at least one) as the start of a match
/// that is not over ([`prefix_alive`]; `skip_first`: its own first part skipped) — or, unless
/// `skip_first`, one that costs at most `tolerance` half-edits so far ([`prefix_cost`]).
// Up to five calls per pause: one out-of-line copy (flash).
#[inline(never)]
fn under_way(
    lib: &Library<'_>,
    skip: u8,
    tokens: &[Token],
    skip_first: bool,
    tolerance: u8,
) -> bool {
    // Nothing begun is nothing under way (every pattern's start is "not over").
    !tokens.is_empty()
        && (0..lib.len()).any(|a| {
            a != usize::from(skip)
                && lib.pattern(a).is_some_and(|pat| {
                    // Its match so far covers all of the tokens and needs more: a longer one.
                    prefix_alive(&pat, tokens, skip_first)
                        || (!skip_first
                            && tolerance > 0
                            && prefix_cost(&pat, tokens, tolerance.min(top_level(&pat) as u8))
                                .is_some())
                })
        })
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::pattern::tests::seq_library;
    use proptest::prelude::*;
    use std::vec::Vec;

    /// A figurine hopping forward `hops` times (up-forward, down-forward), 120 Hz, then still.
    fn hops(hops: usize, t0_us: u64) -> Vec<Sample> {
        let mut out = Vec::new();
        let rate = 120.0f32;
        let still = 0.6f32;
        let hop = 0.5f32;
        let total = 2.0 * still + hops as f32 * hop;
        let n = (total * rate) as u32;
        for i in 0..n {
            let t = i as f32 / rate;
            let (mut y, mut z) = (0.0f32, 0.0f32);
            if t > still {
                let h = ((t - still) / hop).min(hops as f32);
                let phase = h - libm::floorf(h);
                z = 0.2 * h;
                if h < hops as f32 {
                    y = 0.1 * libm::sinf(core::f32::consts::PI * phase);
                }
            }
            out.push(Sample {
                seq: i,
                t_us: t0_us + (t * 1e6) as u64,
                pos: [0.3, 1.0 + y, z],
                quat: [1.0, 0.0, 0.0, 0.0],
            });
        }
        out
    }

    fn run(lib: &Library<'_>, samples: &[Sample]) -> Vec<ActionEvent> {
        let mut rec = Recognizer::new(*lib, None);
        let mut ev = Vec::new();
        for s in samples {
            rec.push(s, |e| ev.push(e));
        }
        rec.flush(|e| ev.push(e));
        ev
    }

    /// [`run`] with the decision stage's notes.
    fn run_noted(lib: &Library<'_>, samples: &[Sample]) -> (Vec<ActionEvent>, Vec<Note>) {
        let mut rec = Recognizer::new(*lib, None);
        let (mut ev, mut notes) = (Vec::new(), Vec::new());
        for s in samples {
            rec.push_noted(s, |e| ev.push(e), |n| notes.push(n));
        }
        rec.flush_noted(|e| ev.push(e), |n| notes.push(n));
        (ev, notes)
    }

    #[test]
    fn the_motion_shape_tips_a_tie_between_actions_written_alike() {
        // "skim" and "bob" are both `uf f df`; a bob rises about as much as it goes forward,
        // a skim barely rises.
        let v1 = seq_library(&[(&["uf", "f", "df"], 0), (&["uf", "f", "df"], 0)]);
        let actions = |blob: &[u8]| -> Vec<u8> {
            let lib = Library::from_bytes(blob).unwrap();
            run(&lib, &hops(1, 0)).iter().map(|e| e.action).collect()
        };
        // Without shapes the tie goes to the lower index.
        assert_eq!(actions(&v1), [0]);
        // Shares of speed (× 255): left, up, front; then the turn and the still share, none
        // here; then the height, an arc's (the mean height above the start is about a third
        // of the path: (1 + 0.32) × 255 / 2 ≈ 168). The hop is the bob's, whichever its index.
        let skim = Some([0, 50, 250, 0, 0, 168]);
        let bob = Some([0, 150, 200, 0, 0, 168]);
        let with = crate::pattern::tests::with_shapes;
        assert_eq!(actions(&with(&v1, &[skim, bob])), [1]);
        assert_eq!(actions(&with(&v1, &[bob, skim])), [0]);
        // Two bobs, one of which turns (ln(1 + angle) = 4 × 100 / 255 ≈ 1.6, a turn of about
        // 3.8 rad) and holds a third of its time: the hop, which does neither, is the other's.
        let twisting = Some([0, 150, 200, 100, 85, 168]);
        assert_eq!(actions(&with(&v1, &[twisting, bob])), [1]);
        assert_eq!(actions(&with(&v1, &[bob, twisting])), [0]);
        // Two bobs, one of which stays below where it began (a crouch's height, −0.2): the
        // hop, which rises, is the other's.
        let low = Some([0, 150, 200, 0, 0, 102]);
        assert_eq!(actions(&with(&v1, &[low, bob])), [1]);
        assert_eq!(actions(&with(&v1, &[bob, low])), [0]);
    }

    #[test]
    fn a_hop_sequence_is_recognised_with_its_segment() {
        let blob = seq_library(&[(&["uf", "f", "df"], 0), (&["l", "r"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let ev = run(&lib, &hops(1, 5_000_000));
        assert_eq!(ev.len(), 1, "{ev:?}");
        let e = ev[0];
        assert_eq!(e.action, 0);
        // The segment lies within the hop (0.6 s … 1.1 s after the start, ± filter edges).
        let (s, t) = (e.start_us - 5_000_000, e.end_us - 5_000_000);
        assert!((550_000..750_000).contains(&s), "start {s}");
        assert!((950_000..1_200_000).contains(&t), "end {t}");
        assert!(e.decided_us > e.end_us && e.decided_us - e.end_us < 400_000);
    }

    #[test]
    fn the_longest_action_wins() {
        // "hop" is one hop; "double" two hops: two hops in a row are one `double`.
        let blob = seq_library(&[
            (&["uf", "f", "df"], 0),
            (&["uf", "f", "df", "uf", "f", "df"], 1),
        ]);
        let lib = Library::from_bytes(&blob).unwrap();
        let ev = run(&lib, &hops(2, 0));
        assert_eq!(
            ev.iter().map(|e| e.action).collect::<Vec<_>>(),
            [1],
            "{ev:?}"
        );
    }

    #[test]
    fn a_stand_alone_gesture_past_every_bound_is_its_nearest_action() {
        // The hop (`uf f df`) against `u+ f+ d+` with no edits allowed: 45° off twice, half an
        // edit each — too far for the automaton, near enough once the hop stands alone.
        let blob = seq_library(&[(&["l", "r"], 0), (&["u", "f", "d"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let ev = run(&lib, &hops(1, 0));
        assert_eq!(ev.len(), 1, "{ev:?}");
        assert_eq!((ev[0].action, ev[0].distance), (1, 1));
        // Decided after the pause that commits any action.
        let after = ev[0].decided_us - ev[0].end_us;
        assert!((PAUSE_US..PAUSE_US + 100_000).contains(&after), "{after}");
        // Nothing near: nothing reported.
        let blob = seq_library(&[(&["l", "r"], 0), (&["b", "d"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        assert_eq!(run(&lib, &hops(1, 0)), []);
    }

    #[test]
    fn a_phrase_an_action_could_go_on_from_is_weighed_once_it_cannot() {
        // One hop (`u uf f df`) of a pattern that goes on `b` after it: while the figurine rests,
        // the hop may be the start of that action; once the stream ends, or the rest outlasts
        // any hold, it is a whole gesture, a stroke short of the action.
        let blob = seq_library(&[(&["l", "r"], 0), (&["u", "uf", "f", "df", "b"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let hop = hops(1, 0);
        let ev = run(&lib, &hop);
        assert_eq!(ev.len(), 1, "{ev:?}");
        assert_eq!((ev[0].action, ev[0].distance), (1, 1));
        // Live, with the rest going on: nothing yet after a second of it; the nearest action
        // once it has lasted OPEN_PHRASE_US.
        let last = *hop.last().unwrap();
        let rest = |s: f32| -> Vec<Sample> {
            let mut out = hop.clone();
            let n = (s * 120.0) as u32;
            out.extend((1..=n).map(|i| Sample {
                seq: last.seq + i,
                t_us: last.t_us + u64::from(i) * 1_000_000 / 120,
                ..last
            }));
            out
        };
        let live = |samples: &[Sample]| {
            let mut rec = Recognizer::new(lib, None);
            let mut ev = Vec::new();
            for s in samples {
                rec.push(s, |e| ev.push(e));
            }
            ev
        };
        assert_eq!(live(&rest(0.4)), []);
        let ev = live(&rest(2.0));
        assert_eq!(ev.len(), 1, "{ev:?}");
        assert_eq!(ev[0].action, 1);
        let after = ev[0].decided_us - ev[0].end_us;
        assert!(
            (OPEN_PHRASE_US..OPEN_PHRASE_US + 100_000).contains(&after),
            "{after}"
        );
    }

    /// `hops` hops forward (as [`hops`]), each pair of hops separated by `pause_s` of stillness.
    fn paused_hops(hops: usize, pause_s: f32) -> Vec<Sample> {
        let rate = 120.0f32;
        let (still, hop) = (0.6f32, 0.5f32);
        let period = hop + pause_s;
        let total = 2.0 * still + hops as f32 * period;
        let n = (total * rate) as u32;
        (0..n)
            .map(|i| {
                let t = i as f32 / rate;
                let (mut y, mut z) = (0.0f32, 0.0f32);
                if t > still {
                    let k = libm::floorf((t - still) / period);
                    let within = ((t - still) - k * period) / hop;
                    let done = k.min(hops as f32) + within.min(1.0);
                    z = 0.2 * done.min(hops as f32);
                    if (k as usize) < hops && within < 1.0 {
                        y = 0.1 * libm::sinf(core::f32::consts::PI * within);
                    }
                }
                Sample {
                    seq: i,
                    t_us: (t * 1e6) as u64,
                    pos: [0.3, 1.0 + y, z],
                    quat: [1.0, 0.0, 0.0, 0.0],
                }
            })
            .collect()
    }

    /// A one-hop pattern `uf+ f* df+`, cyclic (the whole may repeat) or not.
    fn hop_library(cyclic: bool) -> Vec<u8> {
        let syms: Vec<Token> = ["uf", "f", "df"]
            .iter()
            .map(|t| crate::token::parse_token(t).unwrap())
            .collect();
        let mut follow = [1 << 1, 0b110, 0b1100, 0b1000];
        if cyclic {
            follow[3] |= 1 << 1;
        }
        let mut blob = Vec::from(*b"FGL\x01");
        blob.extend([1, 0, 0, 0]);
        crate::pattern::encode_record(&mut blob, &syms, &follow, 1 << 3, 0, cyclic).unwrap();
        blob
    }

    #[test]
    fn the_next_cycle_after_a_short_pause_continues_the_event() {
        let blob = hop_library(true);
        let lib = Library::from_bytes(&blob).unwrap();
        // 350 ms between hops: longer than the stillness that commits a cycle
        // (`CYCLIC_PAUSE_US`), shorter than the one that ends the action (`CONTINUE_US`).
        let ev = run(&lib, &paused_hops(3, 0.35));
        assert_eq!(
            ev.iter().map(|e| e.revises).collect::<Vec<_>>(),
            [false, true, true],
            "{ev:?}"
        );
        // Each continuation keeps the start, reaches further, and is decided later.
        for w in ev.windows(2) {
            assert_eq!(w[1].start_us, w[0].start_us);
            assert!(w[1].end_us > w[0].end_us + 500_000);
            assert!(w[1].decided_us > w[0].decided_us);
        }
        // The first cycle is reported without waiting for the others, after the usual pause
        // rather than the longer one that commits a cycle.
        assert!(ev[0].decided_us < ev[1].end_us);
        assert!(
            ev[0].decided_us - ev[0].end_us < crate::segment::CYCLIC_PAUSE_US,
            "{ev:?}"
        );
    }

    #[test]
    fn a_next_cycle_of_many_runs_still_continues_the_event() {
        // A cycle of two hops (`(uf f df uf f df)+`): the next cycle is some nine runs after
        // the last one's end by the time it is matched.
        let syms: Vec<Token> = ["uf", "f", "df", "uf", "f", "df"]
            .iter()
            .map(|t| crate::token::parse_token(t).unwrap())
            .collect();
        // Each position may repeat (`uf+ f+ df+ …`), as in `hop_library`.
        let mut follow: Vec<u64> = (0..=6u32).map(|i| (1 << i) | (1 << (i + 1))).collect();
        follow[0] = 1 << 1;
        follow[6] = (1 << 6) | (1 << 1);
        let mut blob = Vec::from(*b"FGL\x01");
        blob.extend([1, 0, 0, 0]);
        // One edit: each hop begins with a brief `u`, extra inside the cycle.
        crate::pattern::encode_record(&mut blob, &syms, &follow, 1 << 6, 1, true).unwrap();
        let lib = Library::from_bytes(&blob).unwrap();
        // 450 ms between hops: a cycle is committed (`CYCLIC_PAUSE_US`) before the next one
        // begins, and the action goes on (`CONTINUE_US`).
        let ev = run(&lib, &paused_hops(4, 0.45));
        assert_eq!(
            ev.iter().map(|e| e.revises).collect::<Vec<_>>(),
            [false, true],
            "{ev:?}"
        );
        assert_eq!(ev[1].start_us, ev[0].start_us);
    }

    #[test]
    fn a_long_pause_or_a_one_shot_action_starts_a_new_event() {
        let cyclic = hop_library(true);
        let lib = Library::from_bytes(&cyclic).unwrap();
        let ev = run(&lib, &paused_hops(2, 0.9));
        assert_eq!(
            ev.iter().map(|e| e.revises).collect::<Vec<_>>(),
            [false, false]
        );
        // A one-shot action repeated after a short pause is two actions.
        let once = hop_library(false);
        let lib = Library::from_bytes(&once).unwrap();
        let ev = run(&lib, &paused_hops(2, 0.35));
        assert_eq!(
            ev.iter().map(|e| e.revises).collect::<Vec<_>>(),
            [false, false]
        );
        assert!(ev[1].start_us > ev[0].end_us);
    }

    /// A slow forward stroke (15 cm in 1.2 s from 1.0 s, minimum jerk: it sets off and
    /// settles slowly), then 1.5 s still; 100 Hz, with ±1 mm of white jitter on every axis.
    fn slow_stroke() -> Vec<Sample> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut jitter = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            ((state >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 0.002
        };
        (0..370u32)
            .map(|i| {
                let t = i as f32 / 100.0;
                let x = ((t - 1.0) / 1.2).clamp(0.0, 1.0);
                let z = 0.15 * x * x * x * (10.0 - 15.0 * x + 6.0 * x * x);
                Sample {
                    seq: i,
                    t_us: (t * 1e6) as u64,
                    pos: [0.3 + jitter(), 1.0 + jitter(), z + jitter()],
                    quat: [1.0, 0.0, 0.0, 0.0],
                }
            })
            .collect()
    }

    #[test]
    fn a_slow_stroke_is_reported_from_rest_to_rest() {
        let blob = seq_library(&[(&["f"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let ev = run(&lib, &slow_stroke());
        assert_eq!(ev.len(), 1, "{ev:?}");
        // It moved from 1.0 s to 2.2 s; fast enough to make a token only from about 1.2 s to
        // 2.0 s.
        assert!((900_000..1_120_000).contains(&ev[0].start_us), "{ev:?}");
        assert!((2_080_000..2_300_000).contains(&ev[0].end_us), "{ev:?}");
    }

    /// A smooth step from 0 (x ≤ 0) to 1 (x ≥ 1): how the test strokes move.
    fn ramp(x: f32) -> f32 {
        0.5 - 0.5 * libm::cosf(core::f32::consts::PI * x.clamp(0.0, 1.0))
    }

    /// A thrust forward (0.4 s), a pause of `hold_s`, the return (0.4 s), at 120 Hz.
    fn thrust_and_return(hold_s: f32) -> Vec<Sample> {
        let rate = 120.0f32;
        let (still, stroke) = (0.6f32, 0.4f32);
        let total = 2.0 * still + 2.0 * stroke + hold_s + 0.6;
        (0..(total * rate) as u32)
            .map(|i| {
                let t = i as f32 / rate;
                let out = ramp((t - still) / stroke);
                let back = ramp((t - still - stroke - hold_s) / stroke);
                Sample {
                    seq: i,
                    t_us: (t * 1e6) as u64,
                    pos: [0.3, 1.0, 0.25 * (out - back)],
                    quat: [1.0, 0.0, 0.0, 0.0],
                }
            })
            .collect()
    }

    /// Going down (0.4 s, pitching 0.24 rad in its first half), held low for `hold_s`, back
    /// up (0.4 s), at 120 Hz.
    fn crouch_held_low(hold_s: f32) -> Vec<Sample> {
        let rate = 120.0f32;
        let (still, stroke) = (0.6f32, 0.4f32);
        let total = 2.0 * still + 2.0 * stroke + hold_s;
        (0..(total * rate) as u32)
            .map(|i| {
                let t = i as f32 / rate;
                let down = ramp((t - still) / stroke);
                let up = ramp((t - still - stroke - hold_s) / stroke);
                let half = 0.12 * ramp((t - still) / (0.5 * stroke));
                Sample {
                    seq: i,
                    t_us: (t * 1e6) as u64,
                    pos: [0.3, 1.0 - 0.15 * (down - up), 0.0],
                    quat: [libm::cosf(half), libm::sinf(half), 0.0, 0.0],
                }
            })
            .collect()
    }

    /// Quick strokes (0.12 s each, 5 cm, along `dirs`), 0.15 s apart, played right after the
    /// stream starts; then still.
    fn quick_strokes(dirs: &[[f32; 3]]) -> Vec<Sample> {
        let rate = 200.0f32;
        let (lead, stroke, gap) = (0.3f32, 0.12f32, 0.15f32);
        let total = lead + dirs.len() as f32 * (stroke + gap) + 1.0;
        (0..(total * rate) as u32)
            .map(|i| {
                let t = i as f32 / rate;
                let mut pos = [0.3f32, 1.0, 0.0];
                for (k, d) in dirs.iter().enumerate() {
                    let x = ramp((t - lead - k as f32 * (stroke + gap)) / stroke);
                    for (p, v) in pos.iter_mut().zip(d) {
                        *p += 0.05 * x * v;
                    }
                }
                Sample {
                    seq: i,
                    t_us: (t * 1e6) as u64,
                    pos,
                    quat: [1.0, 0.0, 0.0, 0.0],
                }
            })
            .collect()
    }

    #[test]
    fn strokes_too_brief_for_a_gesture_stay_in_their_phrase() {
        // Each `l` alone matches but is too brief to emit; the `u` between matches nothing.
        // The three strokes, right after the stream began, are one phrase: its nearest action.
        let blob = seq_library(&[(&["l"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let left = [1.0, 0.0, 0.0];
        let ev = run(&lib, &quick_strokes(&[left, [0.0, 1.0, 0.0], left]));
        assert_eq!(ev.len(), 1, "{ev:?}");
        assert!(ev[0].start_us < 400_000 && ev[0].end_us > 900_000, "{ev:?}");
        // A stroke alone stays too brief, and the note says so, over the stroke's 0.12 s.
        let (ev, notes) = run_noted(&lib, &quick_strokes(&[left]));
        assert_eq!(ev, [], "one stroke");
        let brief: Vec<&Note> = notes.iter().filter(|n| n.why == Why::TooBrief).collect();
        assert!(!brief.is_empty(), "{notes:?}");
        for n in brief {
            assert!(
                n.action == 0 && n.start_us >= 250_000 && n.end_us <= 500_000,
                "{n:?}"
            );
        }
        // Offered to its nearest action first, then dropped all the same: nothing else.
        assert!(
            notes
                .iter()
                .all(|n| matches!(n.why, Why::TooBrief | Why::Nearest)),
            "{notes:?}"
        );
    }

    /// A twist about the vertical axis by `angle` rad in 0.12 s, after 0.6 s of stillness and
    /// before 0.8 s more, at 200 Hz.
    fn quick_twist(angle: f32) -> Vec<Sample> {
        twists(angle, 0.12, None)
    }

    /// A twist about the vertical axis by `angle` rad in `twist` s after 0.6 s of stillness,
    /// and, `back` s later if given, the same twist back; then 0.8 s of stillness; 200 Hz.
    fn twists(angle: f32, twist: f32, back: Option<f32>) -> Vec<Sample> {
        let rate = 200.0f32;
        let lead = 0.6f32;
        let moving = back.map_or(twist, |hold| 2.0 * twist + hold);
        (0..((lead + moving + 0.8) * rate) as u32)
            .map(|i| {
                let t = i as f32 / rate;
                let there = ramp((t - lead) / twist);
                let back = back.map_or(0.0, |hold| ramp((t - lead - twist - hold) / twist));
                let half = 0.5 * angle * (there - back);
                Sample {
                    seq: i,
                    t_us: (t * 1e6) as u64,
                    pos: [0.3, 1.0, 0.0],
                    quat: [libm::cosf(half), 0.0, libm::sinf(half), 0.0],
                }
            })
            .collect()
    }

    #[test]
    fn a_sudden_turn_briefer_than_any_gesture_is_still_one() {
        let blob = seq_library(&[(&[".Yp"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        // Two thirds of a right angle in 0.12 s: a flicker as far as brevity goes …
        assert_eq!(run(&lib, &quick_twist(1.0)), []);
        // … a half turn is a turn.
        let ev = run(&lib, &quick_twist(core::f32::consts::PI));
        assert_eq!(ev.len(), 1, "{ev:?}");
        // Reported from rest to rest: the twist (0.6 s … 0.72 s), widened by no more than the
        // filter's half window on either side.
        let half = crate::filter::SG_HALF as u64 * crate::intake::TICK_US;
        let (s, e) = (ev[0].start_us, ev[0].end_us);
        assert!(s <= 600_000 && s + half >= 600_000, "{ev:?}");
        assert!(e >= 720_000 && e <= 720_000 + 2 * half, "{ev:?}");
    }

    #[test]
    fn a_fidget_that_spells_an_action_is_no_action() {
        // A yaw there and back, learnt from examples that turned at least 1.6 rad (and moved
        // a centimetre).
        let blob = seq_library(&[(&[".Yp", ".Yn"], 0)]);
        let unknown = Library::from_bytes(&blob).unwrap();
        let learnt = crate::pattern::tests::with_extents(&blob, &[(0.01, 1.6)]);
        let lib = Library::from_bytes(&learnt).unwrap();
        // 5° there and back spells it: with no extents learnt (a version 1 library) it is
        // reported; with them it went nowhere near as far as a turn goes.
        let fidget = twists(0.09, 0.06, Some(0.3));
        assert_eq!(run(&unknown, &fidget).len(), 1, "the tokens spell it");
        let (ev, notes) = run_noted(&lib, &fidget);
        assert_eq!(ev, []);
        assert!(
            notes.iter().any(|n| n.why == Why::NotFarEnough),
            "{notes:?}"
        );
        // 30° there and back: a turn played small, but played.
        let ev = run(&lib, &twists(0.5, 0.06, Some(0.3)));
        assert_eq!(ev.len(), 1, "{ev:?}");
    }

    #[test]
    fn a_log_that_ends_right_after_a_gesture_keeps_it() {
        // `l r l` exactly only (bound 0): `r l` is its nearest reading, after a pause — or
        // when the stream ends first.
        let blob = seq_library(&[(&["l", "r", "l"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let strokes = quick_strokes(&[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]);
        let ev = run(&lib, &strokes);
        assert_eq!(ev.len(), 1, "{ev:?}");
        // The log ends 60 ms after the second stroke: too soon for any pause to pass.
        let end_us = 300_000 + 120_000 + 150_000 + 120_000 + 60_000;
        let cut: Vec<Sample> = strokes.into_iter().filter(|s| s.t_us <= end_us).collect();
        let ev = run(&lib, &cut);
        assert_eq!(ev.len(), 1, "{ev:?}");
        assert!(ev[0].start_us < 400_000, "{ev:?}");
    }

    #[test]
    fn a_match_reaches_back_over_a_wobble_at_the_start() {
        // `d u` costs nothing from the plain part of the descent on, and half an edit from
        // its pitched start: the whole descent is the crouch.
        let blob = seq_library(&[(&["d", "u"], 1)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let ev = run(&lib, &crouch_held_low(0.5));
        assert_eq!(ev.len(), 1, "{ev:?}");
        assert!(ev[0].start_us < 700_000, "{ev:?}");
        assert_eq!(ev[0].distance, 1, "{ev:?}");
    }

    #[test]
    fn a_match_that_left_a_stroke_out_waits_for_a_closer_action_under_way() {
        // "jump" explains the pitched descent by leaving its hop out (a whole edit); "crouch"
        // explains it at half an edit (the pitch) and is not finished: the hold is part of it.
        let blob = seq_library(&[(&["d.Xp", "u", "d"], 1), (&["d", "u"], 1)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let ev = run(&lib, &crouch_held_low(0.8));
        let got: Vec<_> = ev.iter().map(|e| (e.action, e.revises)).collect();
        assert_eq!(got.last(), Some(&(1, true)), "{ev:?}");
        let crouch = ev.last().unwrap();
        assert!(
            crouch.start_us < 800_000 && crouch.end_us > 1_900_000,
            "{ev:?}"
        );
    }

    #[test]
    fn a_crouch_held_as_long_as_its_examples_held_is_one_crouch() {
        // 0 crouch `d.Xp+ d+ u*` (its pitched descent alone is one, exactly), 1 a rise `u+`.
        // Held low for a second: the crouch is committed at its descent.
        let blob = crate::pattern::tests::seq_library_ending(&[
            (&["d.Xp", "d", "u"], 0, 2),
            (&["u"], 0, 1),
        ]);
        let blob = crate::pattern::tests::with_extents(&blob, &[(0.01, 0.01), (0.01, 0.01)]);
        let low = crouch_held_low(1.0);
        let read = |blob: &[u8]| {
            let lib = Library::from_bytes(blob).unwrap();
            run(&lib, &low)
                .iter()
                .map(|e| (e.action, e.revises))
                .collect::<Vec<_>>()
        };
        // Not learnt to hold that long: the rise is a gesture of its own.
        assert_eq!(read(&blob), [(0, false), (1, false)]);
        // Its examples held 1.1 s: the rise finishes the crouch, reported as its revision.
        let held = crate::pattern::tests::with_hold(&blob, 0, 1_100_000);
        assert_eq!(read(&held), [(0, false), (0, true)]);
    }

    #[test]
    fn a_match_that_needed_an_edit_waits_for_a_closer_one_begun_inside_it() {
        // A sideways stroke just before a pitched descent: "jump" explains `r d.Xp d` by
        // leaving its hop out (a whole edit); "crouch" began at the descent, half an edit off
        // (the pitch), and is not finished: the hold is part of it, not the end of a jump.
        let blob = seq_library(&[(&["r", "u", "d.Xp", "d"], 1), (&["d", "u"], 1)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let samples: Vec<Sample> = crouch_held_low(0.8)
            .into_iter()
            .map(|mut s| {
                let t = s.t_us as f32 * 1e-6;
                s.pos[0] -= 0.05 * ramp((t - 0.25) / 0.15);
                s
            })
            .collect();
        let ev = run(&lib, &samples);
        // The jump is reported after the usual pause, then revised.
        let got: Vec<_> = ev.iter().map(|e| (e.action, e.revises)).collect();
        assert_eq!(got.last(), Some(&(1, true)), "{ev:?}");
        let crouch = ev.last().unwrap();
        // From the descent (0.6 s; its onset shows up to the filter's half window early), not
        // from the sideways stroke (0.25 s … 0.4 s).
        assert!(
            crouch.start_us > 540_000 && crouch.end_us > 1_900_000,
            "{ev:?}"
        );
    }

    #[test]
    fn nothing_begun_is_no_action_under_way() {
        let blob = seq_library(&[(&["f"], 0), (&["d", "u"], 1)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let d = crate::token::parse_token("d").unwrap();
        assert!(under_way(&lib, 0, &[d], false, 0));
        // Not the pending candidate's own action, and not from no tokens at all.
        assert!(!under_way(&lib, 1, &[d], false, 0));
        assert!(!under_way(&lib, 0, &[], false, 1));
    }

    #[test]
    fn an_action_reported_during_a_hold_is_revised_by_the_longer_one() {
        // "thrust" is the forward stroke alone; "jab" is the stroke and its return.
        let blob = seq_library(&[(&["f"], 0), (&["f", "b"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let ev = run(&lib, &thrust_and_return(0.3));
        assert_eq!(
            ev.iter().map(|e| (e.action, e.revises)).collect::<Vec<_>>(),
            [(0, false), (1, true)],
            "{ev:?}"
        );
        // The thrust is out during the pause, before the return began; the jab replaces it.
        assert!(ev[0].decided_us < 1_300_000, "{ev:?}");
        assert_eq!(ev[1].start_us, ev[0].start_us);
        assert!(ev[1].end_us > ev[0].end_us + 300_000);
        // Held past HOLD_US: the thrust stands alone, and the return is no jab.
        let ev = run(&lib, &thrust_and_return(0.9));
        assert_eq!(
            ev.iter().map(|e| (e.action, e.revises)).collect::<Vec<_>>(),
            [(0, false)],
            "{ev:?}"
        );
    }

    fn any_sample() -> impl Strategy<Value = Sample> {
        let f = prop_oneof![
            8 => -3.0f32..3.0,
            1 => Just(f32::NAN),
            1 => Just(f32::INFINITY),
            1 => Just(0.0f32),
            1 => any::<f32>(),
        ];
        (
            any::<u32>(),
            0u64..3_000_000,
            [f.clone(), f.clone(), f.clone()],
            [f.clone(), f.clone(), f.clone(), f],
        )
            .prop_map(|(seq, t_us, pos, quat)| Sample {
                seq,
                t_us,
                pos,
                quat,
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn arbitrary_streams_never_panic_and_every_sample_is_counted(
            mut stream in proptest::collection::vec(any_sample(), 0..400),
            sorted in any::<bool>(),
        ) {
            if sorted {
                stream.sort_by_key(|s| s.t_us);
            }
            let blob = seq_library(&[(&["uf", "df"], 0), (&["u", "d", "u"], 1), (&["f.Yp"], 0)]);
            let lib = Library::from_bytes(&blob).unwrap();
            let mut rec = Recognizer::new(lib, None);
            let mut events = Vec::new();
            for s in &stream {
                rec.push(s, |e| {
                    assert!(e.end_us >= e.start_us);
                    events.push(e);
                });
            }
            rec.flush(|e| events.push(e));
            let st = rec.stats();
            prop_assert_eq!((st.intake.accepted + st.intake.skipped()) as usize, stream.len());
            prop_assert_eq!(st.events as usize, events.len());
            // Asking for notes changes no event.
            let mut noted = Recognizer::new(lib, None);
            let mut again = Vec::new();
            for s in &stream {
                noted.push_noted(s, |e| again.push(e), |n| assert!(n.end_us >= n.start_us));
            }
            noted.flush_noted(|e| again.push(e), |_| {});
            prop_assert_eq!(events, again);
        }
    }
}

#[cfg(test)]
mod ram {
    use super::*;

    #[test]
    fn recognizer_state_fits_the_ram_budget() {
        // The whole recognizer state with room for 32 actions (patterns stay in flash).
        let size = core::mem::size_of::<Recognizer<'static>>();
        // 17 KiB of the firmware's 24 KiB of static RAM (the link, the board and the stacks
        // take the rest: `cargo xtask bench` prints the whole).
        assert!(size <= 17 * 1024, "{size} bytes");
        extern crate std;
        std::eprintln!("Recognizer state: {size} bytes");
    }
}
