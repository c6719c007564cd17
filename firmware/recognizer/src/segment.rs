//! Stage 6 — online segment decision: when to commit which action.
//!
//! Each token that completes one or more approximate matches yields candidates (action, first
//! and last run, weighted cost, length in tokens): per action the longest match ending there
//! at the lowest cost (for a cyclic action, the one of the highest merit within half an edit
//! more). A pending candidate is replaced by an overlapping one of higher merit
//! `4·length − 3·cost − shape`, the cost in half-edits ([`crate::alignment`]: a token that
//! differs from the pattern only in its rotation, or by 45° in its direction, costs half an
//! edit), the shape up to one token per [`SHAPE_TOKENS`](crate::shape::SHAPE_TOKENS) tokens when the matched motion moves
//! unlike the action's examples did ([`shape_cost`](crate::shape::shape_cost)) — near-ties go to the longest action, as
//! in seed 000 §7.5, and an action that keeps
//! extending (a walk of several hops) grows instead of being cut. The pending candidate is
//! committed when
//! - a candidate appears that starts after it (the next action has begun),
//! - [`LOOKAHEAD_TOKENS`] tokens have passed after its end without a better overlapping one,
//! - the figurine has been still for [`PAUSE_US`] after it ([`CYCLIC_PAUSE_US`] for an action
//!   whose pattern repeats as a whole; up to [`HOLD_US`] — [`INEXACT_HOLD_US`] when it
//!   needed near substitutions, [`GAPPED_HOLD_US`] when it needed a whole edit — while another
//!   action has matched further than it exactly, or, for a candidate that needed a whole
//!   edit, at a lower cost, and may go on after the hold; and, when the pending candidate is
//!   shorter than that action's shortest match, a piece of it, as long as that action's
//!   examples held still inside ([`crate::pattern::Library::hold_us`])), or
//! - the stream ends ([`crate::Recognizer::flush`]).
//!
//! After a commit, matching restarts just after the committed segment (the tokens seen during
//! the look-ahead are replayed), so segments never overlap. A gesture that stands alone and
//! that no action matched within its bound is offered to [`crate::nearest`] once the figurine
//! has paused after it.

use crate::alignment::{weighted_cost, FULL};
use crate::pattern::Pattern;
use crate::token::Token;

/// Non-STILL tokens to wait after a candidate's end for a longer/better one.
pub const LOOKAHEAD_TOKENS: u8 = 4;
/// Stillness after a candidate that commits it, µs.
pub const PAUSE_US: u64 = 120_000;
/// Stillness that commits a cyclic action (whose pattern repeats as a whole), µs: a walk
/// pauses briefly between hops without ending. (The recognizer reports it provisionally
/// after [`PAUSE_US`] already, so this costs no latency.)
pub const CYCLIC_PAUSE_US: u64 = 400_000;
/// Stillness after an event up to which a match may still continue it (a cyclic action's
/// next cycle, a one-shot action's second piece or rest) or be its settling
/// ([`crate::follow`]), µs. For a cyclic event's own next cycle it counts from where the
/// strokes settled ([`crate::history::Run::rested_us`]): under a noisy tracker their slow
/// tails fall below the floor, and lengthen the still run between two strides without being
/// a pause.
pub const CONTINUE_US: u64 = 500_000;
/// Moving runs that may lie between an event and a match that continues it: strokes the two
/// matches left out at their edges (a hop's take-off before its `uf`).
pub const CONTINUE_GAP_RUNS: usize = 2;
/// Stillness inside a longer action that does not yet commit a shorter pending one, µs: a
/// punch held at full reach, a crouch held low.
pub const HOLD_US: u64 = 500_000;
/// [`HOLD_US`] for a pending candidate that needed edits, µs: while an action that matched
/// further exactly may go on, an inexact match is the weaker reading of a long hold (a crouch
/// held low, whose downward strokes a jump also explains by leaving out its rise).
pub const INEXACT_HOLD_US: u64 = 1_000_000;
/// [`HOLD_US`] for a pending candidate that needed a whole edit or more (a stroke left out or
/// added, not just a near substitution), µs: a crouch held low for a second or more, whose
/// downward strokes a jump explains by leaving out its rise, while the crouch that matches
/// exactly once the figurine rises is still under way.
pub const GAPPED_HOLD_US: u64 = 2_000_000;
/// Edits a match may spend per token it covers, as (edits, tokens): 2 per 5. A pattern's own
/// bound (up to [`crate::pattern::MAX_EDITS`]) caps the total; this share keeps a short match
/// from being mostly edits, so the bound can be generous for long performances without
/// turning a lone stroke into any action.
pub const EDIT_SHARE: (usize, usize) = (2, 5);

