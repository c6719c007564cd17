//! Stage 6a — how a match moved: its motion shape against its action's.
//!
//! Tokens only know which way each stroke went, to 45°; the shape ([`Shape`]: shares of
//! speed along the object's axes, log angle turned, still share, mean height over the path)
//! keeps how much. A match whose motion is unlike its action's examples loses merit
//! ([`crate::segment::Candidate::merit`]) in proportion to how far it lies beyond the
//! examples' own spread, capped so that the tokens decide and the shape only tips near-ties:
//!
//! | step | what |
//! |---|---|
//! | [`observed_shape`] | the shape of a match's runs, holds included |
//! | [`shape_penalty`] | [`SHAPE_WEIGHT`] × Σ (weighted distance beyond the examples' tolerance)², at most [`SHAPE_CAP`] |
//! | [`shape_cost`] | the penalty once per [`SHAPE_TOKENS`] tokens of the match |

use crate::features::{Shape, ShapeSums, SHAPE_DIMS};
use crate::fmath;
use crate::history::{History, HISTORY_RUNS};
use crate::pattern::Library;
use crate::token::STILL;

/// Quarter tokens of merit per squared share of speed by which a match's motion shape
/// differs from its action's ([`shape_penalty`]).
pub const SHAPE_WEIGHT: f32 = 50.0;
/// Most merit a shape unlike the action's costs, quarter tokens (one token): the tokens
/// decide, the shape only tips near-ties.
pub const SHAPE_CAP: i16 = 4;

/// Weight of each [`Shape`] dimension in [`shape_penalty`]: the shares of speed as they are;
/// the log angle turned and the still share scaled so that what tells actions apart in them
/// (a throw turns about twice as far as a kick; a crouch spends half its time held, a jump a
/// fifth) weighs about as much as a walk's bob against a run's skim does in the shares; the
/// height ×3, as one action's performances vary about a third as much in it (±0.04 of the
/// path, against ±0.11 in a share of speed), and a crouch, about −0.3, and a jump, about
/// +0.07, are written alike.
pub const SHAPE_SCALE: Shape = [1.0, 1.0, 1.0, 0.5, 0.5, 3.0];

/// The merit (quarter tokens) a match loses when its motion shape `observed` is unlike its
/// action's `expected` one: [`SHAPE_WEIGHT`] × the sum over the dimensions of the squared
/// weighted difference ([`SHAPE_SCALE`] × |observed − expected|) beyond that dimension's
/// `tolerance` (how far the action's own examples lay from `expected` in it, weighted alike),
/// at most [`SHAPE_CAP`]. A dimension that is NaN on either side (no evidence) counts nothing.
/// Tokens only know which way each stroke went, to 45°; the shape keeps how much: a walk's
/// hops bob, a run's strides skim, though both are written `uf f df`. Where the examples
/// themselves varied (a kick flicked flat or high), so may a performance, at no cost — in that
/// dimension only: a walk whose examples turned more or less does not thereby skim like a run.
pub fn shape_penalty(expected: Shape, tolerance: Shape, observed: Shape) -> i16 {
    let mut d2 = 0.0;
    for k in 0..SHAPE_DIMS {
        let beyond = SHAPE_SCALE[k] * fmath::abs(observed[k] - expected[k]) - tolerance[k];
        // False for NaN too.
        if beyond > 0.0 {
            d2 += beyond * beyond;
        }
    }
    if !fmath::is_finite(d2) {
        return 0;
    }
    fmath::min(SHAPE_WEIGHT * d2, f32::from(SHAPE_CAP)) as i16
}

/// Tokens of a match over which a shape unlike its action's costs up to [`SHAPE_CAP`] once
/// more. The evidence grows with the match: a dozen strides that all skim are no walk, however
/// well their tokens fit one, while the shape of a few tokens only tips a near-tie.
pub const SHAPE_TOKENS: usize = 2;

/// The merit (quarter tokens) a match over `len` tokens loses for a shape `penalty`
/// ([`shape_penalty`]): the penalty once per [`SHAPE_TOKENS`] tokens, at least once.
pub fn shape_cost(penalty: i16, len: usize) -> i16 {
    penalty.saturating_mul((len / SHAPE_TOKENS).clamp(1, 255) as i16)
}

/// The shape penalty of action `a`'s match over runs `start..=end` ([`shape_penalty`]); None
/// when the library has no shape for it.
// Once per candidate, not per sample: one out-of-line copy (flash).
#[inline(never)]
pub fn shape_of(
    library: &Library<'_>,
    a: usize,
    hist: &History,
    start: u32,
    end: u32,
) -> Option<i16> {
    penalty_of(library, a, &observed_shape(hist, start, end))
}

