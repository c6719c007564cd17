//! Stage 6c — what a match right after an event is to that event: its next piece, its rest,
//! its settling, or a new action.
//!
//! The last event stays *held* until [`CONTINUE_US`] of stillness have passed after it (or its
//! runs leave the history) — for a cyclic action's own next cycle, of rest counted from
//! where its strokes settled, so that a noisy tracker's slow stride ends are no pause
//! (the recognizer's commit). A match committed while
//! it is held, with nothing but stillness and at most [`CONTINUE_GAP_RUNS`] moving runs
//! between them, is one of:
//!
//! - **its next piece**: the same action, and the runs from the held event's start to the
//!   match's end are together one whole match of it, costing no more than the two matches
//!   apart — for a cyclic action any next cycle. A turn made in two twists with a breath
//!   between is one turn; two punches are still two punches, since `b f b b f b` is no punch,
//!   and two jumps two jumps, though one jump's edit budget could swallow the second. The
//!   held event is extended.
//! - **its rest**: another action's match such that the held action's pattern over both costs
//!   less than the two matches apart. A throw committed at the pause after its release, whose
//!   return stroke then matched a kick, is one throw; a walk's next stride first read as a
//!   poor kick is the walk going on. The held event is extended.
//! - **its settling**: another action's match with under [`SETTLE_SHARE`] of the held event's
//!   motion. A figurine that lands from a jump and gives at the knees (`d u`, a few
//!   millimetres) has not crouched; nothing is reported.
//! - **what it wound up for**: the settling's mirror — the held event was one stroke, under
//!   [`SETTLE_SHARE`] of the match's motion, and went against the match's first stroke
//!   (`reversed`). A dip before a jump, a counter-turn before a spin, a backswing before a
//!   kick is the gesture's wind-up: the match takes the held event's place, from its start,
//!   as a revision of it.
//! - otherwise, a new event.
//!
//! Past [`CONTINUE_US`] the event stays held only as long as its action's examples held still
//! inside ([`Library::hold_us`]: a crouch held low, then risen from), and only what it wound up
//! for or its rest may then follow it — its rest being another action's match over which the
//! held action's pattern costs no more than the two apart, and which alone is not the held
//! action again: a repetition after a hold is a new event.
//!
//! Motion is measured as path length plus [`ARM_M`] × the angle turned, so that a wave or a
//! turn (much rotation, little path) is not mistaken for a settling. Everything here runs at
//! commits only, never per sample.

use crate::features::{Accum, SPEED};
use crate::history::{History, HISTORY_RUNS};
use crate::pattern::Library;
#[cfg(doc)]
use crate::segment::CONTINUE_US;
use crate::segment::{whole_cost, Candidate, CONTINUE_GAP_RUNS};
use crate::token::{token_signs, Token, ARM_M, STILL, TURN};

/// Share of the held event's motion (path + [`ARM_M`] × angle) below which another action's
/// match right after it is its settling, not an action. A jump's landing gives 2–5 cm against
/// the jump's 30–60 cm; a crouch played after a jump at the same scale has a quarter or more.
pub const SETTLE_SHARE: f32 = 0.2;

/// The last emitted event, while a match right after it may still continue it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Held {
    /// Action index.
    pub action: u8,
    /// First run of its match (absolute history index).
    pub start_run: u32,
    /// Input sample (seq, µs) where it starts.
    pub start: (u32, u64),
    /// Input sample (seq, µs) where it ends.
    pub end: (u32, u64),
    /// Last run of its match (absolute history index).
    pub end_run: u32,
    /// Edit distance reported, whole edits.
    pub distance: u8,
    /// Weighted cost of its match, half-edits.
    pub cost: u8,
    /// Whether its action is cyclic: its pauses count from where its motion settled
    /// ([`crate::history::Run::rested_us`]).
    pub cyclic: bool,
    /// Feature sums over its motion phrase.
    pub acc: Accum,
}

/// What a match is to the held event before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Follow {
    /// Its next piece (same action).
    Continues,
    /// Its rest: the held action's whole match over both now costs this much (half-edits).
    Completes(u8),
    /// Its settling: nothing to report.
    Settles,
    /// The held event was its wind-up (one stroke against its first, under [`SETTLE_SHARE`] of
    /// its motion): the match takes its place, reported as a revision of it from its start.
    LeadsIn,
    /// A new event.
    New,
}

