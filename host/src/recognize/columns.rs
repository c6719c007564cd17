//! `figurine learn`, step 4: a pattern from the examples' intent strings ([`super::intent`]).
//!
//! | step | what |
//! |---|---|
//! | mandatory runs | in every string, a run is *mandatory* when it lasts at least [`MANDATORY_SHARE`] of that gesture's moving time (a deliberate part of the gesture), otherwise *optional* (a transition or a wobble); the seed's "repeated more than twice" counts samples, durations make the rule independent of the sample rate |
//! | quorum | a variation is kept when [`quorum`] strings show it: any one of three to six examples and their average, a quarter of more (one odd performance among many no longer widens the pattern) |
//! | columns | the mandatory strings are aligned to the reference's (the one with the fewest mandatory runs, the quorum-th fewest) by edit distance; column i becomes `(m_i0\|…\|m_in)+` of the tokens a quorum showed there, or `…*` when most strings lack it or a quorum of performances too short for an edit do; a stroke that turned as it moved is written with its plain stroke too (`db.Xn\|db`, [`with_plain`]: the turn may fall under the token threshold in another performance) |
//! | optional runs | the optional tokens a quorum showed between two columns become `(o_1\|…\|o_k)*` before the later column — or mandatory columns when every example has the same optional sequence there |
//! | repetition | a cyclic action's whole pattern repeats (cyclic: the reference repeats a cycle, or a quorum of performances is closer to it done twice, or repeats one part — all its strokes but a third are the stroke a period later, [`REPEAT_OFF_PER`]); a pattern needs two tokens at least: when its only mandatory column is a part every example performs twice or more (a run's strides), that column is written twice |

use std::collections::{BTreeMap, BTreeSet};

use anyhow::{bail, Result};
use figurine_recognizer::alignment::FULL;
use figurine_recognizer::pattern::MAX_POSITIONS;
use figurine_recognizer::segment::edits_fit;
use figurine_recognizer::token::{Symbol, Token, ANY_LIN, ANY_ROT, NONE_BIN, TURN};

use super::intent::{
    bare, common_symbol, expand_symbol, plain, unsigned, wobble_axes, Tokenized, WOBBLE_AXES,
};
use super::regex::Regex;

/// Share of a gesture's moving time a run needs to be mandatory.
pub const MANDATORY_SHARE: f64 = 0.08;

fn mandatory_flags(t: &Tokenized) -> Vec<bool> {
    let total: f64 = t.iter().map(|x| x.1).sum();
    // The half-turn marker is always deliberate, however short its run.
    t.iter()
        .map(|x| x.0 == TURN || x.1 >= MANDATORY_SHARE * total)
        .collect()
}

/// Whether two symbols move the same way (same translation half, not none): `b` then `b.Xp`
/// is one backward stroke during which a rotation began.
fn same_translation(a: Symbol, b: Symbol) -> bool {
    let lin = |s: Symbol| (s & 0x3ff) / 27;
    lin(a) == lin(b) && lin(a) != NONE_BIN && (a & ANY_LIN) == 0 && (b & ANY_LIN) == 0
}

/// Mandatory runs (token, index in `t`); a repeat of the previous mandatory token separated
/// from it only by optional runs is the same gesture part and is merged, and so is a run
/// right after one with the same translation (the column then accepts both).
pub(super) fn mandatory_runs(t: &Tokenized) -> Vec<(Token, usize)> {
    let flags = mandatory_flags(t);
    let mut mand: Vec<(Token, usize)> = Vec::new();
    for (i, (x, f)) in t.iter().zip(&flags).enumerate() {
        if !*f {
            continue;
        }
        match mand.last() {
            Some(&(prev, at)) if prev == x.0 && at + 1 < i => {}
            Some(&(prev, at)) if at + 1 == i && same_translation(prev, x.0) => {}
            _ => mand.push((x.0, i)),
        }
    }
    mand
}

/// How many of the strings a pattern is learnt from (the examples and their average) must show
/// a variation for the pattern to keep it — a token in a column or between columns, a column
/// an example too short for an edit lacked, a repetition that makes the action cyclic: of m
/// strings k = m / 4 rounded down, at least one — the most whose share, k / m, is at most
/// the quarter that one of three examples and their average is. Three to six examples give
/// one: every variation any of them showed; seven to ten give two; eleven to fourteen three.
/// So one odd performance among many no longer widens the pattern for all of them: a union
/// of every variation seen grows with each example, and read carried toys as actions. (The
/// learnt bounds take the examples' lower quartile likewise: `learn::lower_quartile`.)
pub fn quorum(strings: usize) -> usize {
    (strings / 4).max(1)
}

/// Mandatory columns a learnt pattern keeps at least (when its reference has that many).
pub const MIN_MANDATORY: usize = 1;

/// A performance repeats one part (the action is cyclic) when all its strokes but one in this
/// many are the stroke one period later: a walk's strides, each a little different, repeat;
/// a kick's thrust and return (`b f b db`: half its strokes differ a period on) do not.
pub const REPEAT_OFF_PER: usize = 3;

/// Mandatory strokes a performance needs for that test: three, so that a stroke and its
/// return are no cycle.
pub const REPEAT_MANDATORY: usize = 3;

