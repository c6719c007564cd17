//! Stage 5 — fixed-size weighted Levenshtein automata: every action matched in parallel.
//!
//! Edits are counted in half-edits ([`crate::alignment`]): an insertion, a deletion or a
//! substitution costs [`FULL`] = 2; a substitution between near tokens (the same stroke with
//! another rotation, or a stroke 45° off at the same rotation) costs [`HALF`](crate::alignment::HALF) = 1. For each
//! action, `2·max_edits + 1` state masks (one `u64` per cost level, bit-parallel over the
//! Glushkov positions of [`crate::pattern`]) track every way the recent token stream can end
//! inside the pattern at cost ≤ v. The initial state is always active, so a match may start
//! anywhere; the cost per token is a handful of word operations per level, independent of how
//! long the figurine has been played with. With `T` the forward transition, `B`/`H` the
//! positions that read token `c` exactly / at half cost, and `Iᵥ` the start and the positions
//! leading deletions of cost ≤ v reach, level v is updated as
//! ```text
//! D'[v] = T(D[v] ∪ Iᵥ) ∩ B  ∪  T(D[v−1] ∪ Iᵥ₋₁) ∩ H  ∪  T(D[v−2] ∪ Iᵥ₋₂)   match, near, other
//!       ∪ D[v−2]                                                          insertion
//!       ∪ T(D'[v−2])  ∪  D'[v−1]                                          deletion, monotone
//! ```
//! A match of cost v ends at this token when `D'[v]` meets the accepting set. Since match
//! starts are not tracked in the masks (that would cost 32× the RAM), the start of a match is
//! found when needed by running the reversed automaton backwards over the token history:
//! [`earliest_start`] picks the longest match at the lowest cost, [`best_start`] the match a
//! score prefers over all costs within the bound (the recognizer's merit: a longer match with
//! a near substitution in it can outrank a short exact one).
//! RAM: `MAX_ACTIONS × (2·MAX_EDITS + 1) × 8` = 1.75 KiB.

use crate::alignment::{advance, masks, FULL};
use crate::pattern::{Library, Pattern, MAX_ACTIONS, MAX_EDITS};
use crate::token::Token;

/// Cost levels per action: 0 ..= 2·[`MAX_EDITS`] half-edits.
pub const LEVELS: usize = 2 * MAX_EDITS + 1;

/// Highest cost level of pattern `p`, half-edits: its edit bound in whole edits.
pub fn top_level(p: &Pattern<'_>) -> usize {
    (usize::from(FULL) * p.max_edits()).min(LEVELS - 1)
}

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

/// Matches ending at the latest token: lowest cost per action, half-edits (`u8::MAX` =
/// none).
pub type Matches = [u8; MAX_ACTIONS];