/// What match `c` is to the held event `h` (see the module docs); `late`: a stillness longer
/// than [`CONTINUE_US`] lies between them.
// Out of line: commits only, and for flash. One pass over the runs from `h`'s start to `c`'s
// end gathers all it needs.
#[inline(never)]
pub(crate) fn follow(
    lib: &Library<'_>,
    hist: &History,
    h: &Held,
    c: &Candidate,
    late: bool,
) -> Follow {
    let mut tok = [STILL; HISTORY_RUNS];
    let (mut n, mut between, mut mine) = (0usize, 0usize, 0.0f32);
    // The held event's stroke (TURN, which has no direction, when it made several) and `c`'s
    // first.
    let (mut held_last, mut c_first) = (STILL, STILL);
    // Moving tokens before `c`'s first.
    let mut before_c = 0usize;
    // A held event too long to read whole with what follows (a long walk) is read from its
    // end: a next cycle still continues it, a settling is still one.
    let mut whole = c.end.wrapping_sub(h.start_run) < HISTORY_RUNS as u32;
    let mut i = if whole {
        h.start_run
    } else {
        h.end_run.wrapping_add(1)
    };
    for _ in 0..HISTORY_RUNS {
        let r = hist.get(i);
        let moving = r.is_none_or(|r| r.token != STILL);
        let after_h = i.wrapping_sub(h.start_run) > h.end_run.wrapping_sub(h.start_run);
        let in_c = i.wrapping_sub(h.start_run) >= c.start.wrapping_sub(h.start_run);
        if after_h && !in_c {
            between += usize::from(moving);
        }
        match r {
            Some(r) => {
                if moving && !after_h {
                    held_last = if held_last == STILL { r.token } else { TURN };
                }
                if in_c {
                    mine += motion(&r.acc);
                    if moving && c_first == STILL {
                        c_first = r.token;
                    }
                }
                if moving {
                    if !in_c {
                        before_c = n + 1;
                    }
                    match tok.get_mut(n) {
                        Some(t) => *t = r.token,
                        None => whole = false,
                    }
                    n += 1;
                }
            }
            None => whole = false,
        }
        if i == c.end {
            break;
        }
        i = i.wrapping_add(1);
    }
    // Only stillness and a few strokes the two matches left out at their edges (a hop's
    // take-off before its `uf`) may lie between.
    if between > CONTINUE_GAP_RUNS {
        return Follow::New;
    }
    // The held action's whole match over tokens `tok[from..n]`.
    let held_cost = |from: usize| {
        lib.pattern(usize::from(h.action))
            .filter(|_| whole)
            .and_then(|p| whole_cost(&p, tok.get(from..n)?))
    };
    // A wind-up first, whenever the event is still held: a held stroke that small is no
    // action whose rest the match could be (a kick's backswing, read as a punch, is not
    // completed by the kick).
    if h.action != c.action && motion(&h.acc) < SETTLE_SHARE * mine && reversed(held_last, c_first)
    {
        return Follow::LeadsIn;
    }
    let cost = held_cost(0);
    if late {
        // After a longer stillness than any pause inside an action: only what finishes a
        // hold its action's examples made, never a repetition of the held action.
        return match cost {
            Some(v)
                if h.action != c.action
                    && v <= h.cost.saturating_add(c.cost)
                    && held_cost(before_c).is_none() =>
            {
                Follow::Completes(v)
            }
            _ => Follow::New,
        };
    }
    if h.action == c.action {
        // One match over both must be no worse than the two apart: two jumps with a breath
        // between are two jumps, even when one jump's edit budget could swallow the second.
        return if c.cyclic || cost.is_some_and(|v| v <= h.cost.saturating_add(c.cost)) {
            Follow::Continues
        } else {
            Follow::New
        };
    }
    match cost {
        Some(v) if v < h.cost.saturating_add(c.cost) => Follow::Completes(v),
        _ if mine < SETTLE_SHARE * motion(&h.acc) => Follow::Settles,
        _ => Follow::New,
    }
}

/// Whether stroke `a` is stroke `b` reversed: on every axis both move along (or turn about),
/// they go opposite ways, and there is one — a dip before a rise (`d`, `u`), a backswing
/// before a swing (`b`, `f`), a counter-turn before a spin (`.Yn`, `.Yp`).
fn reversed(a: Token, b: Token) -> bool {
    let ((al, ar), (bl, br)) = (token_signs(a), token_signs(b));
    let mut opposite = false;
    for (x, y) in al.iter().chain(&ar).zip(bl.iter().chain(&br)) {
        match x * y {
            1 => return false,
            -1 => opposite = true,
            _ => {}
        }
    }
    opposite
}

