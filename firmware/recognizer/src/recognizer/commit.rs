//! Stage 6b — what a committed match becomes: a new event, the next piece of the one before,
//! its settling, or nothing.
//!
//! A candidate the decision stage commits is first re-read when it moved plainly unlike its
//! action ([`crate::nearest::reread`]), then weighed against the event before it
//! ([`crate::follow`]) and, when new, against how far its action's examples went
//! ([`crate::extent`]) — falling short, it is offered to the action its motion did reach
//! ([`crate::nearest::not_that_far`]); a match too brief for any gesture is none. A commit
//! consumes the match's runs, but for a match dropped as short of its action that ended below
//! every rest before it ([`crate::history::History::sunk_below_rests`]): a descent whose rise
//! is still to come is left to a longer match. A candidate held at a pause is reported early
//! ([`Recognizer::report_provisional`]) and revised by the commit if it changed. Each drop,
//! and each re-read, is a [`Note`] for a reader who asks.

use crate::alignment::FULL;
use crate::bayes::quantise;
use crate::extent::{
    far_enough, noise_reach, rested_extent, span_extent, went_as_far, FIDGET_MOVED_M,
};
use crate::features::segment_features;
use crate::follow::{follow, Follow, Held};
use crate::history::HISTORY_RUNS;
use crate::intake::TICK_S;
use crate::nearest::{not_that_far, reread};
use crate::note::{Note, Why};
use crate::segment::{Candidate, BRIEF_TURN_RAD, CONTINUE_US, MIN_ACTION_US};
use crate::sweep::carried;
use crate::token::STILL;

use super::{ActionEvent, Recognizer, Sink};

/// What committing a candidate emits ([`Recognizer::outcome`]): the event, whether it revises
/// the held one, and the held event after it; or why there is none.
type Outcome = Result<(Held, bool, Option<Held>), Why>;

impl<'lib> Recognizer<'lib> {
    /// Reports the pending candidate `p` before it is committed (once): the figurine has
    /// paused after it for as long as commits an action, and only a longer action in progress
    /// or the next cycle of a cyclic one could still change it. A consumer has the likely
    /// answer after the usual pause instead of after the hold; the commit revises the report
    /// if it did change (see [`ActionEvent::revises`]).
    pub(super) fn report_provisional(&mut self, p: Candidate, out: &mut impl Sink) {
        if self.provisional.is_some() {
            return;
        }
        let before = self.held;
        let (p, outcome) = self.reaching_outcome(p, before);
        if let Ok((ev, continues, held)) = outcome {
            self.provisional = Some((p, before, continues));
            self.held = held;
            self.report_floor = self.phrase_floor;
            self.phrase_floor = (p.end.wrapping_add(1), false);
            self.emit_held(ev, continues, out);
        }
    }