/// One automaton step of pattern `p` over `d` (only `0..=top_level(p)` are used). Returns
/// the lowest cost level that accepts, if any.
fn step_pattern(p: &Pattern<'_>, d: &mut [u64; LEVELS], c: Token) -> Option<u8> {
    let levels = d.get_mut(..=top_level(p)).unwrap_or(&mut []);
    advance(p, levels, c, true)
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
/// history). Returns `(j, v)`: the largest `j` such that tokens `j..=0` match `p` at the
/// lowest cost `v ≤ max_cost` half-edits (the longest match at the best cost), or `None`.
/// The mirror of the forward automaton, levels and costs alike.
pub fn earliest_start(
    p: &Pattern<'_>,
    max_cost: u8,
    token_back: impl FnMut(usize) -> Option<Token>,
) -> Option<(usize, u8)> {
    let mut found: Option<(usize, u8)> = None;
    reverse_search(p, max_cost, token_back, |j, v| {
        // The lowest cost wins; at equal cost the longest (latest j).
        if found.is_none_or(|(_, fv)| v <= fv) {
            found = Some((j, v));
        }
        // Higher levels can only find costlier starts.
        v
    });
    found
}

/// Like [`earliest_start`], but of all the starts at costs `v ≤ max_cost` — for each cost the
/// longest match — returns the one `score(j, v)` rates highest (`None` = not acceptable), and
/// its score; on equal scores the cheaper. `bound(best)` is the highest cost that could still
/// beat score `best` with any match the history allows (`j` grows by one per token read), so
/// the search stops early.
pub fn best_start(
    p: &Pattern<'_>,
    max_cost: u8,
    token_back: impl FnMut(usize) -> Option<Token>,
    mut score: impl FnMut(usize, u8) -> Option<i32>,
    mut bound: impl FnMut(i32) -> u8,
) -> Option<(usize, u8, i32)> {
    let mut found: Option<(usize, u8, i32)> = None;
    reverse_search(p, max_cost, token_back, |j, v| {
        if let Some(s) = score(j, v) {
            if found.is_none_or(|(_, fv, fs)| s > fs || (s == fs && v < fv)) {
                found = Some((j, v, s));
            }
        }
        found.map_or(max_cost, |(_, _, s)| bound(s))
    });
    found
}

/// The reversed automaton of `p` up to `max_cost` (and the pattern's own bound): for each `j`
/// (growing) at which tokens `j..=0` match, calls `on_start(j, v)` with the lowest cost `v`
/// of that match; it returns the highest level still worth searching.
fn reverse_search(
    p: &Pattern<'_>,
    max_cost: u8,
    mut token_back: impl FnMut(usize) -> Option<Token>,
    mut on_start: impl FnMut(usize, u8) -> u8,
) {
    // A virtual state after the accepting ones.
    const END: u64 = 1 << 63;
    let mut top = usize::from(max_cost).min(top_level(p));
    let first = p.first();
    let rev = |d: u64| -> u64 {
        let mut r = p.backward(d & !END);
        if d & END != 0 {
            r |= p.last();
        }
        r & !1
    };
    // Before reading: the end, and the positions trailing deletions (each FULL) reach.
    // Each level's states, and what they reach one step back (`rev` of them): a level's step
    // back after one token is its step back before the next, so each is computed once.
    let mut d = [0u64; LEVELS];
    let mut back = [0u64; LEVELS];
    let (mut n1, mut g1, mut g2) = (0u64, 0u64, 0u64);
    for (v, (slot, b)) in d.iter_mut().zip(back.iter_mut()).enumerate().take(top + 1) {
        let n = if v == 0 { END } else { n1 } | g2;
        *slot = n;
        let g = rev(n);
        *b = g;
        (n1, g2, g1) = (n, g1, g);
    }
    let mut j = 0;
    while let Some(c) = token_back(j) {
        let (exact, near) = masks(p, c);
        let (mut o1, mut o2, mut f1, mut f2) = (0u64, 0u64, 0u64, 0u64);
        let (mut n1, mut g1, mut g2) = (0u64, 0u64, 0u64);
        let mut live = false;
        let mut started = false;
        let mut v = 0;
        while v <= top {
            let (Some(slot), Some(b)) = (d.get_mut(v), back.get_mut(v)) else {
                break;
            };
            let old = *slot;
            let f0 = *b;
            // One stroke for two positions, mirrored: the later one read near, the one
            // before it exactly (only a token's few exact positions are looked up).
            let merge = p.backward_among(f1 & near, exact);
            let new = (f0 & exact) | (f1 & near) | merge | f2 | o2 | n1 | g2;
            *slot = new;
            live |= new != 0;
            // A match may start here, at a first position of the pattern (leading deletions
            // are in `new` already: the backward deletion term). Each level reports its
            // longest start (a lower level's is reported first and stands at equal cost). The
            // levels are monotone: a start here is one at every higher level too, dominated.
            if !started && new & first != 0 {
                started = true;
                top = top.min(usize::from(on_start(j, v as u8)));
            }
            let g0 = rev(new);
            *b = g0;
            (o2, o1, f2, f1) = (o1, old, f1, f0);
            (n1, g2, g1) = (new, g1, g0);
            v += 1;
        }
        if !live {
            break;
        }
        j += 1;
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::pattern::tests::{seq_library, toks};
    use crate::token::parse_token;
    use std::vec::Vec;

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

    /// Token `j` back from the end of `stream` (what the reverse searches read).
    fn backwards(stream: &[Token]) -> impl Fn(usize) -> Option<Token> + Copy + '_ {
        move |j| stream.len().checked_sub(j + 1).map(|i| stream[i])
    }

    #[test]
    fn exact_match_anywhere_in_the_stream() {
        let blob = seq_library(&[(&["u", "f", "d"], 0)]);
        let m = run(&blob, "l r u f d b");
        let d: Vec<u8> = m.iter().map(|m| m[0]).collect();
        assert_eq!(d, [255, 255, 255, 255, 0, 255]);
    }

    #[test]
    fn edits_are_counted_in_half_edits_and_bounded() {
        let blob = seq_library(&[(&["u", "f", "d", "b"], 1)]);
        // One substitution (r for d): a whole edit.
        assert_eq!(run(&blob, "u f r b")[3][0], 2);
        // One near substitution (`df`, 45° from `d`; `d.Xp`, another rotation): half of one.
        assert_eq!(run(&blob, "u f df b")[3][0], 1);
        assert_eq!(run(&blob, "u f d.Xp b")[3][0], 1);
        // One insertion (l).
        assert_eq!(run(&blob, "u f l d b")[4][0], 2);
        // One deletion (f missing).
        assert_eq!(run(&blob, "u d b")[2][0], 2);
        // The bound (one edit) admits two near substitutions, not two whole edits.
        assert_eq!(
            top_level(&Library::from_bytes(&blob).unwrap().pattern(0).unwrap()),
            2
        );
        assert_eq!(run(&blob, "uf f df b")[3][0], 2);
        assert_eq!(run(&blob, "u r r b")[3][0], 255);
    }

    #[test]
    fn the_first_parts_of_a_pattern_may_be_missing() {
        // A punch without its wind-up: `f b` is `b f b` with the leading `b` deleted.
        let blob = seq_library(&[(&["b", "f", "b"], 1), (&["u", "f", "d", "b"], 2)]);
        assert_eq!(run(&blob, "f b")[1][0], 2);
        // Two leading parts missing: two edits, the bound of the second pattern.
        assert_eq!(run(&blob, "d b")[1][1], 4);
        assert_eq!(run(&blob, "b")[0][1], 255);
        // The reverse search agrees on where such a match starts and what it costs.
        let lib = Library::from_bytes(&blob).unwrap();
        let p = lib.pattern(0).unwrap();
        let stream = toks("f b");
        assert_eq!(earliest_start(&p, 2, backwards(&stream)), Some((1, 2)));
        assert_eq!(earliest_start(&p, 1, backwards(&stream)), None);
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
        assert_eq!(earliest_start(&p, 0, backwards(&stream)), Some((2, 0)));
        // With one edit allowed, the extra leading `b` is not taken when it costs more.
        assert_eq!(earliest_start(&p, 2, backwards(&stream)), Some((2, 0)));
        let stream = toks("u f l d");
        assert_eq!(earliest_start(&p, 2, backwards(&stream)), Some((3, 2)));
        // A near token costs half an edit at the start too.
        let stream = toks("uf f d");
        assert_eq!(earliest_start(&p, 2, backwards(&stream)), Some((2, 1)));
    }

    #[test]
    fn the_best_start_is_the_one_the_score_prefers() {
        let blob = seq_library(&[(&["u", "f", "d"], 1)]);
        let lib = Library::from_bytes(&blob).unwrap();
        let p = lib.pattern(0).unwrap();
        // `u f d` exactly, or `l u f d` with one insertion.
        let stream = toks("l u f d");
        let back = backwards(&stream);
        let merit = |j: usize, v: u8| Some(4 * (j as i32 + 1) - 3 * i32::from(v));
        assert_eq!(best_start(&p, 2, back, merit, |_| 2), Some((2, 0, 12)));
        let longest = |j: usize, _: u8| Some(j as i32);
        assert_eq!(best_start(&p, 2, back, longest, |_| 2), Some((3, 2, 3)));
        // Refused starts are not taken (`u f d` here); once one is found, the bound on what
        // could beat it ends the search (only `f d`, a deletion, is then seen).
        let costly = |j: usize, v: u8| (v > 0).then_some(j as i32);
        assert_eq!(best_start(&p, 2, back, costly, |_| 2), Some((3, 2, 3)));
        assert_eq!(best_start(&p, 2, back, costly, |_| 0), Some((1, 2, 1)));
    }

    use proptest::prelude::*;

    proptest! {
        #[test]
        fn automaton_and_reverse_search_agree_with_the_alignment_cost(
            pat in proptest::collection::vec(0usize..8, 2..6),
            bound in 0u8..3,
            text in proptest::collection::vec(0usize..8, 1..10),
        ) {
            use crate::alignment::weighted_cost;
            const NAMES: [&str; 8] = ["u", "uf", "f", "d", "d.Xp", "f.Xn", ".Xp", "lu"];
            let names: Vec<&str> = pat.iter().map(|&i| NAMES[i]).collect();
            let bound = bound.min(names.len() as u8 - 1);
            let blob = seq_library(&[(&names, bound)]);
            let lib = Library::from_bytes(&blob).unwrap();
            let p = lib.pattern(0).unwrap();
            let t: Vec<Token> = text.iter().map(|&i| parse_token(NAMES[i]).unwrap()).collect();
            let top = FULL * bound;
            let mut bank = MatcherBank::new();
            for end in 0..t.len() {
                let mut m = [0u8; MAX_ACTIONS];
                bank.step(&lib, t[end], &mut m);
                // The cheapest match ending here, over every start, within the bound.
                let costs: Vec<Option<u8>> = (0..=end)
                    .map(|s| weighted_cost(&p, &t[s..=end], top))
                    .collect();
                let best = costs.iter().flatten().min().copied();
                prop_assert_eq!(m[0], best.unwrap_or(u8::MAX), "end {}", end);
                let back = |j: usize| end.checked_sub(j).map(|i| t[i]);
                let found = earliest_start(&p, m[0].min(top), back);
                let longest = best.and_then(|b| {
                    (0..=end).find(|&s| costs[s] == Some(b)).map(|s| (end - s, b))
                });
                prop_assert_eq!(found, longest, "end {}", end);
                // The best-scoring start: the brute force over every start and its cost.
                let score = |j: usize, v: u8| Some(4 * (j as i32 + 1) - 3 * i32::from(v));
                let brute = costs
                    .iter()
                    .enumerate()
                    .filter_map(|(s, c)| c.and_then(|c| Some((end - s, c, score(end - s, c)?))))
                    .max_by_key(|&(_, c, sc)| (sc, core::cmp::Reverse(c)));
                let bound = |best: i32| ((4 * (end as i32 + 1) - best - 1).max(0) / 3) as u8;
                let found = best_start(&p, top, back, score, bound);
                prop_assert_eq!(found.map(|f| (f.1, f.2)), brute.map(|b| (b.1, b.2)), "end {}", end);
            }
        }
    }
}
