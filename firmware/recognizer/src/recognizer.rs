//! The whole recognizer: samples in, [`ActionEvent`]s out.
//!
//! Front end (stages 0–3, 7) → automata over the library (5) → segment decision (6) → effort
//! classification (8) at commit time. No allocation, no clock: every time comes in with the
//! samples. RAM (see `capacities` in the crate docs): front end ≈ 11 KiB, automata 1.75 KiB,
//! effort model 0.6 KiB, the last event (open to continuation, [`crate::follow`]), the state
//! before a provisional report and the last stand-alone phrase's nearest action 0.6 KiB —
//! 16.5 KiB in all (16,920 B by `size_of`, measured by a test) with 32 actions loaded.
//!
//! | file | what it does |
//! |---|---|
//! | `recognizer.rs` | the sample loop: the front end's new runs to the automata, a pause's commit, hold or report, a stand-alone phrase to its nearest action |
//! | `recognizer/candidate.rs` | the best match ending at a token; whether a longer action is under way |
//! | `recognizer/commit.rs` | what a committed match becomes (new event, continuation, nothing), emitted, and why not ([`crate::note`]) |

use crate::automaton::{MatcherBank, Matches};
use crate::bayes::EffortModel;
use crate::follow::Held;
use crate::frontend::{FrontEvent, Frontend};
use crate::history::HISTORY_RUNS;
use crate::intake::{IntakeCounters, Sample};
use crate::nearest::{nearest_action, whole_phrase, Nearest, OPEN_PHRASE_US};
use crate::note::{Note, Why};
use crate::pattern::{Library, MAX_ACTIONS};
use crate::segment::{Candidate, Decider, Decision, CONTINUE_US, LONG_PAUSE_US, PAUSE_US};
use crate::token::{Token, STILL};

mod candidate;
mod commit;
#[cfg(test)]
mod fixtures;

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
    /// The STILL run last checked for a longer action in progress, and the answer (its learnt
    /// hold, µs: a library byte of 10 ms units, so u32 holds it; u64 would cost 12 bytes of
    /// the RAM budget).
    hold: Option<(u32, Option<u32>)>,
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
                // A cyclic event's pause counts from where its motion settled (`follow`); read
                // only while one is held (an interpolation, on every still sample otherwise).
                let rested = if self.held.is_some_and(|h| h.cyclic) {
                    r.rested_us(self.front.last_tick_us())
                } else {
                    0
                };
                // The first sample of the pause that may commit: nothing moves during a pause,
                // so what is checked then holds for all of it.
                let mut first = false;
                let longer = match (self.decider.pending(), newest) {
                    (Some(p), Some(run)) if (PAUSE_US..LONG_PAUSE_US).contains(&still) => {
                        match self.hold {
                            Some((r, v)) if r == run => v.map(u64::from),
                            _ => {
                                let v = self.longer_in_progress(&p);
                                let kept = v.map(|h| u32::try_from(h).unwrap_or(u32::MAX));
                                self.hold = Some((run, kept));
                                first = true;
                                kept.map(u64::from)
                            }
                        }
                    }
                    _ => None,
                };
                if let Decision::Commit(c) = self.decider.stillness(still, longer) {
                    if let Some(run) = newest {
                        self.commit_at_pause(c, run.wrapping_sub(1), out);
                    }
                } else if let Some(p) = self
                    .decider
                    .pending()
                    .filter(|p| longer.is_some() || p.cyclic)
                {
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
                // As long as its action's examples held still inside, and no shorter; a cyclic
                // event, for its next cycle, from where its strokes settled.
                if let Some(h) = self.held {
                    let paused = if h.cyclic { rested } else { still };
                    if paused >= self.keep_held(&h) {
                        self.held = None;
                    }
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

    /// Ends the stream as a long pause would: commits the pending candidate as at a pause
    /// (its whole phrase, the first of two performances read as one), reads on from what
    /// moved after it until nothing is pending; then, if no event took the stream's last
    /// phrase, reports its nearest action (a log that ends right after a gesture no action
    /// matched closely keeps that gesture).
    pub fn flush(&mut self, emit: impl FnMut(ActionEvent)) {
        self.flush_to(&mut Quiet(emit));
    }

    /// [`Self::flush`], with notes as [`Self::push_noted`] gives them.
    pub fn flush_noted(&mut self, emit: impl FnMut(ActionEvent), note: impl FnMut(Note)) {
        self.flush_to(&mut Noted { event: emit, note });
    }

    fn flush_to(&mut self, out: &mut impl Sink) {
        // What followed a committed match is read on, as after any commit: the stream's end
        // is a pause long enough for everything pending.
        let hist = self.front.history();
        let Some(newest) = hist.newest() else {
            self.held = None;
            return;
        };
        let still = hist.get(newest).is_some_and(|r| r.token == STILL);
        let last = if still {
            newest.wrapping_sub(1)
        } else {
            newest
        };
        for _ in 0..HISTORY_RUNS {
            let Some(c) = self.decider.pending() else {
                break;
            };
            self.commit_at_pause(c, last, out);
        }
        if let Some(Nearest {
            candidate: Some(c),
            open: false,
        }) = self.nearest_to(last, true)
        {
            out.note(|| self.note_of(&c, Why::Nearest));
            self.commit(c, out);
        }
        self.held = None;
    }

    /// Commits `c` at a pause (or the stream's end) after run `last`: as the whole phrase
    /// around it, the first of two performances if it read two as one, and then reads on
    /// from what moved after it (a turn begun while a run's match waited for its next stride;
    /// a crouch right after a wave's last stroke).
    fn commit_at_pause(&mut self, c: Candidate, last: u32, out: &mut impl Sink) {
        let (floor, bounds) = if self.provisional.is_some() {
            self.report_floor
        } else {
            self.phrase_floor
        };
        let c =
            whole_phrase(&self.library, self.front.history(), floor, bounds, last, &c).unwrap_or(c);
        let c = self.first_of_two(&c).unwrap_or(c);
        if self.commit(c, out) {
            self.feed_from(self.floor, out);
        }
    }

    /// How long event `h` stays held after it, µs of rest: [`CONTINUE_US`], or as long as its
    /// action's examples held still inside if longer.
    fn keep_held(&self, h: &Held) -> u64 {
        CONTINUE_US.max(self.library.hold_us(usize::from(h.action)))
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
                    let c = self.first_of_two(&c).unwrap_or(c);
                    if self.commit(c, out) {
                        i = self.floor;
                    } else {
                        // Left open: the match ending here is weighed as if none had been.
                        self.decider.offer(best, self.floor);
                        i = i.wrapping_add(1);
                    }
                }
            }
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

#[cfg(test)]
mod tests {
    extern crate std;
    use super::fixtures::*;
    use super::*;
    use crate::pattern::tests::seq_library;
    use proptest::prelude::*;
    use std::vec::Vec;

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
