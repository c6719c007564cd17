//! Stage 6a — the match that ends at a token, and whether a longer one is under way.
//!
//! Each token that some action's automaton accepts ends a candidate: of every action whose
//! pattern matches here, the match of the highest merit ([`Candidate::merit_of`]: length less
//! edits, less the shape penalty). At a pause the pending candidate is held while another
//! action's match that began inside it is still under way ([`Recognizer::longer_in_progress`]):
//! a punch held at full reach after its forward stroke is not a run's stride.

use crate::alignment::{prefix_cost, FULL};
use crate::automaton::{best_start, prefix_alive, top_level, Matches};
use crate::history::{History, HISTORY_RUNS};
use crate::pattern::Library;
use crate::segment::{edits_fit, whole_cost, Candidate};
use crate::shape::{shape_cost, shape_of};
use crate::token::{Token, STILL};

use super::Recognizer;

impl<'lib> Recognizer<'lib> {
    /// The best match ending at run `end` (the newest token), among the actions whose
    /// automata accept there (`m`: each action's lowest cost, `u8::MAX` for none).
    pub(super) fn best_candidate(&self, end: u32, m: &Matches) -> Option<Candidate> {
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

    /// The first of two performances of one one-shot action that match `c` reads as one: `c`
    /// up to a stillness inside it, when the runs on either side are each a whole match of
    /// the action and cost less apart than together — the rule [`crate::follow`] applies to
    /// an event and the match after it, applied inside one match (the cheapest such cut, the
    /// earliest among equals). A punch waiting out a kick that may begin with it reads the
    /// next punch's wind-up into its retraction (`b f b b`, `b+` reads on), then the whole next
    /// punch within its edits; a run's strides after a breath cost nothing more as one run.
    /// None when there is no such cut, when `c` is exact, or cyclic (its cycles are one bout).
    // Once per commit, from two call sites: one out-of-line copy (flash).
    #[inline(never)]
    pub(super) fn first_of_two(&self, c: &Candidate) -> Option<Candidate> {
        // An exact match costs no less apart; a cyclic action's cycles are one bout.
        if c.cyclic || c.cost == 0 {
            return None;
        }
        let a = usize::from(c.action);
        let p = self.library.pattern(a)?;
        let hist = self.front.history();
        // The moving tokens of `c`, each one's run, and which follow a stillness (bit k).
        const _: () = assert!(HISTORY_RUNS < 64, "a token's stillness bit must fit a u64");
        let mut tok = [STILL; HISTORY_RUNS];
        let mut run = [0u32; HISTORY_RUNS];
        let mut after_still = 0u64;
        let mut n = 0usize;
        let mut i = c.start;
        for _ in 0..HISTORY_RUNS {
            let r = hist.get(i)?;
            if r.token == STILL {
                after_still |= 1 << n;
            } else {
                *tok.get_mut(n)? = r.token;
                *run.get_mut(n)? = i;
                n += 1;
            }
            if i == c.end {
                break;
            }
            i = i.wrapping_add(1);
        }
        let whole = |t: Option<&[Token]>| whole_cost(&p, t?);
        // The cheapest cut, the earliest among equals: (tokens before it, their cost).
        let mut best: Option<(usize, u8)> = None;
        let mut cheapest = c.cost;
        for k in (1..n).filter(|k| after_still >> k & 1 == 1) {
            let (Some(x), Some(y)) = (whole(tok.get(..k)), whole(tok.get(k..n))) else {
                continue;
            };
            if x.saturating_add(y) < cheapest {
                cheapest = x.saturating_add(y);
                best = Some((k, x));
            }
        }
        let (k, cost) = best?;
        let end = *run.get(k - 1)?;
        Some(Candidate {
            end,
            cost,
            len: k as u16,
            shape: shape_cost(
                shape_of(&self.library, a, hist, c.start, end).unwrap_or(0),
                k,
            ),
            ..*c
        })
    }

    /// Whether another action's match began with `p` (its own first part skipped) and is still
    /// under way: then a pause after `p` is a hold inside that longer gesture — a punch held at
    /// full reach after its forward stroke. When `p` needed a whole edit, a match under way
    /// that is not exact but costs less than `p` ([`prefix_cost`]) counts too, begun with `p`
    /// or at its second token: a crouch held low, whose descent a jump explained by taking a
    /// sideways wobble before it as its lead-in and leaving its hop out. Some(the hold to wait
    /// for, µs, from [`under_way`]) when one is; None when none is.
    // Once per pause at most: kept out of the per-sample path (flash, not speed).
    #[cold]
    #[inline(never)]
    pub(super) fn longer_in_progress(&self, p: &Candidate) -> Option<u64> {
        // The moving runs from the floor to the newest, oldest first.
        let hist = self.front.history();
        let newest = hist.newest()?;
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
        let ps = at_start?;
        let moving = tok.get(..n).unwrap_or(&[]);
        // When `p` itself needed a whole edit, another action that explains the same tokens
        // more cheaply and is not finished is as good a reason to wait: a crouch held low
        // after going down with a wobble, where a jump without its hop matched the descent.
        let tolerance = if p.cost >= FULL { p.cost - 1 } else { 0 };
        let alive_from = |from: usize, skip_first: bool| {
            let tokens = moving.get(from..).unwrap_or(&[]);
            under_way(&self.library, p, tokens, skip_first, tolerance)
        };
        // Begun with the pending candidate, but without its own first part; or, tolerantly,
        // with it or one token into it.
        alive_from(ps, true).or_else(|| {
            if tolerance > 0 {
                alive_from(ps, false).or_else(|| alive_from(ps + 1, false))
            } else {
                None
            }
        })
    }
}

/// Whether an action other than the `pending` candidate's has `tokens` (at least one) as the
/// start of a match that is not over ([`prefix_alive`]; `skip_first`: its own first part
/// skipped) — or, unless `skip_first`, one that costs at most `tolerance` half-edits so far
/// ([`prefix_cost`]). Some(hold, µs) when one has: the longest stillness inside the examples
/// of those whose shortest match is longer than `pending` (0 for none: a match as long as an
/// action's least is no piece of it); None when none has.
// Up to five calls per pause: one out-of-line copy (flash).
#[inline(never)]
fn under_way(
    lib: &Library<'_>,
    pending: &Candidate,
    tokens: &[Token],
    skip_first: bool,
    tolerance: u8,
) -> Option<u64> {
    // Nothing begun is nothing under way (every pattern's start is "not over").
    if tokens.is_empty() {
        return None;
    }
    (0..lib.len())
        .filter_map(|a| {
            let pat = lib.pattern(a)?;
            // Its match so far covers all of the tokens and needs more: a longer one.
            let alive = a != usize::from(pending.action)
                && (prefix_alive(&pat, tokens, skip_first)
                    || (!skip_first
                        && tolerance > 0
                        && prefix_cost(&pat, tokens, tolerance.min(top_level(&pat) as u8))
                            .is_some()));
            // A pending match shorter than that action's least is a piece of it: wait as long
            // as its examples held still inside.
            alive.then(|| {
                if usize::from(pending.len) < pat.min_len() {
                    lib.hold_us(a)
                } else {
                    0
                }
            })
        })
        .max()
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::super::fixtures::*;
    use super::*;
    use crate::intake::Sample;
    use crate::pattern::tests::seq_library;
    use std::vec::Vec;

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
    fn a_piece_of_an_action_under_way_waits_as_long_as_its_examples_held() {
        // 0 "jump" `d.Xp d`: the descent alone, exactly; 1 "crouch" `d.Xp d u`, not finished
        // after the descent. Held low for a second, longer than the usual hold.
        let blob = crate::pattern::tests::seq_library_ending(&[
            (&["d.Xp", "d"], 0, 2),
            (&["d.Xp", "d", "u"], 0, 3),
        ]);
        let blob = crate::pattern::tests::with_extents(&blob, &[(0.01, 0.01), (0.01, 0.01)]);
        let low = crouch_held_low(1.0);
        let last = |blob: &[u8]| {
            let lib = Library::from_bytes(blob).unwrap();
            let ev = run(&lib, &low);
            ev.last()
                .map(|e| (e.action, e.start_us < 800_000 && e.end_us > 1_900_000))
        };
        // Not learnt to hold that long: the descent is committed as the shorter action.
        assert_ne!(last(&blob), Some((1, true)));
        // The crouch's examples held 1.1 s: the descent waits for its rise.
        let held = crate::pattern::tests::with_hold(&blob, 1, 1_100_000);
        assert_eq!(last(&held), Some((1, true)));
        // A hold learnt by the pending match's own action does not make it wait.
        let own = crate::pattern::tests::with_hold(&blob, 0, 1_100_000);
        assert_ne!(last(&own), Some((1, true)));
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
        let pending = |action: u8| Candidate {
            action,
            start: 0,
            end: 0,
            cost: 0,
            len: 1,
            min_len: 1,
            positions: 1,
            cyclic: false,
            shape: 0,
        };
        assert_eq!(under_way(&lib, &pending(0), &[d], false, 0), Some(0));
        // Not the pending candidate's own action, and not from no tokens at all.
        assert_eq!(under_way(&lib, &pending(1), &[d], false, 0), None);
        assert_eq!(under_way(&lib, &pending(0), &[], false, 1), None);
        // The one-token pending match is a piece of "d u": it waits as long as that held.
        let held = crate::pattern::tests::with_hold(
            &crate::pattern::tests::with_extents(&blob, &[(0.01, 0.01), (0.01, 0.01)]),
            1,
            900_000,
        );
        let lib = Library::from_bytes(&held).unwrap();
        assert_eq!(under_way(&lib, &pending(0), &[d], false, 0), Some(900_000));
    }

    #[test]
    fn one_match_across_a_stillness_is_two_performances_when_they_cost_less_apart() {
        // `b+ f+ b+`, a punch, played twice with a breath between (`b f b _ b f b`): one
        // match over all six strokes needs two edits; apart, each punch is exact.
        let blob = seq_library(&[(&["b", "f", "b"], 2)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let (back, fwd) = ([0.0, 0.0, -1.0], [0.0, 0.0, 1.0]);
        let mut rec = Recognizer::new(lib, None);
        for s in &quick_strokes(&[back, fwd, back, back, fwd, back]) {
            rec.push(s, |_| {});
        }
        let hist = rec.front.history();
        let (oldest, newest) = (hist.oldest().unwrap(), hist.newest().unwrap());
        let moving: Vec<u32> = (oldest..=newest)
            .filter(|&i| hist.get(i).is_some_and(|r| r.token != STILL))
            .collect();
        assert_eq!(moving.len(), 6, "one run per stroke");
        let whole = Candidate {
            action: 0,
            start: moving[0],
            end: moving[5],
            cost: 2 * FULL,
            len: 6,
            min_len: 3,
            positions: 3,
            cyclic: false,
            shape: 0,
        };
        // The first punch, cut at the cheapest pause (not after `b f`, which needs an edit
        // and leaves `b b f b`).
        let first = rec.first_of_two(&whole).expect("two punches");
        assert_eq!(
            (first.start, first.end, first.cost, first.len),
            (moving[0], moving[2], 0, 3)
        );
        // Read as one no dearer than apart, it is one performance (a run's strides after a
        // breath); and a cyclic action's cycles are one bout.
        assert_eq!(rec.first_of_two(&Candidate { cost: 0, ..whole }), None);
        assert_eq!(
            rec.first_of_two(&Candidate {
                cyclic: true,
                ..whole
            }),
            None
        );
        // A match that never paused is not cut.
        assert_eq!(
            rec.first_of_two(&Candidate {
                end: moving[0],
                len: 1,
                ..whole
            }),
            None
        );
    }
}