/// Whether a match over `len` tokens (or the pattern's shortest match, if longer) that costs
/// `cost` half-edits ([`crate::alignment`]) is close enough ([`EDIT_SHARE`]).
pub const fn edits_fit(cost: u8, len: usize) -> bool {
    (cost as usize) * EDIT_SHARE.1 <= EDIT_SHARE.0 * 2 * len
}

/// The cost (half-edits) of reading all of `tokens` as one whole match of `p`, when that is
/// within the pattern's edit bound and [`EDIT_SHARE`]; None otherwise. What [`crate::follow`]
/// weighs an event and the match after it by, and the recognizer one match's two halves.
pub fn whole_cost(p: &Pattern<'_>, tokens: &[Token]) -> Option<u8> {
    let bound = (usize::from(FULL) * p.max_edits()).min(usize::from(u8::MAX)) as u8;
    weighted_cost(p, tokens, bound).filter(|&v| edits_fit(v, tokens.len().max(p.min_len())))
}

/// Shortest action that is emitted, µs (first run's start to last run's end), unless it
/// turned [`BRIEF_TURN_RAD`].
pub const MIN_ACTION_US: u64 = 150_000;
/// Angle a match briefer than [`MIN_ACTION_US`] must have turned to be emitted all the same,
/// rad (the turning about the three object axes summed): a quarter turn. A flicker does not
/// turn the figurine that far; a sudden turn does, in little more than a tenth of a second.
pub const BRIEF_TURN_RAD: f32 = core::f32::consts::FRAC_PI_2;
/// Stillness that forgets all partial matches, µs (unrelated gestures are not joined).
pub const LONG_PAUSE_US: u64 = 2_500_000;

/// A possible action segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Candidate {
    /// Action index in the library.
    pub action: u8,
    /// First run (absolute history index).
    pub start: u32,
    /// Last run (absolute history index).
    pub end: u32,
    /// Weighted edit distance in half-edits ([`crate::alignment`]: a near token costs half an
    /// edit). What candidates are ranked by and held to their bound with.
    pub cost: u8,
    /// Non-STILL tokens covered.
    pub len: u16,
    /// Shortest match of the action's pattern (its specificity), tokens.
    pub min_len: u8,
    /// Positions of the action's pattern: fewer accept fewer strings (a tighter pattern).
    pub positions: u8,
    /// The pattern can repeat as a whole (a cyclic action: walk, wave …).
    pub cyclic: bool,
    /// How far the matched motion's shape is from its action's ([`shape_cost`](crate::shape::shape_cost)), quarter
    /// tokens, taken off its merit.
    pub shape: i16,
}

impl Candidate {
    /// Edit distance in whole edits, rounded up: what an event reports.
    pub fn distance(&self) -> u8 {
        self.cost.div_ceil(FULL)
    }

    /// Ranking score, in quarter tokens: longer is better, each edit costs 1.5 tokens
    /// (a rotation-only disagreement half of that), a shape unlike the action's up to one
    /// token per [`SHAPE_TOKENS`](crate::shape::SHAPE_TOKENS).
    pub fn merit(&self) -> i32 {
        Self::merit_of(usize::from(self.len), self.cost) - i32::from(self.shape)
    }

    /// [`Candidate::merit`] of a match over `len` tokens at `cost` half-edits.
    pub fn merit_of(len: usize, cost: u8) -> i32 {
        4 * (len.min(u16::MAX as usize) as i32) - 3 * i32::from(cost)
    }