/// Strokes of all kinds (consecutive ones alike by translation counted once) a performance
/// needs for that test on all its strokes: two periods of three.
pub const REPEAT_STROKES: usize = 6;

/// Distinct tokens sharing one half that make the other half a wildcard.
pub const WILDCARD_VARIANTS: usize = 3;

/// Replaces tokens that differ only in one half by a wildcard symbol (`uf~`, `~.Yp`) when at
/// least two of them share the other half: the examples disagree there, so it is not part of
/// the gesture.
pub fn generalise(set: &BTreeSet<Token>) -> Vec<Symbol> {
    let mut out = BTreeSet::new();
    let mut covered = BTreeSet::new();
    for &t in set {
        if t & (ANY_LIN | ANY_ROT) != 0 {
            out.insert(t);
            covered.insert(t);
            continue;
        }
        let (lin, ang) = (t / 27, t % 27);
        let plain = |u: &&Token| **u & (ANY_LIN | ANY_ROT) == 0;
        if lin != NONE_BIN
            && set.iter().filter(plain).filter(|&&u| u / 27 == lin).count() >= WILDCARD_VARIANTS
        {
            out.insert((lin * 27 + NONE_BIN) | ANY_ROT);
            covered.insert(t);
        }
        if ang != NONE_BIN
            && set.iter().filter(plain).filter(|&&u| u % 27 == ang).count() >= WILDCARD_VARIANTS
        {
            out.insert((NONE_BIN * 27 + ang) | ANY_LIN);
            covered.insert(t);
        }
    }
    out.extend(set.iter().filter(|t| !covered.contains(t)).copied());
    let full: BTreeSet<Symbol> = out
        .iter()
        .filter(|&&s| s & ANY_ROT != 0 && s & WOBBLE_AXES == 0)
        .map(|&s| (s & 0x3ff) / 27)
        .collect();
    // A wobble is no sign where another example turned decisively about the same axis while
    // making the same stroke: that sign is part of the gesture (a kick leans back as it
    // strikes, a throw forward), so the wobble stands only for the stroke without a turn.
    let decisive = |w: Symbol| {
        set.iter().any(|&t| {
            t & (ANY_LIN | ANY_ROT) == 0
                && plain(t) == plain(w)
                && t != plain(t)
                && wobble_axes(t) == w & WOBBLE_AXES
        })
    };
    let out: BTreeSet<Symbol> = out
        .into_iter()
        .map(|s| {
            if s & ANY_ROT != 0 && (s & WOBBLE_AXES).count_ones() == 1 && decisive(s) {
                plain(s)
            } else {
                s
            }
        })
        .collect();
    let expanded: BTreeSet<Symbol> = out.into_iter().flat_map(expand_symbol).collect();
    // What a full wildcard of the same translation already accepts is not written again.
    expanded
        .into_iter()
        .filter(|&s| s & ANY_ROT != 0 || s & ANY_LIN != 0 || !full.contains(&(s / 27)))
        .collect()
}

/// A column's tokens, and for each stroke that turned as it moved (`db.Xn`) the plain stroke
/// (`db`) as well: a rotation read in every example can fall under the token threshold in a
/// performance, or in some of the runs the tokenizer splits the stroke into (`db db.Xn db`),
/// and the stroke is still the same part of the gesture. Where that makes the pattern accept
/// another action's example (a punch's `f` for a kick's `f.Xn`), [`super::separate`] takes
/// the plain stroke out again.
pub fn with_plain(col: &BTreeSet<Token>) -> BTreeSet<Token> {
    let mut out = col.clone();
    for &t in col {
        let (lin, ang) = ((t & 0x3ff) / 27, (t & 0x3ff) % 27);
        if t & (ANY_LIN | ANY_ROT) == 0 && lin != NONE_BIN && ang != NONE_BIN {
            out.insert(lin * 27 + NONE_BIN);
        }
    }
    out
}

fn merge_dups(v: Vec<Token>) -> Vec<Token> {
    let mut out: Vec<Token> = Vec::with_capacity(v.len());
    for t in v {
        if out.last() != Some(&t) {
            out.push(t);
        }
    }
    out
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    Pair(usize, usize),
    Del(usize),
    Ins(usize),
}

/// Alignment cost of leaving a token unpaired (an optional or missing gesture part).
const INDEL: usize = 2;

/// Alignment cost of pairing two symbols in one column: 0 when they mean the same motion,
/// 1 when they share their translation (the examples disagree only about a rotation), and
/// more than two unpaired tokens otherwise — a column never joins unrelated motions such as
/// `d` and `u`, which would make `(d|u)+` accept either.
fn pair_cost(a: Symbol, b: Symbol) -> usize {
    let half = |s: Symbol| (s & 0x3ff) / 27;
    if common_symbol(a, b).is_some() {
        0
    } else if half(a) == half(b) && half(a) != NONE_BIN {
        1
    } else {
        2 * INDEL + 1
    }
}

