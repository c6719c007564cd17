//! Stage 5a — weighted edit costs: how far a token is from what a pattern position expects.
//!
//! A token that disagrees with the pattern only about its rotation (`u.Xn` where the examples
//! showed `u` — the toy wobbled while it rose), or whose stroke is 45° off, is a far smaller
//! departure than a stroke that is missing or extra: rotation modifiers come and go with how
//! the toy is held, while strokes are the gesture. So such near substitutions cost half an
//! edit, in the automata ([`crate::automaton`]) and in whole-phrase comparisons
//! ([`crate::nearest`]) alike; a crouch `d.Xp u.Xn u` (one rotation disagreement) then ranks
//! above a jump that explains the same tokens by leaving out its landing.
//!
//! [`weighted_cost`] is the edit distance between a token string and a whole pattern
//! with these costs, in half-edits: insertion, deletion and substitution [`FULL`]; a
//! substitution [`HALF`] between two moving tokens that differ only in their rotation half, or
//! only in one component of their translation direction at the same rotation (`uf` for `f`:
//! 45° apart). And one token may stand for a position it matches exactly and the next one,
//! which it is near, at [`HALF`]: a stroke that did not drift across a bin border, where the
//! examples' did (`b.Xp` for a kick's return `b.Xp+ db.Xp+`, which curved down in every
//! example) — not a missing stroke, which costs [`FULL`]. Like the automata it is
//! bit-parallel over the pattern's Glushkov states: one `u64` set per cost level, `D[v]` =
//! the states some alignment of the tokens read so far reaches at cost ≤ v. With `B`/`H` the
//! positions a token matches exactly / at half cost:
//! ```text
//! D'[v] = T(D[v]) ∩ B  ∪  T(D[v−1]) ∩ H  ∪  T(D[v−2])   match, half and full substitution
//!       ∪ T(T(D[v−1]) ∩ B) ∩ H                            one stroke for two positions
//!       ∪ D[v−2]  ∪  D'[v−1]  ∪  T(D'[v−2])               insertion, monotone, deletion
//! ```
//! The automata read each token with the same update (`advance`), adding at every token the
//! start a match may take there. [`weighted_cost`] is for whole phrases
//! ([`crate::nearest`]): its levels go up to the bound the caller asks for (at most
//! [`MAX_COST`]), so it costs `tokens × levels` forward steps, once per pause.

use crate::pattern::{Pattern, MAX_POSITIONS};
use crate::token::{symbol_matches, Token, ANY_LIN, ANY_ROT, NONE_BIN, STILL};

/// Cost of an insertion, a deletion or a substitution, in half-edits.
pub const FULL: u8 = 2;
/// Cost of a substitution between near tokens (see the module docs), half-edits.
pub const HALF: u8 = 1;
/// Highest cost [`weighted_cost`] resolves, half-edits (its level sets: 8 bytes each, on the
/// stack).
pub const MAX_COST: u8 = 23;

const LEVELS: usize = MAX_COST as usize + 1;

/// Per translation code (0..27), the codes one component away from it (45° apart; none for
/// the empty translation): `NEIGHBOURS[a] >> b & 1`.
const NEIGHBOURS: [u32; 27] = {
    let mut out = [0u32; 27];
    let mut a = 0;
    while a < 27 {
        let mut b = 0;
        while b < 27 {
            let (mut apart, mut k, mut x, mut y) = (0, 0, a, b);
            while k < 3 {
                let d = (x % 3) as i32 - (y % 3) as i32;
                apart += if d < 0 { -d } else { d };
                x /= 3;
                y /= 3;
                k += 1;
            }
            if apart == 1 && a != NONE_BIN as usize && b != NONE_BIN as usize {
                out[a] |= 1 << b;
            }
            b += 1;
        }
        a += 1;
    }
    out
};