    /// The highest cost at which a match of at most `max_len` tokens can still have a merit
    /// above `merit` (0 when none can).
    pub fn max_cost_beating(merit: i32, max_len: usize) -> u8 {
        let top = Self::merit_of(max_len, 0)
            .saturating_sub(merit)
            .saturating_sub(1);
        (top.max(0) / 3).min(255) as u8
    }

    /// True when `self` should replace `other`: higher merit (without the shape costs when
    /// both are readings of one action from the same run); at equal merit the more
    /// specific pattern (longer shortest match, then fewer positions: a pattern that accepts
    /// fewer strings explains the match better than one that merely allows it), then fewer
    /// edits, then the lower index.
    pub fn beats(&self, other: &Candidate) -> bool {
        // Two readings of one action from the same run are one performance read to two
        // ends: their shapes differ only by what the longer one read on through, so the
        // tokens decide (a jump read on through its landing, not cut into a jump and a crouch).
        let same = self.action == other.action && self.start == other.start;
        let merit = |c: &Candidate| {
            if same {
                Self::merit_of(usize::from(c.len), c.cost)
            } else {
                c.merit()
            }
        };
        (
            merit(self),
            self.min_len,
            other.positions,
            other.cost,
            other.action,
        ) > (
            merit(other),
            other.min_len,
            self.positions,
            self.cost,
            self.action,
        )
    }
}

/// What the decider wants done after an offer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decision {
    /// Nothing to commit yet.
    Wait,
    /// Commit this candidate and restart matching after its end.
    Commit(Candidate),
}

/// The pending-candidate state machine.
#[derive(Debug, Clone, Default)]
pub struct Decider {
    pending: Option<Candidate>,
    since_end: u8,
}

impl Decider {
    /// No pending candidate.
    pub const fn new() -> Self {
        Decider {
            pending: None,
            since_end: 0,
        }
    }

    /// The pending candidate.
    pub fn pending(&self) -> Option<Candidate> {
        self.pending
    }

    /// Drops the pending candidate (after a commit or a restart).
    pub fn clear(&mut self) {
        self.pending = None;
        self.since_end = 0;
    }

    /// A non-STILL token was fed; `best` is the best candidate ending at it, if any.
    /// Run indices are compared relative to `floor` (the first run matching may use).
    pub fn offer(&mut self, best: Option<Candidate>, floor: u32) -> Decision {
        let rel = |i: u32| i.wrapping_sub(floor);
        match (self.pending, best) {
            (None, Some(c)) => {
                self.pending = Some(c);
                self.since_end = 0;
                Decision::Wait
            }
            (None, None) => Decision::Wait,
            (Some(p), Some(c)) if rel(c.start) > rel(p.end) => Decision::Commit(p),
            (Some(p), Some(c)) if c.beats(&p) => {
                self.pending = Some(c);
                self.since_end = 0;
                Decision::Wait
            }
            (Some(p), _) => {
                self.since_end = self.since_end.saturating_add(1);
                if self.since_end >= LOOKAHEAD_TOKENS {
                    Decision::Commit(p)
                } else {
                    Decision::Wait
                }
            }
        }
    }