/// Alignment of `b` to reference `a` (costs: [`pair_cost`], [`INDEL`]).
fn align(a: &[Token], b: &[Token]) -> Vec<Op> {
    let (n, m) = (a.len(), b.len());
    let mut d = vec![vec![0usize; m + 1]; n + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i * INDEL;
    }
    for (j, v) in d[0].iter_mut().enumerate() {
        *v = j * INDEL;
    }
    for i in 1..=n {
        for j in 1..=m {
            let sub = d[i - 1][j - 1] + pair_cost(a[i - 1], b[j - 1]);
            d[i][j] = sub.min(d[i - 1][j] + INDEL).min(d[i][j - 1] + INDEL);
        }
    }
    let (mut i, mut j) = (n, m);
    let mut ops = Vec::new();
    while i > 0 || j > 0 {
        if i > 0 && j > 0 && d[i][j] == d[i - 1][j - 1] + pair_cost(a[i - 1], b[j - 1]) {
            ops.push(Op::Pair(i - 1, j - 1));
            i -= 1;
            j -= 1;
        } else if i > 0 && d[i][j] == d[i - 1][j] + INDEL {
            ops.push(Op::Del(i - 1));
            i -= 1;
        } else {
            ops.push(Op::Ins(j - 1));
            j -= 1;
        }
    }
    ops.reverse();
    ops
}

/// Learns a regex from tokenized sequences; `seqs[0]` is the reference (the average doodle).
pub fn learn_regex(seqs: &[Tokenized]) -> Result<Regex> {
    learn_regex_within(seqs, MAX_POSITIONS, quorum(seqs.len()))
}