/// Path length plus [`ARM_M`] × angle turned, as sums over ticks (÷ the tick rate, metres;
/// only ratios are used).
fn motion(a: &Accum) -> f32 {
    a.sum[SPEED] + ARM_M * a.turn_sum()
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::alignment::FULL;
    use crate::pattern::tests::seq_library;
    use crate::token::parse_token;

    /// A history of runs, each `(token, motion)`: `motion` goes into the speed sum (STILL runs
    /// are written `_`). Returns it with the absolute index of the first run.
    fn history(runs: &[(&str, f32)]) -> (History, u32) {
        let mut h = History::new();
        let mut first = None;
        for (k, (t, m)) in runs.iter().enumerate() {
            let mut acc = Accum::new();
            acc.sum[SPEED] = *m;
            acc.n = 1;
            let t_us = 100_000 * k as u64;
            let i = h.open(parse_token(t).unwrap(), (k as u32, t_us), acc);
            first.get_or_insert(i);
        }
        (h, first.unwrap_or(0))
    }

    fn held(hist: &History, action: u8, from: u32, to: u32, cost: u8) -> Held {
        Held {
            action,
            start_run: from,
            start: (0, 0),
            end: (0, 0),
            end_run: to,
            distance: cost.div_ceil(FULL),
            cost,
            cyclic: false,
            acc: hist.accum(from, to),
        }
    }

    fn cand(action: u8, start: u32, end: u32, cyclic: bool) -> Candidate {
        Candidate {
            action,
            start,
            end,
            cost: 0,
            len: (end - start + 1) as u16,
            min_len: 1,
            positions: 1,
            cyclic,
            shape: 0,
        }
    }

    #[test]
    fn a_second_piece_continues_only_when_both_are_one_match() {
        // 0 turn `.Yn+`, 1 punch `b+ f+ b+`.
        let blob = seq_library(&[(&[".Yn"], 0), (&["b", "f", "b"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        // A turn in two twists with a breath between: one turn.
        let (hist, o) = history(&[(".Yn", 1.0), ("_", 0.0), (".Yn", 1.0)]);
        let h = held(&hist, 0, o, o, 0);
        assert_eq!(
            follow(&lib, &hist, &h, &cand(0, o + 2, o + 2, false), false),
            Follow::Continues
        );
        // Two punches are two: `b f b b f b` is no punch.
        let (hist, o) = history(&[
            ("b", 1.0),
            ("f", 1.0),
            ("b", 1.0),
            ("_", 0.0),
            ("b", 1.0),
            ("f", 1.0),
            ("b", 1.0),
        ]);
        let h = held(&hist, 1, o, o + 2, 0);
        assert_eq!(
            follow(&lib, &hist, &h, &cand(1, o + 4, o + 6, false), false),
            Follow::New
        );
        // … unless the action is cyclic: its next cycle continues it.
        assert_eq!(
            follow(&lib, &hist, &h, &cand(1, o + 4, o + 6, true), false),
            Follow::Continues
        );
    }

    #[test]
    fn a_repeat_that_one_match_swallows_only_at_a_cost_is_a_new_event() {
        // A jump `d+ u+ d+` allowed two edits: `d u d d u d` is one jump with two extra
        // strokes, but two exact jumps are the better reading.
        let blob = seq_library(&[(&["d", "u", "d"], 2)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let (hist, o) = history(&[
            ("d", 1.0),
            ("u", 1.0),
            ("d", 1.0),
            ("_", 0.0),
            ("d", 1.0),
            ("u", 1.0),
            ("d", 1.0),
        ]);
        let h = held(&hist, 0, o, o + 2, 0);
        assert_eq!(
            follow(&lib, &hist, &h, &cand(0, o + 4, o + 6, false), false),
            Follow::New
        );
        // A first piece that was itself a poor match (two edits) is completed by the second.
        let (hist, o) = history(&[("d", 1.0), ("_", 0.0), ("u", 1.0), ("d", 1.0)]);
        let mut h = held(&hist, 0, o, o, 2 * FULL);
        h.distance = 2;
        assert_eq!(
            follow(&lib, &hist, &h, &cand(0, o + 2, o + 3, false), false),
            Follow::Continues
        );
    }

    #[test]
    fn a_long_event_is_read_from_its_end() {
        let blob = seq_library(&[(&["uf", "df"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        // A walk of 21 hops (42 runs, its first gone from the history), a breath, one more.
        let mut runs = std::vec::Vec::new();
        for _ in 0..21 {
            runs.extend([("uf", 1.0), ("df", 1.0)]);
        }
        runs.extend([("_", 0.0), ("uf", 1.0), ("df", 1.0)]);
        let (hist, o) = history(&runs);
        assert!(hist.get(o).is_none());
        let h = held(&hist, 0, o, o + 41, 0);
        let next = |cyclic| follow(&lib, &hist, &h, &cand(0, o + 43, o + 44, cyclic), false);
        // Its next cycle continues it; a one-shot action cannot be read whole: a new event.
        assert_eq!(next(true), Follow::Continues);
        assert_eq!(next(false), Follow::New);
    }

    #[test]
    fn another_action_that_completes_the_held_one_is_its_rest() {
        // 0 throw `ub+ f+ db+` (one edit), 1 `db+ u+`.
        let blob = seq_library(&[(&["ub", "f", "db"], 1), (&["db", "u"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let (hist, o) = history(&[("ub", 1.0), ("f", 1.0), ("_", 0.0), ("db", 1.0), ("u", 1.0)]);
        // The throw was committed at the pause after its release, its `db` left out.
        let h = held(&hist, 0, o, o + 1, FULL);
        let rest = cand(1, o + 3, o + 4, false);
        // `ub f db u`: one added stroke, where the throw alone had one left out: not cheaper.
        assert_eq!(follow(&lib, &hist, &h, &rest, false), Follow::New);
        // … unless that other reading needed more edits than the throw over both does: one
        // match no worse than the two apart (a walk's next stride first read as a poor kick).
        let poor = Candidate {
            cost: 2 * FULL,
            ..rest
        };
        assert_eq!(
            follow(&lib, &hist, &h, &poor, false),
            Follow::Completes(FULL)
        );
        // Its return alone (`db`) completes it exactly.
        let rest = cand(1, o + 3, o + 3, false);
        assert_eq!(follow(&lib, &hist, &h, &rest, false), Follow::Completes(0));
        // Not when the held match was exact already.
        let h = held(&hist, 0, o, o + 1, 0);
        assert_eq!(follow(&lib, &hist, &h, &rest, false), Follow::New);
    }

    #[test]
    fn after_a_long_hold_only_the_held_actions_rest_continues_it() {
        // 0 crouch `d+ u+`, 1 `u+ r+` (a hop aside), 2 `d+ u+`.
        let blob = seq_library(&[(&["d", "u"], 0), (&["u", "r"], 0), (&["d", "u"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        // The crouch was committed at its descent (its rise left out: one edit).
        let (hist, o) = history(&[("d", 1.0), ("_", 0.0), ("u", 1.0), ("r", 1.0)]);
        let h = held(&hist, 0, o, o, FULL);
        // Risen from after a hold longer than the usual pause: `d _ u` is one crouch, cheaper
        // than the crouch that left its rise out and a hop that added a stroke.
        let rise = Candidate {
            cost: FULL,
            ..cand(1, o + 2, o + 3, false)
        };
        let late = |c: &Candidate| follow(&lib, &hist, &h, c, true);
        assert_eq!(late(&rise), Follow::New, "`d u r` is no crouch");
        let rise = Candidate {
            cost: FULL,
            ..cand(1, o + 2, o + 2, false)
        };
        assert_eq!(late(&rise), Follow::Completes(0));
        // A whole second crouch after the hold is a repetition, whatever reads it.
        let (hist, o) = history(&[("d", 1.0), ("_", 0.0), ("d", 1.0), ("u", 1.0)]);
        let h = held(&hist, 0, o, o, FULL);
        let again = Candidate {
            cost: FULL,
            ..cand(2, o + 2, o + 3, false)
        };
        assert_eq!(follow(&lib, &hist, &h, &again, true), Follow::New);
        // The same action again is never its next piece after a long hold.
        assert_eq!(
            follow(&lib, &hist, &h, &cand(0, o + 2, o + 3, false), true),
            Follow::New
        );
    }

    #[test]
    fn a_small_motion_right_after_an_event_is_its_settling() {
        // 0 jump `d+ u+ d+`, 1 crouch `d+ u+`.
        let blob = seq_library(&[(&["d", "u", "d"], 0), (&["d", "u"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let jump_then = |give: f32| {
            history(&[
                ("d", 5.0),
                ("u", 20.0),
                ("d", 20.0),
                ("_", 0.0),
                ("d", give),
                ("u", give),
            ])
        };
        // Landing gives 2 × 2 against 45: settling.
        let (hist, o) = jump_then(2.0);
        let h = held(&hist, 0, o, o + 2, 0);
        assert_eq!(
            follow(&lib, &hist, &h, &cand(1, o + 4, o + 5, false), false),
            Follow::Settles
        );
        // A real crouch, 2 × 6 against 45: an action.
        let (hist, o) = jump_then(6.0);
        let h = held(&hist, 0, o, o + 2, 0);
        assert_eq!(
            follow(&lib, &hist, &h, &cand(1, o + 4, o + 5, false), false),
            Follow::New
        );
    }

    #[test]
    fn a_small_stroke_against_the_action_after_it_is_its_wind_up() {
        // 0 crouch `d+`, 1 jump `u+ d+`, 2 turn `.Yp+`, 3 bow `.Xp+ .Xn+`, 4 run `f+`.
        let blob = seq_library(&[
            (&["d"], 0),
            (&["u", "d"], 0),
            (&[".Yp"], 0),
            (&[".Xp", ".Xn"], 0),
            (&["f"], 0),
        ]);
        let lib = Library::from_bytes(&blob).unwrap();
        let dip_then_jump = |dip: f32| history(&[("d", dip), ("_", 0.0), ("u", 20.0), ("d", 20.0)]);
        // A 2 cm dip before a 40 cm jump: the jump's wind-up.
        let (hist, o) = dip_then_jump(2.0);
        let h = held(&hist, 0, o, o, 0);
        let jump = cand(1, o + 2, o + 3, false);
        assert_eq!(follow(&lib, &hist, &h, &jump, false), Follow::LeadsIn);
        // As far as a fifth of the jump: a crouch of its own.
        let (hist, o) = dip_then_jump(8.0);
        let h = held(&hist, 0, o, o, 0);
        assert_eq!(follow(&lib, &hist, &h, &jump, false), Follow::New);
        // A small turn before a run is no wind-up: it does not go against the run's stroke.
        let (hist, o) = history(&[(".Yp", 2.0), ("_", 0.0), ("f", 40.0)]);
        let h = held(&hist, 2, o, o, 0);
        let run = cand(4, o + 2, o + 2, false);
        assert_eq!(follow(&lib, &hist, &h, &run, false), Follow::New);
        // Nor is a whole bow, there and back, though it ends against the run's pitch.
        let (hist, o) = history(&[(".Xp", 1.0), (".Xn", 1.0), ("_", 0.0), ("f.Xp", 40.0)]);
        let h = held(&hist, 3, o, o + 1, 0);
        let run = cand(4, o + 3, o + 3, false);
        assert_eq!(follow(&lib, &hist, &h, &run, false), Follow::New);
        // After a longer stillness than the usual pause, held by its action's learnt hold
        // (a crouch held low), it is a wind-up all the same.
        let (hist, o) = dip_then_jump(2.0);
        let h = held(&hist, 0, o, o, 0);
        assert_eq!(follow(&lib, &hist, &h, &jump, true), Follow::LeadsIn);
    }

    #[test]
    fn a_stroke_reversed_goes_the_other_way_on_every_axis_both_use() {
        let t = |n: &str| parse_token(n).unwrap();
        assert!(reversed(t("d"), t("u")));
        assert!(reversed(t("b"), t("uf")));
        assert!(reversed(t(".Yn"), t(".YpZn")));
        assert!(reversed(t("d.Xp"), t("u")));
        // One axis the same way: not reversed; no shared axis: not reversed.
        assert!(!reversed(t("db"), t("df")));
        assert!(!reversed(t("d"), t("f")));
        assert!(!reversed(t(".Yp"), t("lb")));
        assert!(!reversed(STILL, t("u")));
        assert!(!reversed(crate::token::TURN, t("u")));
    }

    #[test]
    fn only_what_comes_right_after_counts() {
        let blob = seq_library(&[(&["d", "u", "d"], 0), (&["d", "u"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let with_between = |between: &[&'static str]| {
            let mut runs = std::vec![("d", 5.0), ("u", 20.0), ("d", 20.0)];
            runs.extend(between.iter().map(|t| (*t, 1.0)));
            runs.extend([("d", 2.0), ("u", 2.0)]);
            let (hist, o) = history(&runs);
            let h = held(&hist, 0, o, o + 2, 0);
            let n = between.len() as u32;
            follow(
                &lib,
                &hist,
                &h,
                &cand(1, o + 3 + n, o + 4 + n, false),
                false,
            )
        };
        // Up to CONTINUE_GAP_RUNS strokes between: still its settling.
        assert_eq!(with_between(&["_", "f", "b", "_"]), Follow::Settles);
        // One more: a new event.
        assert_eq!(with_between(&["f", "b", "f"]), Follow::New);
    }
}