    /// The current run is STILL and has lasted `still_us`: commits after [`PAUSE_US`] —
    /// or after [`HOLD_US`] ([`INEXACT_HOLD_US`] if the pending candidate needed a near
    /// substitution, [`GAPPED_HOLD_US`] if it needed a whole edit) while
    /// `longer_in_progress` is `Some` (a longer action has matched further than the pending one
    /// and may go on after the hold), and for as long as the hold it carries (µs: how long the
    /// examples of the action it is a piece of held still inside) if that is longer.
    pub fn stillness(&mut self, still_us: u64, longer_in_progress: Option<u64>) -> Decision {
        let Some(p) = self.pending else {
            return Decision::Wait;
        };
        let pause = if p.cyclic { CYCLIC_PAUSE_US } else { PAUSE_US };
        let hold = if p.cost >= FULL {
            GAPPED_HOLD_US
        } else if p.cost > 0 {
            INEXACT_HOLD_US
        } else {
            HOLD_US
        };
        let hold = longer_in_progress.map_or(hold, |learnt| hold.max(learnt));
        if still_us >= pause && (still_us >= hold || longer_in_progress.is_none()) {
            Decision::Commit(p)
        } else {
            Decision::Wait
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::{shape_cost, SHAPE_CAP};

    fn c(action: u8, start: u32, end: u32, distance: u8) -> Candidate {
        Candidate {
            action,
            start,
            end,
            cost: 2 * distance,
            len: (end - start + 1) as u16,
            min_len: 1,
            positions: 1,
            cyclic: false,
            shape: 0,
        }
    }

    #[test]
    fn a_shape_unlike_the_actions_is_taken_off_the_merit() {
        // Taken off the merit: an exact tie goes to the matching shape.
        let a = Candidate {
            shape: 0,
            ..c(0, 1, 3, 0)
        };
        let b = Candidate {
            shape: 2,
            ..c(1, 1, 3, 0)
        };
        assert!(a.beats(&b) && !b.beats(&a));
        assert_eq!(b.merit(), a.merit() - 2);
    }

    #[test]
    fn longest_wins_near_ties_and_lookahead_commits() {
        let mut d = Decider::new();
        assert_eq!(d.offer(Some(c(0, 2, 3, 0)), 0), Decision::Wait);
        // A longer overlapping match with one edit still wins (merit 9 vs 4).
        assert_eq!(d.offer(Some(c(1, 1, 5, 1)), 0), Decision::Wait);
        assert_eq!(d.pending().unwrap().action, 1);
        // A shorter overlapping exact match does not.
        assert_eq!(d.offer(Some(c(2, 4, 5, 0)), 0), Decision::Wait);
        for _ in 2..LOOKAHEAD_TOKENS {
            assert_eq!(d.offer(None, 0), Decision::Wait);
        }
        assert_eq!(d.offer(None, 0), Decision::Commit(c(1, 1, 5, 1)));
    }

    #[test]
    fn at_equal_merit_the_tighter_pattern_wins() {
        // `d u` matched exactly by a crouch (`d+ u+`, 2 positions) and by a jump whose landing
        // is optional (`d+ u+ (f|df|d)*`, 5 positions): the crouch explains it better.
        let crouch = Candidate {
            min_len: 2,
            positions: 2,
            ..c(8, 1, 2, 0)
        };
        let jump = Candidate {
            min_len: 2,
            positions: 5,
            ..c(2, 1, 2, 0)
        };
        assert!(crouch.beats(&jump));
        assert!(!jump.beats(&crouch));
        // A longer shortest match still comes first: it is the more specific gesture.
        let jump = Candidate { min_len: 3, ..jump };
        assert!(jump.beats(&crouch));
    }

    #[test]
    fn two_readings_of_one_action_from_one_run_are_weighed_without_shapes() {
        // A jump read to its take-off (4 tokens, shape as its examples) and read on through
        // its landing (6 tokens, whose dip the examples lacked: 2 quarter tokens per 2 tokens).
        let short = c(2, 1, 4, 0);
        let long = Candidate {
            shape: shape_cost(SHAPE_CAP, 6),
            ..c(2, 1, 6, 0)
        };
        assert!(long.merit() < short.merit());
        // Of one action from the same run, the tokens decide: the whole jump.
        assert!(long.beats(&short) && !short.beats(&long));
        // Another action, or the same action from another run, is weighed with its shape.
        let crouch = Candidate { action: 8, ..short };
        assert!(crouch.beats(&long) && !long.beats(&crouch));
        let later = Candidate { start: 2, ..short };
        assert!(later.beats(&long));
    }

    #[test]
    fn edits_are_bounded_by_the_share_of_the_match() {
        // In half-edits: one whole edit needs 3 tokens, half of one 2.
        assert!(edits_fit(0, 1));
        assert!(!edits_fit(2, 2));
        assert!(edits_fit(1, 2));
        assert!(edits_fit(2, 3));
        assert!(!edits_fit(4, 4));
        assert!(edits_fit(4, 5));
        assert!(edits_fit(6, 8));
    }

    #[test]
    fn a_later_candidate_or_a_pause_commits() {
        let mut d = Decider::new();
        d.offer(Some(c(0, 2, 3, 0)), 0);
        assert_eq!(
            d.offer(Some(c(1, 4, 6, 0)), 0),
            Decision::Commit(c(0, 2, 3, 0))
        );
        let mut d = Decider::new();
        d.offer(Some(c(0, 2, 3, 0)), 0);
        assert_eq!(d.stillness(PAUSE_US - 1, None), Decision::Wait);
        assert_eq!(d.stillness(PAUSE_US, None), Decision::Commit(c(0, 2, 3, 0)));
        assert_eq!(
            Decider::new().stillness(10 * PAUSE_US, None),
            Decision::Wait
        );
        // A longer action in progress: the pause is a hold inside it.
        let mut d = Decider::new();
        d.offer(Some(c(0, 2, 3, 0)), 0);
        assert_eq!(d.stillness(PAUSE_US, Some(0)), Decision::Wait);
        assert_eq!(
            d.stillness(HOLD_US, Some(0)),
            Decision::Commit(c(0, 2, 3, 0))
        );
        // An inexact pending candidate is the weaker reading of a long hold: it waits longer,
        // the longer the more it needed.
        let mut d = Decider::new();
        d.offer(Some(c(0, 1, 3, 1)), 0);
        assert_eq!(d.stillness(HOLD_US, Some(0)), Decision::Wait);
        assert_eq!(d.stillness(GAPPED_HOLD_US - 1, Some(0)), Decision::Wait);
        assert_eq!(
            d.stillness(GAPPED_HOLD_US, Some(0)),
            Decision::Commit(c(0, 1, 3, 1))
        );
        assert_eq!(d.stillness(PAUSE_US, None), Decision::Commit(c(0, 1, 3, 1)));
        let mut near = c(0, 1, 3, 0);
        near.cost = 1;
        let mut d = Decider::new();
        d.offer(Some(near), 0);
        assert_eq!(d.stillness(INEXACT_HOLD_US - 1, Some(0)), Decision::Wait);
        assert_eq!(
            d.stillness(INEXACT_HOLD_US, Some(0)),
            Decision::Commit(near)
        );
        // A piece of an action whose examples held still 1.4 s inside waits that long; a hold
        // learnt shorter than the fixed one does not shorten it.
        let mut d = Decider::new();
        d.offer(Some(c(0, 2, 3, 0)), 0);
        assert_eq!(d.stillness(HOLD_US, Some(1_400_000)), Decision::Wait);
        assert_eq!(d.stillness(1_399_999, Some(1_400_000)), Decision::Wait);
        assert_eq!(
            d.stillness(1_400_000, Some(1_400_000)),
            Decision::Commit(c(0, 2, 3, 0))
        );
        let mut d = Decider::new();
        d.offer(Some(c(0, 2, 3, 0)), 0);
        assert_eq!(d.stillness(HOLD_US - 1, Some(100_000)), Decision::Wait);
    }

    #[test]
    fn a_rotation_only_disagreement_ranks_above_a_missing_stroke() {
        // The same three tokens, one edit each: a crouch reading `u.Xn` as its `u` (half an
        // edit) beats a jump that leaves out its landing (a whole one).
        let crouch = Candidate {
            cost: 1,
            min_len: 2,
            ..c(8, 1, 3, 1)
        };
        let jump = Candidate {
            min_len: 3,
            ..c(2, 1, 3, 1)
        };
        assert!(crouch.merit() > jump.merit());
        assert!(crouch.beats(&jump) && !jump.beats(&crouch));
    }

    #[test]
    fn the_cost_that_can_still_beat_a_merit() {
        // 5 tokens (merit 20 when exact) beat merit 14 up to cost 1 (20 − 3 = 17 > 14) and
        // 2 (14 is not above 14): 1.
        assert_eq!(Candidate::max_cost_beating(14, 5), 1);
        assert_eq!(Candidate::max_cost_beating(20, 5), 0);
        // Any merit at all: capped, no overflow.
        assert_eq!(Candidate::max_cost_beating(i32::MIN, 5), 255);
        assert_eq!(Candidate::max_cost_beating(i32::MAX, 5), 0);
    }
}