/// [`learn_regex`] with at most `budget` token positions (optional groups are dropped first),
/// keeping a variation that `quorum` strings show ([`quorum`]).
pub fn learn_regex_within(seqs: &[Tokenized], budget: usize, quorum: usize) -> Result<Regex> {
    let q = quorum.max(1);
    let mut seqs: Vec<&Tokenized> = seqs.iter().filter(|s| !s.is_empty()).collect();
    // Reference: the sequence with the fewest mandatory runs (the first — the average — on
    // ties), the quorum-th fewest among many. Performances differ most in how many times they
    // repeat a cycle; longer ones are covered by repeating the whole pattern.
    // (At least two mandatory runs: a one-token pattern would fire on any motion.)
    let counts: Vec<usize> = seqs.iter().map(|s| mandatory_runs(s).len()).collect();
    let mut by_count: Vec<usize> = (0..seqs.len()).filter(|&i| counts[i] >= 2).collect();
    by_count.sort_by_key(|&i| (counts[i], i));
    let Some(best) = by_count
        .get(q.min(by_count.len()).saturating_sub(1))
        .copied()
        .or_else(|| (0..seqs.len()).max_by_key(|&i| (counts[i], usize::MAX - i)))
    else {
        bail!("no motion found in any example (all still?)");
    };
    // Cyclic when a quorum of performances is closer to the reference done twice than once.
    let mand_of = |s: &Tokenized| -> Vec<Token> { mandatory_runs(s).iter().map(|m| m.0).collect() };
    let once = mand_of(seqs[best]);
    let twice: Vec<Token> = once.iter().chain(once.iter()).copied().collect();
    // … or when the reference itself repeats a cycle of ≥ 2 parts (compared by their
    // translation when they translate: a walk's rocking differs from hop to hop).
    let key = |t: Token| {
        if (t & 0x3ff) / 27 != NONE_BIN {
            (t & 0x3ff) / 27
        } else {
            t
        }
    };
    let periodic =
        (2..=once.len() / 2).any(|p| (0..once.len() - p).all(|i| key(once[i]) == key(once[i + p])));
    // … or when a quorum of performances repeat one part (by translation): all but a third of
    // the strokes are the stroke one period later, over enough of its mandatory strokes, or of
    // all its strokes (a long performance whose every stride is too brief to be mandatory).
    let repeats = |m: &[Token]| {
        (1..=m.len() / 2).any(|p| {
            let off = (0..m.len() - p).filter(|&i| m[i] != m[i + p]).count();
            REPEAT_OFF_PER * off <= m.len() - p
        })
    };
    let repeats_a_part = |s: &Tokenized| {
        let mand: Vec<Token> = mand_of(s).into_iter().map(key).collect();
        let mut all: Vec<Token> = s.iter().map(|&(t, _)| key(t & 0x3ff)).collect();
        all.dedup();
        (mand.len() >= REPEAT_MANDATORY && repeats(&mand))
            || (all.len() >= REPEAT_STROKES && repeats(&all))
    };
    let cyclic = periodic
        || seqs
            .iter()
            .filter(|s| {
                let m = mand_of(s);
                edit_distance(&m, &twice) < edit_distance(&m, &once)
            })
            .count()
            >= q
        || seqs.iter().filter(|s| repeats_a_part(s)).count() >= q;
    // A cyclic action rocks one way and back from cycle to cycle: which way a stroke wobbled
    // is no part of it. (A one-shot gesture's small turn keeps its sign: a throw's follow-through
    // dips forward, whatever else varies.)
    let owned: Vec<Tokenized>;
    if cyclic {
        owned = seqs
            .iter()
            .map(|s| s.iter().map(|&(t, d)| (unsigned(t), d)).collect())
            .collect();
        seqs = owned.iter().collect();
    }
    seqs.swap(0, best);
    let reference = seqs[0];
    let ref_m: Vec<Token> = mandatory_runs(reference).iter().map(|m| m.0).collect();
    let n = ref_m.len();
    // seen[i][token]: the strings that showed `token` in column i (the reference's own token
    // is kept whatever the count).
    let mut seen: Vec<BTreeMap<Token, BTreeSet<usize>>> = vec![BTreeMap::new(); n];
    let mut missing = vec![0usize; n];
    // Performances too short to afford one edit on the device that lack each column.
    let mut lacked_by_short = vec![0usize; n];
    // gaps[g][k]: optional tokens of sequence k before column g (g = n: after the last).
    let mut gaps: Vec<Vec<Vec<Token>>> = vec![vec![Vec::new(); seqs.len()]; n + 1];
    for (k, s) in seqs.iter().enumerate() {
        let flags = mandatory_flags(s);
        let mand = mandatory_runs(s);
        let mt: Vec<Token> = mand.iter().map(|m| m.0).collect();
        let ops = align(&ref_m, &mt);
        // Column of each mandatory run of s (None = inserted → optional).
        let mut col_of = vec![None; mt.len()];
        for op in &ops {
            match *op {
                Op::Pair(i, j) => {
                    seen[i].entry(mt[j]).or_default().insert(k);
                    col_of[j] = Some(i);
                }
                Op::Del(i) => {
                    missing[i] += 1;
                    lacked_by_short[i] += usize::from(!edits_fit(FULL, s.len()));
                }
                Op::Ins(_) => {}
            }
        }
        // Each non-column run goes to the gap before the next column-aligned run.
        let mut is_col = vec![None; s.len()];
        for (j, &(_, idx)) in mand.iter().enumerate() {
            is_col[idx] = col_of[j];
        }
        // Runs merged into a mandatory duplicate or same-translation neighbour count as that
        // column, which accepts them too.
        for i in 1..s.len() {
            if is_col[i].is_none()
                && flags[i]
                && (s[i].0 == s[i - 1].0 || same_translation(s[i].0, s[i - 1].0))
            {
                is_col[i] = is_col[i - 1];
                if let Some(c) = is_col[i] {
                    seen[c].entry(s[i].0).or_default().insert(k);
                }
            }
        }
        let mut next_col = vec![n; s.len() + 1];
        for i in (0..s.len()).rev() {
            next_col[i] = is_col[i].unwrap_or(next_col[i + 1]);
        }
        for i in 0..s.len() {
            if is_col[i].is_none() {
                gaps[next_col[i]][k].push(s[i].0);
            }
        }
    }
    let cols: Vec<BTreeSet<Token>> = seen
        .iter()
        .zip(&ref_m)
        .map(|(by, &own)| {
            by.iter()
                .filter(|(_, who)| who.len() >= q)
                .map(|(&t, _)| t)
                .chain([own])
                .collect()
        })
        .collect();
    // Build the expression, then shrink optional groups if over capacity.
    let mut opt: Vec<Option<Regex>> = Vec::with_capacity(n + 1);
    let mut opt_support: Vec<usize> = Vec::new();
    let mut inline: Vec<Vec<Token>> = vec![Vec::new(); n + 1];
    for (g, per_seq) in gaps.iter().enumerate() {
        let all_same = per_seq.windows(2).all(|w| w[0] == w[1]);
        if all_same && !per_seq[0].is_empty() {
            inline[g] = merge_dups(per_seq[0].clone());
            opt.push(None);
            opt_support.push(0);
            continue;
        }
        // Optional groups keep whole wildcards: they tell little apart, and the pattern's
        // positions are better spent on its mandatory columns.
        let mut shown: BTreeMap<Token, usize> = BTreeMap::new();
        for v in per_seq {
            let own: BTreeSet<Token> = v.iter().map(|&t| bare(t)).collect();
            own.into_iter()
                .for_each(|t| *shown.entry(t).or_default() += 1);
        }
        let set: BTreeSet<Token> = shown
            .into_iter()
            .filter(|&(_, c)| c >= q)
            .map(|(t, _)| t)
            .collect();
        if set.is_empty() {
            opt.push(None);
            opt_support.push(0);
        } else {
            let alt = Regex::Alt(generalise(&set).into_iter().map(Regex::Sym).collect());
            opt.push(Some(Regex::Star(Box::new(simplify(alt)))));
            opt_support.push(per_seq.iter().filter(|v| !v.is_empty()).count());
        }
    }
    // A column is optional when most sequences lack it, or one too short to afford an edit on
    // the device (`edits_fit`) does — but a pattern keeps at least
    // [`MIN_MANDATORY`] mandatory column (the best supported): one made only of optional
    // parts matches any lone token of its alphabet.
    let mut optional_col: Vec<bool> = missing
        .iter()
        .zip(&lacked_by_short)
        .map(|(&m, &short)| 2 * m >= seqs.len() || short >= q)
        .collect();
    let mut by_support: Vec<usize> = (0..n).collect();
    by_support.sort_by_key(|&g| (missing[g], g));
    for &g in by_support.iter().take(MIN_MANDATORY.min(n)) {
        if optional_col.iter().filter(|o| !**o).count() >= MIN_MANDATORY.min(n) {
            break;
        }
        optional_col[g] = false;
    }
    // A pattern needs two tokens at least: one lone stroke (a kick's thrust) is no run. When
    // the only mandatory part is one every example performs at least twice (a run's strides),
    // it is written twice.
    let mandatory: Vec<usize> = (0..n).filter(|&g| !optional_col[g]).collect();
    let doubled = match (mandatory.as_slice(), inline.iter().all(Vec::is_empty)) {
        ([g], true) => {
            let k = key(ref_m[*g]);
            seqs.iter()
                .all(|s| s.iter().filter(|x| key(x.0) == k).count() >= 2)
                .then_some(*g)
        }
        _ => None,
    };
    loop {
        let mut items = Vec::new();
        for g in 0..=n {
            if let Some(o) = &opt[g] {
                items.push(o.clone());
            }
            for &t in &inline[g] {
                let alt = Regex::Alt(expand_symbol(t).into_iter().map(Regex::Sym).collect());
                items.push(Regex::Plus(Box::new(simplify(alt))));
            }
            if g < n {
                let alt = simplify(Regex::Alt(
                    generalise(&with_plain(&cols[g]))
                        .into_iter()
                        .map(Regex::Sym)
                        .collect(),
                ));
                if doubled == Some(g) {
                    items.push(alt.clone());
                }
                // Optional only when most sequences lack it: a part one performance skipped
                // is still part of the gesture (that performance then costs an edit).
                items.push(if optional_col[g] {
                    Regex::Star(Box::new(alt))
                } else {
                    Regex::Plus(Box::new(alt))
                });
            }
        }
        // The whole gesture may repeat (cyclic actions: walk, wave …; a repeated one-shot
        // action is then one event over all repetitions). A stroke every example repeats
        // (a run's strides) is cyclic too: strides after a short pause continue the run. So
        // is an action of one stroke (a turn): the stroke resumed after a breath is the same
        // action going on, a turn made in two twists.
        let re = if cyclic || doubled.is_some() || mandatory.len() == 1 {
            Regex::Plus(Box::new(Regex::Cat(items)))
        } else {
            Regex::Cat(items)
        };
        if re.positions() <= budget {
            // (A pattern over the device's positions cannot be compiled; a caller that asked
            // for one weighs its size itself.)
            if re.positions() <= MAX_POSITIONS && matches!(re.compile()?.min_len(), 0 | usize::MAX)
            {
                bail!("learnt pattern accepts nothing useful");
            }
            return Ok(re);
        }
        // Drop the least supported optional group.
        let Some(g) = (0..=n)
            .filter(|&g| opt[g].is_some())
            .min_by_key(|&g| opt_support[g])
        else {
            bail!(
                "the examples need {} token positions, more than the device's {MAX_POSITIONS}: \
                 perform the action more simply or split it",
                re.positions()
            );
        };
        opt[g] = None;
    }
}