/// The positions of `p` that read token `c` exactly, and those that read it at [`HALF`] cost:
/// for a moving `c`, positions of the same translation (any rotation), and positions one
/// direction component away at the same rotation. Pure rotations have no near tokens: their
/// rotation is the gesture.
pub(crate) fn masks(p: &Pattern<'_>, c: Token) -> (u64, u64) {
    if c >= STILL {
        return (0, 0);
    }
    let (lin_c, rot_c) = (c / 27, c % 27);
    let neighbours = if lin_c == NONE_BIN {
        None
    } else {
        NEIGHBOURS.get(usize::from(lin_c)).copied()
    };
    let (mut exact, mut half) = (0u64, 0u64);
    for (i, s) in p.symbols().enumerate().take(MAX_POSITIONS) {
        let bit = 2u64 << i;
        let code = s & 0x3ff;
        let (lin_s, rot_s) = (code / 27, code % 27);
        if symbol_matches(s, c) {
            exact |= bit;
        } else if let Some(nb) = neighbours.filter(|_| s & ANY_LIN == 0) {
            let same_rotation = s & ANY_ROT != 0 || rot_s == rot_c;
            if lin_s == lin_c || (same_rotation && nb >> lin_s & 1 != 0) {
                half |= bit;
            }
        }
    }
    (exact, half)
}

/// Reads token `c` into the cost levels `d` (level v: the states reached at cost ≤ v
/// half-edits) — the recurrence of the module docs. With `anywhere`, a match may also begin
/// at `c` (the automata of [`crate::automaton`]: matches start anywhere in the stream);
/// without, every alignment began at the first token. Returns the lowest level that accepts.
#[inline]
pub(crate) fn advance(p: &Pattern<'_>, d: &mut [u64], c: Token, anywhere: bool) -> Option<u8> {
    let (exact, near) = masks(p, c);
    let last = p.last();
    let mut best = None;
    // Rolling values of the levels below v: starts I, old levels with their starts and their
    // forward images, new levels and the forward images of new levels.
    let (mut i1, mut i2) = (0u64, 0u64);
    let (mut o1, mut o2, mut f1, mut f2) = (0u64, 0u64, 0u64, 0u64);
    let (mut n1, mut g1, mut g2) = (0u64, 0u64, 0u64);
    for (v, slot) in d.iter_mut().enumerate() {
        // The start, and leading deletions (each FULL).
        let iv = match (anywhere, v) {
            (false, _) => 0,
            (true, 0) => 1,
            (true, _) => i1 | (p.forward_outlined(i2) & !1),
        };
        let old = *slot | iv;
        let f0 = p.forward(old);
        // One stroke for a position read exactly and the next one near (module docs).
        let merge = p.forward(f1 & exact) & near;
        let new = (f0 & exact) | (f1 & near) | merge | f2 | o2 | n1 | g2;
        *slot = new;
        if best.is_none() && new & last != 0 {
            best = Some(v as u8);
        }
        let g0 = p.forward(new);
        (i2, i1) = (i1, iv);
        (o2, o1, f2, f1) = (o1, old, f1, f0);
        (n1, g2, g1) = (new, g1, g0);
    }
    best
}

/// Weighted edit distance (half-edits) between `tokens` (oldest first) and the whole of
/// pattern `p`: the cheapest way to read all the tokens from the initial state to an
/// accepting one. None when it exceeds `bound` (itself capped at [`MAX_COST`]).
pub fn weighted_cost(p: &Pattern<'_>, tokens: &[Token], bound: u8) -> Option<u8> {
    read_from_start(p, tokens, bound, false)
}

/// Lowest cost (half-edits, ≤ `bound`) at which `tokens` (oldest first) are the beginning of
/// a match of `p` that has not ended: some position other than the accepting ones is reached
/// after reading them all (the tolerant counterpart of
/// [`crate::automaton::prefix_alive`]). None when no such alignment is within the bound.
pub fn prefix_cost(p: &Pattern<'_>, tokens: &[Token], bound: u8) -> Option<u8> {
    read_from_start(p, tokens, bound, true)
}