/// The shape penalty of action `a` for motion of shape `observed` ([`shape_penalty`]); None
/// when the library has no shape for it.
// Once per candidate and per action a match is re-read as: one out-of-line copy (flash).
#[inline(never)]
pub fn penalty_of(library: &Library<'_>, a: usize, observed: &Shape) -> Option<i16> {
    let expected = library.shape(a)?;
    Some(shape_penalty(
        expected,
        library.shape_tolerance(a),
        *observed,
    ))
}

/// The motion shape of runs `start..=end` ([`Shape`]), the holds between them included.
pub fn observed_shape(hist: &History, start: u32, end: u32) -> Shape {
    let mut sums = ShapeSums::new();
    let mut i = start;
    for _ in 0..HISTORY_RUNS {
        if let Some(r) = hist.get(i) {
            sums.add(&r.acc, r.token == STILL);
        }
        if i == end {
            break;
        }
        i = i.wrapping_add(1);
    }
    sums.shape()
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXACT: Shape = [0.0; SHAPE_DIMS];

    #[test]
    fn a_shape_unlike_the_actions_costs_up_to_one_token() {
        let walk = [0.1, 0.55, 0.75, 0.3, 0.2, 0.02];
        let like = |l: f32, u: f32, f: f32| [l, u, f, 0.3, 0.2, 0.02];
        assert_eq!(shape_penalty(walk, EXACT, walk), 0);
        // A run's flatter strides: 0.3 less up, 0.1 more front → 50 × 0.1 = 5 → capped at 4.
        assert_eq!(shape_penalty(walk, EXACT, like(0.1, 0.25, 0.85)), SHAPE_CAP);
        // A little off: 50 × 0.04² ≈ 0.08 → nothing.
        assert_eq!(shape_penalty(walk, EXACT, like(0.1, 0.51, 0.75)), 0);
        // 50 × 0.2² = 2 quarter tokens.
        assert_eq!(shape_penalty(walk, EXACT, like(0.1, 0.35, 0.75)), 2);
        assert_eq!(shape_penalty(walk, EXACT, like(f32::NAN, 0.5, 0.7)), 0);
        // The same strokes, turning much further (a throw's swing for a kick's lean): ln-angle
        // 0.8 apart, weighed 0.5 → 50 × 0.4² = 8 → capped; held 0.4 longer (weighed 0.5) →
        // 50 × 0.2² = 2.
        assert_eq!(
            shape_penalty(walk, EXACT, [0.1, 0.55, 0.75, 1.1, 0.2, 0.02]),
            SHAPE_CAP
        );
        assert_eq!(
            shape_penalty(walk, EXACT, [0.1, 0.55, 0.75, 0.3, 0.6, 0.02]),
            2
        );
        // Lower on average by 0.1 of the path (a crouch for a jump), weighed 3 → 50 × 0.3² =
        // 4.5 → capped; by 0.04 → 50 × 0.12² = 0.72 → nothing.
        assert_eq!(
            shape_penalty(walk, EXACT, [0.1, 0.55, 0.75, 0.3, 0.2, -0.08]),
            SHAPE_CAP
        );
        assert_eq!(
            shape_penalty(walk, EXACT, [0.1, 0.55, 0.75, 0.3, 0.2, -0.02]),
            0
        );
        // Where the examples lay up to 0.1 away, only what lies beyond counts: 50 × 0.1² = 0.5
        // → nothing; 50 × 0.2² = 2.
        let tenth = [0.1; SHAPE_DIMS];
        assert_eq!(shape_penalty(walk, tenth, like(0.1, 0.45, 0.75)), 0);
        assert_eq!(shape_penalty(walk, tenth, like(0.1, 0.35, 0.75)), 0);
        assert_eq!(shape_penalty(walk, tenth, like(0.1, 0.25, 0.75)), 2);
        // Per dimension: examples that turned more or less excuse turning, not skimming.
        let turned = [0.0, 0.0, 0.0, 0.5, 0.0, 0.0];
        assert_eq!(
            shape_penalty(walk, turned, [0.1, 0.55, 0.75, 1.1, 0.2, 0.02]),
            0
        );
        assert_eq!(shape_penalty(walk, turned, like(0.1, 0.35, 0.75)), 2);
        // Over a longer match the same unlikeness counts once per two tokens.
        assert_eq!(shape_cost(2, 1), 2);
        assert_eq!(shape_cost(2, 3), 2);
        assert_eq!(shape_cost(2, 4), 4);
        assert_eq!(shape_cost(SHAPE_CAP, 12), 6 * SHAPE_CAP);
        assert_eq!(shape_cost(0, 12), 0);
        assert_eq!(shape_cost(SHAPE_CAP, usize::MAX), 255 * SHAPE_CAP);
    }
}
