//! Stage 5 — fixed-size Levenshtein automata: every action matched in parallel.
//!
//! For each action, `max_edits + 1` state masks (one `u64` per edit level, bit-parallel over
//! the Glushkov positions of [`crate::pattern`]) track every way the recent token stream can
//! end inside the pattern with ≤ k edits. The initial state is always active, so a match may
//! start anywhere; the cost per token is a handful of word operations per level, independent
//! of how long the figurine has been played with. With tokens `c` and `B[c]` the positions
//! labelled `c`, level k is updated as
//! ```text
//! D'[0] = T(D[0] ∪ {0}) ∩ B[c]
//! D'[k] = T(D[k] ∪ Iₖ) ∩ B[c]      match (Iₖ: the start and the positions k deletions from it)
//!       ∪ D[k−1]                    insertion (extra token)
//!       ∪ T(D[k−1] ∪ {0})           substitution
//!       ∪ T(D'[k−1] ∪ {0})          deletion (pattern position skipped)
//! ```
//! A match of distance k ends at this token when `D'[k]` meets the accepting set. Since match
//! starts are not tracked in the masks (that would cost 32× the RAM), the start of a match is
//! found when needed by running the reversed automaton backwards over the token history
//! ([`earliest_start`]), which also picks the longest match at that distance.
//! RAM: `MAX_ACTIONS × (MAX_EDITS + 1) × 8` = 1 KiB.

use crate::pattern::{Library, Pattern, MAX_ACTIONS, MAX_EDITS};
use crate::token::Token;

/// Levels per action.
pub const LEVELS: usize = MAX_EDITS + 1;

/// The automata state of every action.
#[derive(Debug, Clone)]
pub struct MatcherBank {
    d: [[u64; LEVELS]; MAX_ACTIONS],
}

impl Default for MatcherBank {
    fn default() -> Self {
        Self::new()
    }
}

/// Matches ending at the latest token: best distance per action (`u8::MAX` = none).
pub type Matches = [u8; MAX_ACTIONS];

/// One automaton step of pattern `p` over `levels` (only `0..=p.max_edits()` are used).
/// Returns the smallest k whose level accepts, if any.
fn step_pattern(p: &Pattern<'_>, d: &mut [u64; LEVELS], c: Token) -> Option<u8> {
    let b = p.symbol_mask(c);
    let k_max = p.max_edits().min(MAX_EDITS);
    let last = p.last();
    let mut best = None;
    let mut prev_old = 0u64;
    let mut prev_new = 0u64;
    // Where a match may begin at level k: the start, or up to k leading pattern positions
    // skipped (each skip one edit).
    let mut init = 1u64;
    for (k, slot) in d.iter_mut().enumerate().take(k_max + 1) {
        if k > 0 {
            init |= p.forward_outlined(init) & !1;
        }
        let old = *slot;
        let mut new = p.forward(old | init) & b;
        if k > 0 {
            new |= prev_old | p.forward(prev_old | 1) | p.forward(prev_new | 1);
        }
        new &= !1;
        *slot = new;
        if best.is_none() && new & last != 0 {
            best = Some(k as u8);
        }
        prev_old = old;
        prev_new = new;
    }
    best
}

impl MatcherBank {
    /// All automata empty.
    pub const fn new() -> Self {
        MatcherBank {
            d: [[0; LEVELS]; MAX_ACTIONS],
        }
    }

    /// Forgets every partial match (after a commit or a long pause).
    pub fn reset(&mut self) {
        self.d = [[0; LEVELS]; MAX_ACTIONS];
    }

    /// Feeds one (non-STILL) token to every action of `lib`; fills `out` with the distance of
    /// the best match ending here per action (`u8::MAX` when none). Returns whether any matched.
    pub fn step(&mut self, lib: &Library<'_>, c: Token, out: &mut Matches) -> bool {
        let mut any = false;
        for (i, (d, o)) in self.d.iter_mut().zip(out.iter_mut()).enumerate() {
            *o = u8::MAX;
            let Some(p) = lib.pattern(i) else { continue };
            if let Some(k) = step_pattern(&p, d, c) {
                *o = k;
                any = true;
            }
        }
        any
    }
}

/// Whether `tokens`, read from their first, are an exact prefix of a match of `p` — after
/// skipping the pattern's first part when `skip_first` (a punch begun without its wind-up) —
/// that has not ended (some position of the pattern is live and it is not only the accepting
/// one): the gesture of `p` is under way and may go on. One forward step per token.
pub fn prefix_alive(p: &Pattern<'_>, tokens: &[Token], skip_first: bool) -> bool {
    let mut d = if skip_first { 1 | p.first() } else { 1 };
    for &t in tokens {
        d = p.forward_outlined(d) & p.symbol_mask(t) & !1;
        if d == 0 {
            return false;
        }
    }
    d & !p.last() != 0
}