    /// What committing `c` after the held event `held` emits — the event, and whether it
    /// revises `held` (continues it, or takes it in as its wind-up) — and the held event after
    /// it ([`crate::follow`]); or why
    /// there is none: `c` is too brief, is the held event's settling, or is a new event whose
    /// motion did not go as far as its action's examples ([`far_enough`]: a fidget).
    pub(super) fn outcome(&self, c: &Candidate, held: Option<Held>) -> Outcome {
        let (ev, (from, to)) = self.event_of(c)?;
        // Only a new event is held to its action's extent and sub-movements; a continuation's
        // went before. A fidget seems to go as far as the tracker's noise takes it besides.
        let hist = self.front.history();
        let noise = noise_reach(self.front.noise_rms());
        // The stillness the phrase began from, unless an earlier commit consumed it.
        let rested = from.wrapping_sub(1);
        let rest = hist.get(rested).filter(|r| {
            r.token == STILL && rested.wrapping_sub(self.floor) <= from.wrapping_sub(self.floor)
        });
        let new = |ev: Held| match self.library.extent(usize::from(ev.action)) {
            Some(least) if !far_enough(rested_extent(hist, rest, from, to), least, noise) => {
                Err(Why::NotFarEnough)
            }
            Some(least) => {
                let made = self.library.least_sweeps(usize::from(ev.action));
                if carried(least, made, c.cost, hist, from, to) {
                    Err(Why::OneSweep)
                } else {
                    Ok((ev, false, Some(ev)))
                }
            }
            None => Ok((ev, false, Some(ev))),
        };
        let Some(mut h) = held else {
            return new(ev);
        };
        // Past the usual pause, only the rest of a hold its action's examples made (a crouch
        // held low, then risen from) continues it. A cyclic event's next cycle rests only
        // where its strokes had settled, and the event stays held for it that long: their slow
        // tails under a noisy tracker's floor are no pause. For anything else the pause counts
        // from the still run's start, and past the hold the event is no longer held.
        let gap = c.start.wrapping_sub(h.end_run);
        let next_cycle = h.cyclic && h.action == c.action;
        let (mut still, mut rested) = (0, 0);
        if gap <= HISTORY_RUNS as u32 {
            for r in (1..gap)
                .filter_map(|k| hist.get(h.end_run.wrapping_add(k)))
                .filter(|r| r.token == STILL)
            {
                still = still.max(r.end.1.saturating_sub(r.start.1));
                rested = rested.max(r.rested_us(r.set_off().map_or(r.start.1, |o| o.1)));
            }
        }
        if !next_cycle && still >= self.keep_held(&h) {
            return new(ev);
        }
        let late = if next_cycle { rested } else { still } >= CONTINUE_US;
        match follow(&self.library, hist, &h, c, late) {
            Follow::New => return new(ev),
            Follow::Settles => return Err(Why::Settles),
            Follow::LeadsIn => {
                return new(ev).map(|(mut ev, _, _)| {
                    ev.start = h.start;
                    ev.start_run = h.start_run;
                    ev.acc.merge(&h.acc);
                    (ev, true, Some(ev))
                })
            }
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

    /// [`Recognizer::outcome`] of `c`, or, when `c` went less far than its action's examples,
    /// of the action whose pattern reads it within an edit and whose examples it moved like
    /// and went as far as ([`not_that_far`]); with the candidate that outcome is of.
    fn reaching_outcome(&self, c: Candidate, held: Option<Held>) -> (Candidate, Outcome) {
        match self.outcome(&c, held) {
            Err(Why::NotFarEnough) => not_that_far(&self.library, self.front.history(), &c)
                .and_then(|r| self.outcome(&r, held).ok().map(|o| (r, Ok(o))))
                .unwrap_or((c, Err(Why::NotFarEnough))),
            o => (c, o),
        }
    }

    /// Whether `c`'s action's examples vouch for a match that lasted only `lasted_us`: it is
    /// a whole gesture, from rest to rest, as each example was; the briefest of them lasted
    /// at most twice as long (a sudden performance takes about half the time of a neutral
    /// one); and it went as far as the least of them, in a dimension that carries the action
    /// ([`went_as_far`]). A flicker spells a pattern in passing, inside other motion or
    /// without covering its ground; a player who flicks the toy through a sidestep as
    /// quickly as they taught it plays the whole of it.
    #[cold]
    fn examples_as_brief(&self, c: &Candidate, lasted_us: u64) -> bool {
        let a = usize::from(c.action);
        let briefest_us = self.library.briefest_us(a);
        let hist = self.front.history();
        // At rest on either side (or nothing more in the history).
        let rest = |i: u32| hist.get(i).is_none_or(|r| r.token == STILL);
        briefest_us > 0
            && briefest_us <= 2 * lasted_us
            && rest(c.start.wrapping_sub(1))
            && rest(c.end.wrapping_add(1))
            && self
                .library
                .extent(a)
                .is_some_and(|least| went_as_far(span_extent(hist, c.start, c.end), least))
    }

    /// The event `c` would be, and the runs of its motion phrase; or why there is none (its
    /// runs are gone, or it is too brief to be a gesture).
    pub(super) fn event_of(&self, c: &Candidate) -> Result<(Held, (u32, u32)), Why> {
        let hist = self.front.history();
        let start = hist.get(c.start).ok_or(Why::Lost)?.start;
        let end = hist.get(c.end).ok_or(Why::Lost)?.end;
        let lasted_us = end.1.saturating_sub(start.1);
        if lasted_us < MIN_ACTION_US
            && hist.accum(c.start, c.end).turn_sum() * TICK_S < BRIEF_TURN_RAD
            && !self.examples_as_brief(c, lasted_us)
        {
            // A flicker of a token or two that happens to spell a short pattern: no child's
            // gesture is this brief, unless it turned the figurine a quarter turn, or its
            // action's own examples were this quick. (Checked first, before the phrase around
            // the match is gathered for its effort; once per report or commit, not per sample.)
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
            cyclic: c.cyclic,
            acc,
        };
        Ok((ev, (from, to)))
    }

    /// A note on candidate `c` (None when its runs are gone).
    pub(super) fn note_of(&self, c: &Candidate, why: Why) -> Option<Note> {
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
    /// [`reread`]. False when it consumed none of the runs (the automata and the floor stay
    /// where they were); true otherwise.
    pub(super) fn commit(&mut self, c: Candidate, out: &mut impl Sink) -> bool {
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
        let (reached, outcome) = self.reaching_outcome(c, before);
        if reached != c {
            out.note(|| self.note_of(&reached, Why::NotThatFar { matched: c.action }));
        }
        let c = reached;
        // A descent that ended lower than any rest before it has its rise still to come: a
        // crouch held low whose descent another action's pattern read and dropped. Its runs
        // stay open for a longer match to take it whole; any other match's are consumed.
        let open = provisional.is_none()
            && matches!(outcome, Err(Why::NotFarEnough))
            && self.front.history().sunk_below_rests(c.start, c.end) > FIDGET_MOVED_M;
        self.decider.clear();
        // The pause's answer was about the match now committed: what is pending next is
        // weighed afresh.
        self.hold = None;
        if !open {
            self.bank.reset();
            self.floor = c.end.wrapping_add(1);
        }
        // A too-brief match is not emitted (and a report of another candidate stands).
        let (ev, revises, held) = match outcome {
            Ok(o) => o,
            Err(why) => {
                out.note(|| self.note_of(&c, why));
                return !open;
            }
        };
        if let Some(b) = before.filter(|b| revises && b.action != ev.action) {
            // Only a wind-up revises the held event as another action.
            out.note(|| Some(wound_up(&b, ev.action)));
        }
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
        true
    }

    pub(super) fn emit_held(&mut self, h: Held, revises: bool, out: &mut impl Sink) {
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
}

/// The note on held event `b`, taken into the event of action `into` as its wind-up.
fn wound_up(b: &Held, into: u8) -> Note {
    Note {
        action: b.action,
        start_seq: b.start.0,
        start_us: b.start.1,
        end_seq: b.end.0,
        end_us: b.end.1,
        why: Why::WindUp { into },
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::super::fixtures::*;
    use super::*;
    use crate::pattern::tests::seq_library;
    use crate::pattern::Library;
    use crate::token::Token;
    use std::vec::Vec;

    #[test]
    fn a_cycles_slow_tail_is_no_pause() {
        let blob = hop_library(true);
        let lib = Library::from_bytes(&blob).unwrap();
        // After each hop 0.3 s of creeping on under the speed floor, then 0.3 s at rest: a
        // still run of 0.6 s, longer than ends the action (`CONTINUE_US`), of which the
        // figurine rested 0.3 s. The next hop continues the walk.
        let ev = run(&lib, &creeping_hops(3, 0.3, 0.3));
        assert_eq!(
            ev.iter().map(|e| e.revises).collect::<Vec<_>>(),
            [false, true, true],
            "{ev:?}"
        );
        // Resting 0.6 s it ends: the next hop is a new event.
        let ev = run(&lib, &creeping_hops(2, 0.3, 0.6));
        assert_eq!(
            ev.iter().map(|e| e.revises).collect::<Vec<_>>(),
            [false, false],
            "{ev:?}"
        );
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
    fn a_quick_turn_its_examples_were_as_quick_as_is_one() {
        // The twist of the test above, 57° in 0.12 s, read by a turn learnt from examples
        // that turned at least 0.9 rad.
        let blob = seq_library(&[(&[".Yp"], 0)]);
        let learnt = crate::pattern::tests::with_extents(&blob, &[(0.001, 0.9)]);
        let run_with = |briefest_us: u64| {
            let lib = crate::pattern::tests::with_briefest(&learnt, 0, briefest_us);
            run_noted(&Library::from_bytes(&lib).unwrap(), &quick_twist(1.0))
        };
        // Examples that took 0.4 s say nothing for a twist of 0.12: a flicker.
        let (ev, notes) = run_with(400_000);
        assert_eq!(ev, []);
        assert!(notes.iter().any(|n| n.why == Why::TooBrief), "{notes:?}");
        // Examples of 0.2 s, and it turned as far as the least of them: a turn.
        let (ev, _) = run_with(200_000);
        assert_eq!(ev.len(), 1, "{ev:?}");
        // The same twist run straight into a stroke aside: spelt in passing, not a gesture
        // from rest to rest as the examples were, so not a turn of its own (the phrase as a
        // whole may still be read as its nearest action).
        let lib = crate::pattern::tests::with_briefest(&learnt, 0, 200_000);
        let mut twist_then_aside = quick_twist(1.0);
        for s in twist_then_aside.iter_mut() {
            let t = s.t_us as f32 * 1e-6;
            s.pos[0] += 0.15 * ramp((t - 0.72) / 0.2);
        }
        let (ev, notes) = run_noted(&Library::from_bytes(&lib).unwrap(), &twist_then_aside);
        assert!(ev.iter().all(|e| e.end_us > 900_000), "{ev:?}");
        assert!(
            notes
                .iter()
                .any(|n| n.why == Why::TooBrief && n.end_us <= 750_000),
            "{notes:?}"
        );
        // Not learnt (a version 10 library): the floor alone.
        assert_eq!(run_with(0).0, []);
        // As brief as the examples, but short of where the least of them turned: a flicker.
        let short = crate::pattern::tests::with_extents(&blob, &[(0.001, 1.4)]);
        let lib = crate::pattern::tests::with_briefest(&short, 0, 200_000);
        let (ev, notes) = run_noted(&Library::from_bytes(&lib).unwrap(), &quick_twist(1.0));
        assert_eq!(ev, []);
        assert!(notes.iter().any(|n| n.why == Why::TooBrief), "{notes:?}");
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

    /// Still, a dip of `dip` m down in 0.4 s, held 0.3 s, then a jump: up 30 cm in 0.3 s and
    /// down again in 0.3 s, then still; 200 Hz.
    fn dip_then_jump(dip: f32) -> Vec<crate::intake::Sample> {
        let rate = 200.0f32;
        (0..(3.0 * rate) as u32)
            .map(|i| {
                let t = i as f32 / rate;
                let y = 1.0 - dip * ramp((t - 0.5) / 0.4) + (dip + 0.3) * ramp((t - 1.2) / 0.3)
                    - 0.3 * ramp((t - 1.5) / 0.3);
                crate::intake::Sample {
                    seq: i,
                    t_us: (t * 1e6) as u64,
                    pos: [0.3, y, 0.1],
                    quat: [1.0, 0.0, 0.0, 0.0],
                }
            })
            .collect()
    }

    #[test]
    fn a_dip_before_a_jump_is_the_jump_from_the_dip_on() {
        // 0 "crouch" `d`, 1 "jump" `u d`.
        let blob = seq_library(&[(&["d"], 0), (&["u", "d"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let folded = |ev: &[ActionEvent]| {
            let mut out: Vec<ActionEvent> = Vec::new();
            for e in ev {
                match out.last_mut() {
                    Some(last) if e.revises => *last = *e,
                    _ => out.push(*e),
                }
            }
            out
        };
        // A 4 cm dip is reported when the figurine pauses low, then taken into the jump.
        let ev = run(&lib, &dip_then_jump(0.04));
        assert_eq!(ev.first().map(|e| e.action), Some(0), "{ev:?}");
        let one = folded(&ev);
        assert_eq!(
            one.iter().map(|e| e.action).collect::<Vec<_>>(),
            [1],
            "{ev:?}"
        );
        assert!(
            one[0].start_us <= 520_000 && one[0].end_us >= 1_750_000,
            "{one:?}"
        );
        // `--why` says where the dip went.
        let (_, notes) = run_noted(&lib, &dip_then_jump(0.04));
        let wound = Why::WindUp { into: 1 };
        assert!(
            notes
                .iter()
                .any(|n| n.action == 0 && n.why == wound && n.end_us < 1_100_000),
            "{notes:?}"
        );
        // A 25 cm dip is more than a fifth of the jump's 85 cm (rising from the dip, then
        // landing): a crouch, then a jump.
        let ev = run(&lib, &dip_then_jump(0.25));
        assert_eq!(
            folded(&ev).iter().map(|e| e.action).collect::<Vec<_>>(),
            [0, 1],
            "{ev:?}"
        );
    }

    /// Still, then `pushes` strokes forward of 0.4 s and 10 cm each, the speed falling to
    /// nothing between them, then still; 120 Hz.
    fn pushes_forward(pushes: usize) -> Vec<crate::intake::Sample> {
        let rate = 120.0f32;
        let (still, stroke) = (0.6f32, 0.4f32);
        let total = 2.0 * still + pushes as f32 * stroke;
        (0..(total * rate) as u32)
            .map(|i| {
                let t = i as f32 / rate;
                let h = ((t - still) / stroke).clamp(0.0, pushes as f32);
                let k = libm::floorf(h);
                crate::intake::Sample {
                    seq: i,
                    t_us: (t * 1e6) as u64,
                    pos: [0.3, 1.0, 0.1 * (k + ramp(h - k))],
                    quat: [1.0, 0.0, 0.0, 0.0],
                }
            })
            .collect()
    }

    #[test]
    fn one_sweep_is_a_toy_carried_where_the_examples_made_several_pushes() {
        // A forward stroke, learnt from examples that went at least 20 cm.
        let blob = seq_library(&[(&["f"], 0)]);
        let learnt = crate::pattern::tests::with_extents(&blob, &[(0.2, 0.05)]);
        let carry = pushes_forward(1);
        let lib = Library::from_bytes(&learnt).unwrap();
        let (ev, notes) = run_noted(&lib, &carry);
        assert_eq!(ev.len(), 1, "sub-movements not learnt: {ev:?} {notes:?}");
        // Its examples each made two: a performance may be one push and its settling.
        let two = crate::pattern::tests::with_sweeps(&learnt, 0, 2);
        assert_eq!(run(&Library::from_bytes(&two).unwrap(), &carry).len(), 1);
        // Three or more: one sweep from rest to rest is a toy carried, three pushes are not.
        let three = crate::pattern::tests::with_sweeps(&learnt, 0, 3);
        let lib = Library::from_bytes(&three).unwrap();
        let (ev, notes) = run_noted(&lib, &carry);
        assert_eq!(ev, []);
        assert!(notes.iter().any(|n| n.why == Why::OneSweep), "{notes:?}");
        let (ev, notes) = run_noted(&lib, &pushes_forward(3));
        assert_eq!(ev.len(), 1, "{ev:?} {notes:?}");
    }

    #[test]
    fn a_match_that_went_less_far_than_its_action_is_the_near_action_that_went_as_far() {
        use crate::pattern::tests::{with_extents, with_travel};
        // A jab (25 cm out and back) that a dash's pattern `f b` matches exactly, and a
        // punch's `b f b` reads bar its wind-up; every shape alike.
        let blob = seq_library(&[(&["f", "b"], 0), (&["b", "f", "b"], 0)]);
        let jab = thrust_and_return(0.1);
        // Which of the two ended, in every example, as far from where it began as it went.
        let lib = |travels: [bool; 2]| {
            let mut l = with_extents(&blob, &[(0.3, 0.0), (0.1, 0.0)]);
            for (i, _) in travels.iter().enumerate().filter(|(_, t)| **t) {
                l = with_travel(&l, i, 0.3, 1.0);
            }
            l
        };
        // Every dash's example ended as far from where it began as it went: the jab, back
        // where it began, is no dash; it went as far as the punch's examples.
        let (ev, notes) = run_noted(&Library::from_bytes(&lib([true, false])).unwrap(), &jab);
        assert_eq!(
            ev.iter().map(|e| e.action).collect::<Vec<_>>(),
            [1],
            "{notes:?}"
        );
        assert!(
            notes
                .iter()
                .any(|n| n.action == 1 && n.why == Why::NotThatFar { matched: 0 }),
            "{notes:?}"
        );
        // A dash that need not travel: the dash it is.
        let ev = run(&Library::from_bytes(&lib([false, false])).unwrap(), &jab);
        assert_eq!(ev.iter().map(|e| e.action).collect::<Vec<_>>(), [0]);
        // Not as far as either's examples went (the punch's travelled too): nothing.
        let (ev, notes) = run_noted(&Library::from_bytes(&lib([true, true])).unwrap(), &jab);
        assert_eq!(ev, []);
        assert!(
            notes.iter().any(|n| n.why == Why::NotFarEnough),
            "{notes:?}"
        );
    }

    /// What a library of 0 "jump" `d+`, whose examples went 20 cm and landed 30 cm ahead, and
    /// 1 "crouch" `d+ u+` reads from `samples`: its events, and whether the jump's match was
    /// dropped as going less far than its examples.
    fn read_jump_and_crouch(samples: &[crate::intake::Sample]) -> (Vec<ActionEvent>, bool) {
        let blob = seq_library(&[(&["d"], 0), (&["d", "u"], 0)]);
        let blob = crate::pattern::tests::with_extents(&blob, &[(0.2, 0.01), (0.01, 0.01)]);
        let blob = crate::pattern::tests::with_travel(&blob, 0, 0.3, 0.5);
        let (ev, notes) = run_noted(&Library::from_bytes(&blob).unwrap(), samples);
        let dropped = notes
            .iter()
            .any(|n| n.action == 0 && n.why == Why::NotFarEnough);
        (ev, dropped)
    }

    #[test]
    fn a_descent_that_ended_below_every_rest_waits_for_its_rise() {
        // Held low longer than any hold waits: at the pause the jump's match of the descent
        // is committed and dropped (it landed nowhere), but the crouch is still to come.
        let (ev, dropped) = read_jump_and_crouch(&crouch_held_low(1.2));
        assert!(dropped);
        assert_eq!(
            ev.iter().map(|e| (e.action, e.revises)).collect::<Vec<_>>(),
            [(1, false)],
            "{ev:?}"
        );
        // From the descent (0.6–1.0 s; pitched in its first half, which `d` leaves out) to
        // the rise (2.2–2.6 s).
        assert!(
            ev[0].start_us < 1_000_000 && ev[0].end_us > 2_500_000,
            "{ev:?}"
        );
    }

    #[test]
    fn a_toy_set_back_down_where_it_rested_leaves_its_descent_behind() {
        // Set down to the height it rested at before the lift: the jump's dropped match of
        // the set-down is consumed, and the next lift is no crouch's rise.
        let (ev, dropped) = read_jump_and_crouch(&lifted_set_down_lifted());
        assert!(dropped);
        assert_eq!(ev, []);
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
}