fn simplify(alt: Regex) -> Regex {
    match alt {
        Regex::Alt(mut v) if v.len() == 1 => v.pop().unwrap_or(Regex::Cat(vec![])),
        other => other,
    }
}

/// Levenshtein distance between two token strings (insertions, deletions, substitutions).
pub fn edit_distance(a: &[Token], b: &[Token]) -> usize {
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, x) in a.iter().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, y) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(x != y))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::super::intent::testing::{accepts, seen, seq, wobble};
    use super::super::intent::{mirror_seq, tokens_only};
    use super::super::library::{full_match, parse_tokens, ActionEntry};
    use super::*;
    use figurine_recognizer::token::parse_token;

    #[test]
    fn a_stroke_that_turned_as_it_moved_is_also_written_plain() {
        let col = |names: &[&str]| -> BTreeSet<Token> {
            names.iter().map(|n| parse_token(n).unwrap()).collect()
        };
        assert_eq!(
            with_plain(&col(&["db.Xn", "f.XpZn"])),
            col(&["db.Xn", "db", "f.XpZn", "f"])
        );
        // Plain strokes and pure rotations (which have no plain stroke) stay as they are.
        assert_eq!(with_plain(&col(&["db", ".Xn"])), col(&["db", ".Xn"]));
        // A throw learnt from examples that all pitched accepts a performance whose release
        // and return pitched too little in some runs.
        let seq = |names: &str| -> Tokenized {
            names
                .split_whitespace()
                .map(|n| (parse_token(n).unwrap(), 0.3))
                .collect()
        };
        let ex = seq("ub.Xn f.Xp db.Xn");
        let re = learn_regex(&[ex.clone(), ex.clone(), ex]).unwrap();
        let entry = ActionEntry::new("throw", &re.to_source(), Some(0), vec![]).unwrap();
        let perf = parse_tokens("ub.Xn f f.Xp db db.Xn db").unwrap();
        assert_eq!(
            full_match(&entry, &perf).unwrap(),
            Some(0),
            "{}",
            re.to_source()
        );
    }

    #[test]
    fn mandatory_and_optional_tokens_make_a_pattern_accepting_every_example() {
        let seqs = vec![
            seq("uf:0.3 f:0.05 df:0.3"),
            seq("uf:0.3 df:0.3"),
            seq("uf:0.25 l:0.01 f:0.02 df:0.35"),
            seq("u:0.1 uf:0.2 df:0.3"),
        ];
        let re = learn_regex(&seqs).unwrap();
        let c = re.compile().unwrap();
        for s in &seqs {
            assert!(
                c.accepts(&tokens_only(s)),
                "{} rejects {:?}",
                re.to_source(),
                s
            );
        }
        assert!(!c.accepts(&tokens_only(&seq("df:1 uf:1"))));
        assert!(re.to_source().contains("uf"), "{}", re.to_source());
    }

    #[test]
    fn the_quorum_is_one_string_up_to_six_examples_then_a_quarter() {
        // Strings are the examples and their average.
        let q: Vec<usize> = (1..=13).map(|examples| quorum(examples + 1)).collect();
        assert_eq!(q, [1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3]);
    }

    #[test]
    fn a_variation_one_of_many_examples_shows_does_not_widen_the_pattern() {
        // Twelve strings (performances and their average) strike forward and back; one more
        // pitched its strike and dipped between the two strokes.
        let plain = seq("f:0.2 b:0.2");
        let odd = seq("f.Xn:0.2 d:0.1 b:0.2");
        let mut many = vec![plain.clone(); 12];
        many.push(odd.clone());
        let re = learn_regex(&many).unwrap();
        assert_eq!(re.to_source(), "f+ b+");
        // The odd one is now an edit and a half away: its pitch and its dip.
        assert!(!accepts(&re, "f.Xn d b"), "{}", re.to_source());
        // Among three examples and their average every variation is kept, as before.
        let few = vec![plain.clone(), plain.clone(), plain, odd.clone()];
        let re = learn_regex(&few).unwrap();
        assert!(accepts(&re, "f.Xn d b"), "{}", re.to_source());
        // Three of thirteen strings showing it are a quorum: it is kept.
        let mut some = vec![seq("f:0.2 b:0.2"); 10];
        some.extend([odd.clone(), odd.clone(), odd]);
        let re = learn_regex(&some).unwrap();
        assert!(accepts(&re, "f.Xn d b"), "{}", re.to_source());
    }

    mod quorum_scales {
        use super::*;
        use proptest::prelude::*;

        const NAMES: [&str; 11] = [
            "f", "b", "u", "d", "uf", "db", "f.Xn", "b.Xp", "d.Xp", "l", "r",
        ];

        fn strings() -> impl Strategy<Value = Vec<Tokenized>> {
            let run = (0..NAMES.len(), 0.05f64..0.4)
                .prop_map(|(i, d)| (parse_token(NAMES[i]).unwrap(), d));
            prop::collection::vec(prop::collection::vec(run, 2..7), 3)
        }

        proptest! {
            #![proptest_config(ProptestConfig {
                cases: 200,
                rng_seed: proptest::test_runner::RngSeed::Fixed(26),
                ..ProptestConfig::default()
            })]
            // Each string taught four times over is taught no differently: the quorum grows by
            // no more than a quarter of the strings, so what one of three strings showed, four
            // of twelve show, and three are a quorum of them.
            #[test]
            fn the_same_strings_taught_four_times_teach_the_same_pattern(three in strings()) {
                let twelve: Vec<Tokenized> =
                    three.iter().flat_map(|s| std::iter::repeat_n(s.clone(), 4)).collect();
                let once = learn_regex(&three).map(|r| r.to_source());
                let four_times = learn_regex(&twelve).map(|r| r.to_source());
                prop_assert_eq!(once.ok(), four_times.ok());
            }
        }
    }

    #[test]
    fn a_column_missing_in_the_shortest_example_becomes_optional() {
        let seqs = vec![
            seq("u:0.3 f:0.3 d:0.3"),
            seq("u:0.3 f:0.3 d:0.3"),
            seq("u:0.5 d:0.5"),
        ];
        let re = learn_regex(&seqs).unwrap();
        assert_eq!(re.to_source(), "u+ f* d+");
    }

    #[test]
    fn a_column_lacked_by_an_example_too_short_for_an_edit_becomes_optional() {
        // The device allows no edit in a two-token match, so a column the short performance
        // lacks must not be required, or that performance would never be recognised.
        let seqs = vec![
            seq("lu:0.3 l:0.3 lu:0.3 l:0.3"),
            seq("lu:0.3 l:0.3 ld:0.2"),
            seq("lu:0.4 lu:0.4"),
        ];
        let re = learn_regex(&seqs).unwrap();
        assert!(accepts(&re, "lu lu"), "{}", re.to_source());
        assert!(accepts(&re, "lu l ld"), "{}", re.to_source());
        // A long performance lacking a column still only costs an edit: the column stays.
        let seqs = vec![
            seq("lu:0.3 l:0.3 ld:0.3 u:0.3"),
            seq("lu:0.3 l:0.3 ld:0.2 u:0.3"),
            seq("lu:0.3 ld:0.3 u:0.3 b:0.3"),
        ];
        let re = learn_regex(&seqs).unwrap();
        assert!(re.to_source().contains("l+"), "{}", re.to_source());
    }

    #[test]
    fn a_performance_repeating_a_part_makes_the_action_cyclic() {
        // Every example already holds two hops, each a little differently: no exact period,
        // and none is closer to the reference done twice — but in two of them every stroke
        // but one in three is the stroke a hop later.
        assert!(cyclic(&[
            "uf:0.3 df:0.3 f:0.3 uf:0.3 df:0.3",
            "uf:0.3 df:0.3 uf:0.3 df:0.3 f:0.3",
            "uf:0.3 f:0.3 df:0.3 uf:0.3 df:0.3",
        ]));
        // A back-and-forth stroke is no cycle: no stroke comes back a period later.
        assert!(!cyclic(&["b:0.3 f:0.3 b:0.3", "b:0.3 f:0.3 b:0.3"]));
    }

    /// Whether the pattern learnt from these strings (`token:seconds …`) is cyclic.
    fn cyclic(strings: &[&str]) -> bool {
        let seqs: Vec<Tokenized> = strings.iter().map(|s| seq(s)).collect();
        let re = learn_regex(&seqs).unwrap();
        let cyclic = re.compile().unwrap().cyclic;
        eprintln!("{} cyclic: {cyclic}", re.to_source());
        cyclic
    }

    #[test]
    fn a_thrust_and_its_return_is_no_cycle() {
        // Kicks: a wind-up, the thrust, its return and a settling step back. Each string's
        // halves (`b f` and `b db`) differ by one stroke, but half its strokes do not come
        // back a period later: one kick, not two.
        assert!(!cyclic(&[
            "b:0.15 f.Xn:0.3 b.Xp:0.3 db:0.15",
            "b:0.15 f.Xn:0.25 b.Xp:0.35 db.Xp:0.15",
            "b:0.12 uf.Xn:0.3 b.Xp:0.3 db.Xp:0.2",
        ]));
    }

    #[test]
    fn strides_too_brief_to_be_mandatory_still_make_a_cycle() {
        // A walk taught with one long stride, then brief ones: only the long stride's runs
        // are mandatory, but all its strokes repeat `uf df`, fewer than one in three off.
        assert!(cyclic(&[
            "uf:0.6 df:0.6 f:0.04 uf:0.04 df:0.04 uf:0.04 df:0.04 uf:0.04 df:0.04",
            "uf:0.5 df:0.7 uf:0.04 df:0.04 uf:0.04 df:0.05 uf:0.04 df:0.04",
        ]));
    }

    #[test]
    fn tokens_disagreeing_in_one_half_become_wildcards() {
        let names = |tokens: &[&str]| -> Vec<String> {
            let set: BTreeSet<Token> = tokens.iter().map(|t| parse_token(t).unwrap()).collect();
            generalise(&set)
                .into_iter()
                .map(super::super::regex::symbol_name)
                .collect()
        };
        let n = names(&["uf.Zp", "uf.Zn", "uf.Xp", "f", ".Yn", "d.Yn", "u.Yn"]);
        assert_eq!(n.len(), 3, "{n:?}");
        assert!(n.contains(&"uf~".to_string()) && n.contains(&"~.Yn".to_string()));
        assert!(n.contains(&"f".to_string()));
        // Two variants are not evidence enough: a kick's `b.Xp` must not become any `b~`
        // (a punch's `b.Zn`).
        let n = names(&["b", "b.Xp"]);
        assert_eq!(n, ["b", "b.Xp"], "{n:?}");
    }

    #[test]
    fn a_one_shot_gesture_keeps_the_sign_its_wobbles_were_seen_with() {
        let names = |v: Vec<Symbol>| -> Vec<String> {
            let mut n: Vec<String> = v
                .into_iter()
                .map(super::super::regex::symbol_name)
                .collect();
            n.sort();
            n
        };
        assert_eq!(names(expand_symbol(seen("db.Xn"))), ["db", "db.Xn"]);
        assert_eq!(
            names(expand_symbol(unsigned(seen("db.Xn")))),
            ["db", "db.Xn", "db.Xp"]
        );
        assert_eq!(unsigned(seen("db.Xn")), wobble("db.Xn"));
        assert_eq!(bare(seen("db.Xn")), bare(wobble("db.Xp")));
        let m = mirror_seq(&vec![(seen("lu.Zp"), 0.1)]);
        assert_eq!(m[0].0, seen("ru.Zn"));
        // A wobble beside the same stroke turned decisively about its axis is the plain
        // stroke: a kick leans back as it strikes, and never forward.
        let set = BTreeSet::from([wobble("f.Xp"), parse_token("f.Xn").unwrap()]);
        assert_eq!(names(generalise(&set)), ["f", "f.Xn"]);
        let set = BTreeSet::from([wobble("f.Xp"), parse_token("f.Zn").unwrap()]);
        assert_eq!(names(generalise(&set)), ["f", "f.Xn", "f.Xp", "f.Zn"]);
        let toks = |s: &str| -> Vec<Token> {
            s.split_whitespace()
                .map(|w| parse_token(w).unwrap())
                .collect()
        };
        // Throws whose follow-through dipped forward a little each time.
        let throw = || {
            vec![
                (parse_token("ub").unwrap(), 0.2),
                (parse_token("f.Xp").unwrap(), 0.3),
                (seen("db.Xn"), 0.2),
            ]
        };
        let re = learn_regex(&[throw(), throw(), throw()]).unwrap();
        let c = re.compile().unwrap();
        assert!(c.accepts(&toks("ub f.Xp db.Xn")), "{}", re.to_source());
        assert!(c.accepts(&toks("ub f.Xp db")), "{}", re.to_source());
        assert!(!c.accepts(&toks("ub f.Xp db.Xp")), "{}", re.to_source());
        // A walk rocks one way and back from hop to hop: either sign.
        let hop = |w: &str| [(parse_token("uf").unwrap(), 0.2), (seen(w), 0.2)];
        let walk: Tokenized = [hop("df.Zn"), hop("df.Zn")].concat();
        let re = learn_regex(&[walk.clone(), walk.clone(), walk]).unwrap();
        assert!(
            re.compile().unwrap().accepts(&toks("uf df.Zp uf df.Zp")),
            "{}",
            re.to_source()
        );
    }

    #[test]
    fn a_rolling_punch_does_not_accept_a_pitched_kick() {
        // Three punches whose forward stroke rolls a little (incidental), once about each
        // sign: the column accepts the plain stroke and any roll, not a pitch.
        let punch = |w: Symbol| {
            vec![
                (parse_token("b").unwrap(), 0.2),
                (w, 0.3),
                (parse_token("b").unwrap(), 0.2),
            ]
        };
        let seqs = vec![
            punch(wobble("f.Zp")),
            punch(wobble("f.Zn")),
            punch(wobble("f.Zp")),
            punch(wobble("f.Zn")),
        ];
        let re = learn_regex(&seqs).unwrap();
        let c = re.compile().unwrap();
        let toks = |s: &str| -> Vec<Token> {
            s.split_whitespace()
                .map(|w| parse_token(w).unwrap())
                .collect()
        };
        for ok in ["b f b", "b f.Zp b", "b f.Zn b"] {
            assert!(c.accepts(&toks(ok)), "{} rejects {ok}", re.to_source());
        }
        assert!(
            !c.accepts(&toks("b f.Xn b")),
            "{} accepts a kick",
            re.to_source()
        );
        // Wobbles about two axes learn the whole wildcard, as before.
        let seqs = vec![
            punch(wobble("f.XpZp")),
            punch(wobble("f.XnZn")),
            punch(wobble("f.Zp")),
        ];
        let re = learn_regex(&seqs).unwrap();
        assert!(
            re.compile().unwrap().accepts(&toks("b f.Xn b")),
            "{}",
            re.to_source()
        );
    }

    #[test]
    fn a_part_every_example_repeats_is_needed_twice() {
        // Runs: every example has several forward strides; a lone forward thrust is no run.
        let seqs = vec![
            seq("f:0.3 f.Zp:0.1 f:0.3"),
            seq("f:0.2 f:0.2 f:0.2 f:0.2"),
            seq("f:0.3 uf:0.05 f:0.3"),
        ];
        let re = learn_regex(&seqs).unwrap();
        let c = re.compile().unwrap();
        assert_eq!(c.min_len(), 2, "{}", re.to_source());
        let f = parse_token("f").unwrap();
        assert!(!c.accepts(&[f]), "{}", re.to_source());
        assert!(c.accepts(&[f, f, f]), "{}", re.to_source());
        // Repeated strides make it cyclic: more strides after a pause continue the run.
        assert!(c.cyclic, "{}", re.to_source());
        // One example with a single stroke: one is enough.
        let seqs = vec![seq("f:0.3 f.Zp:0.1 f:0.3"), seq("f:0.6")];
        let re = learn_regex(&seqs).unwrap();
        assert!(re.compile().unwrap().accepts(&[f]), "{}", re.to_source());
    }

    #[test]
    fn an_action_of_one_stroke_goes_on_when_the_stroke_resumes() {
        // Turns: one twist each, with a little settling in one.
        let seqs = vec![
            seq(".Yn:0.5"),
            seq("df:0.05 .Yn:0.6 u:0.05"),
            seq(".Yn:0.4"),
        ];
        let re = learn_regex(&seqs).unwrap();
        assert!(re.compile().unwrap().cyclic, "{}", re.to_source());
        // A turn in two twists, with its settling between them, is one match.
        assert!(accepts(&re, ".Yn u .Yn"), "{}", re.to_source());
        // A two-stroke action does not become cyclic by this.
        let seqs = vec![seq("b:0.3 f:0.3"), seq("b:0.2 f:0.4")];
        let re = learn_regex(&seqs).unwrap();
        assert!(!re.compile().unwrap().cyclic, "{}", re.to_source());
    }

    #[test]
    fn a_stroke_whose_rotation_begins_midway_is_one_column() {
        // `b b.Xp` (one backward stroke, the rotation starting halfway) aligns with `b.Xp`.
        let re = learn_regex(&[
            seq("f.Xn:0.3 b.Xp:0.3"),
            seq("f.Xn:0.3 b:0.15 b.Xp:0.15"),
            seq("f.Xn:0.3 b.Xp:0.3"),
        ])
        .unwrap();
        let src = re.to_source();
        assert_eq!(src.matches('+').count(), 2, "{src}");
        assert!(src.contains("b.Xp") && src.contains("(b|b.Xp)"), "{src}");
    }

    #[test]
    fn a_pattern_keeps_one_mandatory_column() {
        // No column is shared by most examples; the best supported stays mandatory.
        let re = learn_regex(&[
            seq("f:0.3 uf:0.3"),
            seq("df:0.3 ub:0.3"),
            seq("df:0.3 ub:0.3"),
            seq("f:0.3 uf:0.3"),
        ])
        .unwrap();
        assert!(re.to_source().contains('+'), "{}", re.to_source());
    }

    #[test]
    fn identical_optional_sequences_become_mandatory() {
        let seqs = vec![seq("u:1 l:0.01 d:1"), seq("u:1 l:0.01 d:1")];
        assert_eq!(learn_regex(&seqs).unwrap().to_source(), "u+ l+ d+");
    }
}