/// Reads `tokens` into levels that began at the pattern's start; returns the lowest level
/// that accepts, or with `unfinished` the lowest that reaches a position other than the
/// initial and the accepting ones.
// Once per stand-alone phrase or pause and action: out of line, one copy of `advance` for
// both uses (flash).
#[inline(never)]
fn read_from_start(p: &Pattern<'_>, tokens: &[Token], bound: u8, unfinished: bool) -> Option<u8> {
    let mut all = [0u64; LEVELS];
    let d = all
        .get_mut(..=usize::from(bound.min(MAX_COST)))
        .unwrap_or(&mut []);
    // Before reading: the initial state, and the positions leading deletions reach.
    let (mut n1, mut g1, mut g2) = (0u64, 0u64, 0u64);
    for (v, slot) in d.iter_mut().enumerate() {
        let n = if v == 0 { 1 } else { n1 } | g2;
        *slot = n;
        let g = p.forward(n);
        (n1, g2, g1) = (n, g1, g);
    }
    let mut best = d.iter().position(|&x| x & p.last() != 0).map(|v| v as u8);
    for &c in tokens {
        best = advance(p, d, c, false);
        if d.last().is_none_or(|&top| top == 0) {
            // Not even the top level reaches anything: over the bound.
            return None;
        }
    }
    if unfinished {
        // Bit 0 is the initial state: every token inserted is no beginning.
        d.iter()
            .position(|&x| x & !1 & !p.last() != 0)
            .map(|v| v as u8)
    } else {
        best
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::pattern::tests::{seq_library, toks};
    use crate::pattern::Library;
    use crate::token::{parse_token, token_signs, Symbol};
    use proptest::prelude::*;
    use std::vec::Vec;

    /// Cost of `tokens` against the pattern `pattern[0]+ pattern[1]+ …`.
    fn cost(pattern: &[&str], tokens: &str) -> Option<u8> {
        let blob = seq_library(&[(pattern, 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let p = lib.pattern(0).unwrap();
        let t = toks(tokens);
        weighted_cost(&p, &t, MAX_COST)
    }

    /// Whether `c` at a position labelled `s` is a near substitution, from the token's sign
    /// triples (independently of the table `masks` uses).
    fn near_ref(s: Symbol, c: Token) -> bool {
        let code = s & 0x3ff;
        let (lin_s, lin_c) = (code / 27, c / 27);
        if c >= STILL || s & ANY_LIN != 0 || lin_c == NONE_BIN || lin_s == NONE_BIN {
            return false;
        }
        let same_rotation = s & ANY_ROT != 0 || code % 27 == c % 27;
        let (a, _) = token_signs(code);
        let (b, _) = token_signs(c);
        let apart: u8 = a.iter().zip(b.iter()).map(|(x, y)| x.abs_diff(*y)).sum();
        lin_s == lin_c || (same_rotation && apart == 1)
    }

    /// The same distance by a plain dynamic programme over the states (one cost per state,
    /// deletions closed by relaxing to a fixpoint), written as plainly as possible.
    #[allow(clippy::needless_range_loop)]
    fn reference(p: &Pattern<'_>, tokens: &[Token]) -> u32 {
        let n = p.positions();
        let inf = u32::MAX / 4;
        let close = |d: &mut Vec<u32>| loop {
            let mut changed = false;
            for from in 0..=n {
                for q in 1..=n {
                    if p.follow(from) & (1 << q) != 0 && d[from] + 2 < d[q] {
                        d[q] = d[from] + 2;
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        };
        let mut d = std::vec![inf; n + 1];
        d[0] = 0;
        close(&mut d);
        for &c in tokens {
            let mut next: Vec<u32> = d.iter().map(|&x| x + 2).collect();
            for from in 0..=n {
                for q in 1..=n {
                    if p.follow(from) & (1 << q) != 0 {
                        let s = p.symbol(q);
                        let sub = if symbol_matches(s, c) {
                            0
                        } else if near_ref(s, c) {
                            1
                        } else {
                            2
                        };
                        next[q] = next[q].min(d[from] + sub);
                        // One stroke read as `q` exactly and as the next position `r` near
                        // (not exactly: `f+ f+` still asks for two strides).
                        if sub == 0 {
                            for r in 1..=n {
                                let rs = p.symbol(r);
                                if p.follow(q) & (1 << r) != 0
                                    && near_ref(rs, c)
                                    && !symbol_matches(rs, c)
                                {
                                    next[r] = next[r].min(d[from] + 1);
                                }
                            }
                        }
                    }
                }
            }
            close(&mut next);
            d = next;
        }
        (1..=n)
            .filter(|&q| p.last() & (1 << q) != 0)
            .map(|q| d[q])
            .min()
            .unwrap_or(inf)
    }

    #[test]
    fn exact_near_and_stroke_edits_cost_0_1_2() {
        assert_eq!(cost(&["d", "u"], "d u"), Some(0));
        assert_eq!(cost(&["d", "u"], "d u.Xn"), Some(HALF));
        // 45° off at the same rotation: half; 90° off: a full substitution.
        assert_eq!(cost(&["d", "uf"], "d f"), Some(HALF));
        assert_eq!(cost(&["d", "u"], "d f"), Some(FULL));
        assert_eq!(cost(&["d", "uf.Xn"], "d f"), Some(FULL));
        // A return that did not curve into the next position's direction: half an edit;
        // but one stride is no two (`f+ f+`), and a stroke near neither position is missing.
        assert_eq!(cost(&["b.Xp", "db.Xp"], "b.Xp"), Some(HALF));
        assert_eq!(cost(&["f", "f"], "f"), Some(FULL));
        assert_eq!(cost(&["b", "u"], "b"), Some(FULL));
        // Missing landing: one deletion; an extra stroke: one insertion.
        assert_eq!(cost(&["d", "u", "d"], "d u"), Some(FULL));
        assert_eq!(cost(&["d", "u"], "d b u"), Some(FULL));
        // A pure rotation's rotation is the gesture: `.Xn` for `.Xp` is a full substitution.
        assert_eq!(cost(&[".Xp", ".Xn"], ".Xp .Xp"), Some(FULL));
    }

    #[test]
    fn the_crouch_with_a_wobble_beats_the_jump_without_its_landing() {
        let crouch = cost(&["d", "u"], "d.Xp u.Xn u").unwrap();
        let jump = cost(&["d", "u", "d"], "d.Xp u.Xn u").unwrap();
        assert!(crouch < jump, "crouch {crouch} jump {jump}");
    }

    #[test]
    fn a_prefix_costs_what_reading_it_into_an_unfinished_match_costs() {
        let blob = seq_library(&[(&["d", "u"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let p = lib.pattern(0).unwrap();
        let pre = |t: &str| prefix_cost(&p, &toks(t), 3 * FULL);
        // A crouch gone down, with a 45° wobble on the way: under way at half an edit.
        assert_eq!(pre("d d"), Some(0));
        assert_eq!(pre("d df d"), Some(HALF));
        // Down and up is a whole crouch: only an extra stroke keeps it unfinished.
        assert_eq!(pre("d u"), Some(FULL));
        // Nothing read is under way only past a stroke left out.
        assert_eq!(pre(""), Some(FULL));
        // Nothing like it within the bound.
        assert_eq!(pre("f f f b"), None);
    }

    #[test]
    fn beyond_the_bound_is_none_and_still_tokens_are_extra() {
        assert_eq!(cost(&["d", "u", "d"], ""), Some(3 * FULL));
        let blob = seq_library(&[(&["d", "u"], 0)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let p = lib.pattern(0).unwrap();
        assert_eq!(weighted_cost(&p, &[STILL, STILL], MAX_COST), Some(2 * FULL));
        let t = toks("f b f b");
        assert_eq!(weighted_cost(&p, &t, 7), None);
        assert_eq!(weighted_cost(&p, &t, 8), Some(8));
    }

    proptest! {
        #[test]
        fn bit_parallel_levels_agree_with_the_plain_programme(
            pat in proptest::collection::vec(0usize..8, 1..6),
            text in proptest::collection::vec(0usize..8, 0..9),
        ) {
            const NAMES: [&str; 8] = ["u", "uf", "f", "d", "d.Xp", "f.Xn", ".Xp", "lu"];
            let names: Vec<&str> = pat.iter().map(|&i| NAMES[i]).collect();
            let blob = seq_library(&[(&names, 0)]);
            let lib = Library::from_bytes(&blob).unwrap();
            let p = lib.pattern(0).unwrap();
            let t: Vec<Token> = text.iter().map(|&i| parse_token(NAMES[i]).unwrap()).collect();
            let want = reference(&p, &t);
            let got = weighted_cost(&p, &t, MAX_COST);
            if want <= u32::from(MAX_COST) {
                prop_assert_eq!(got, Some(want as u8));
            } else {
                prop_assert_eq!(got, None);
            }
        }
    }
}