/// Runs pattern `p` backwards over the tokens ending a match: `token_back(0)` is the last
/// token of the match, `token_back(j)` the one `j` tokens earlier (`None` past the available
/// history). Returns `(j, k)`: the largest `j` such that tokens `j..=0` match `p` with
/// `k ≤ max_dist` edits (the longest match at the best distance), or `None`.
pub fn earliest_start(
    p: &Pattern<'_>,
    max_dist: u8,
    mut token_back: impl FnMut(usize) -> Option<Token>,
) -> Option<(usize, u8)> {
    let k_max = usize::from(max_dist).min(p.max_edits()).min(MAX_EDITS);
    const END: u64 = 1 << 63;
    let first = p.first();
    let rev = |d: u64| -> u64 {
        let mut r = p.backward(d & !END);
        if d & END != 0 {
            r |= p.last();
        }
        r
    };
    // Before reading: the virtual end state, closed under trailing deletions.
    let mut d = [0u64; LEVELS];
    d[0] = END;
    for k in 1..=k_max {
        d[k] = d[k - 1] | rev(d[k - 1]);
    }
    let mut found: Option<(usize, u8)> = None;
    let mut j = 0;
    while let Some(c) = token_back(j) {
        let b = p.symbol_mask(c);
        let mut prev_old = 0u64;
        let mut prev_new = 0u64;
        let mut live = false;
        for (k, slot) in d.iter_mut().enumerate().take(k_max + 1) {
            let old = *slot;
            let mut new = rev(old) & b;
            if k > 0 {
                new |= (prev_old & !END) | rev(prev_old) | rev(prev_new);
            }
            new &= !1 & !END;
            *slot = new;
            live |= new != 0;
            // A match may start here, at a first position of the pattern, or after leading
            // positions that were skipped (each skip one more edit, as the forward automaton
            // allows).
            let mut reach = new;
            for kk in k..=k_max {
                if reach & first != 0 {
                    // Keep the lowest distance; among equal distances the longest (latest j).
                    match found {
                        Some((_, fk)) if fk < kk as u8 => {}
                        _ => found = Some((j, kk as u8)),
                    }
                    break;
                }
                reach = rev(reach) & !1 & !END;
                if reach == 0 {
                    break;
                }
            }
            prev_old = old;
            prev_new = new;
        }
        if !live {
            break;
        }
        j += 1;
    }
    found
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::pattern::tests::seq_library;
    use crate::token::parse_token;
    use std::vec::Vec;

    fn toks(s: &str) -> Vec<Token> {
        s.split_whitespace()
            .map(|t| parse_token(t).unwrap())
            .collect()
    }

    fn run(blob: &[u8], stream: &str) -> Vec<Matches> {
        let lib = Library::from_bytes(blob).unwrap();
        let mut bank = MatcherBank::new();
        toks(stream)
            .into_iter()
            .map(|c| {
                let mut m = [0u8; MAX_ACTIONS];
                bank.step(&lib, c, &mut m);
                m
            })
            .collect()
    }

    #[test]
    fn exact_match_anywhere_in_the_stream() {
        let blob = seq_library(&[(&["u", "f", "d"], 0)]);
        let m = run(&blob, "l r u f d b");
        let d: Vec<u8> = m.iter().map(|m| m[0]).collect();
        assert_eq!(d, [255, 255, 255, 255, 0, 255]);
    }

    #[test]
    fn edits_are_counted_and_bounded() {
        let blob = seq_library(&[(&["u", "f", "d", "b"], 1)]);
        // One substitution (r for d).
        assert_eq!(run(&blob, "u f r b")[3][0], 1);
        // One insertion (l).
        assert_eq!(run(&blob, "u f l d b")[4][0], 1);
        // One deletion (f missing).
        assert_eq!(run(&blob, "u d b")[2][0], 1);
        // Two edits exceed the bound.
        assert_eq!(run(&blob, "u r r b")[3][0], 255);
    }

    #[test]
    fn the_first_parts_of_a_pattern_may_be_missing() {
        // A punch without its wind-up: `f b` is `b f b` with the leading `b` deleted.
        let blob = seq_library(&[(&["b", "f", "b"], 1), (&["u", "f", "d", "b"], 2)]);
        assert_eq!(run(&blob, "f b")[1][0], 1);
        // Two leading parts missing: two edits.
        assert_eq!(run(&blob, "d b")[1][1], 2);
        assert_eq!(run(&blob, "b")[0][1], 255);
        // The reverse search agrees on where such a match starts and what it costs.
        let lib = Library::from_bytes(&blob).unwrap();
        let p = lib.pattern(0).unwrap();
        let stream = toks("f b");
        let back = |j: usize| stream.len().checked_sub(j + 1).map(|i| stream[i]);
        assert_eq!(earliest_start(&p, 1, back), Some((1, 1)));
        assert_eq!(earliest_start(&p, 0, back), None);
    }

    #[test]
    fn a_live_prefix_is_a_gesture_under_way() {
        let blob = seq_library(&[(&["b", "f", "b"], 1)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let p = lib.pattern(0).unwrap();
        assert!(prefix_alive(&p, &toks("b f"), false));
        assert!(!prefix_alive(&p, &toks("f b"), false));
        // Begun without its first part.
        assert!(!prefix_alive(&p, &toks("f"), false));
        assert!(prefix_alive(&p, &toks("f"), true));
        // Complete: nothing left to wait for.
        assert!(!prefix_alive(&p, &toks("b f b"), false));
    }

    #[test]
    fn reverse_search_finds_the_longest_start() {
        let blob = seq_library(&[(&["u", "f", "d"], 1)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let p = lib.pattern(0).unwrap();
        let stream = toks("b u f d");
        let back = |j: usize| stream.len().checked_sub(j + 1).map(|i| stream[i]);
        assert_eq!(earliest_start(&p, 0, back), Some((2, 0)));
        // With one edit allowed, the extra leading `b` is not taken when it costs more.
        let back = |j: usize| stream.len().checked_sub(j + 1).map(|i| stream[i]);
        assert_eq!(earliest_start(&p, 1, back), Some((2, 0)));
        let stream = toks("u f l d");
        let stream: Vec<Token> = stream;
        let back = |j: usize| stream.len().checked_sub(j + 1).map(|i| stream[i]);
        assert_eq!(earliest_start(&p, 1, back), Some((3, 1)));
    }
}
