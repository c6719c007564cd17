//! `figurine learn`: an action's pattern from a few example logs (seed 000 §4.3).
//!
//! 1. Each example is tokenized by the device front end (through the wire quantisation); its
//!    gesture is the span from the first to the last non-STILL run.
//! 2. The examples are DTW-averaged ([`super::dtw`]) and the average doodle is tokenized too.
//! 3. In every token string, a run is *mandatory* when it lasts at least
//!    [`MANDATORY_SHARE`] of that gesture's moving time (a deliberate part of the gesture),
//!    otherwise *optional* (a transition or a wobble). The seed's "repeated more than twice"
//!    counts samples; durations make the rule independent of the sample rate.
//! 4. The mandatory strings of the examples are aligned to the average's by edit-distance
//!    alignment. Column i becomes `(m_i0|…|m_in)+`, or `…*` when some example lacks it. A run
//!    whose rotation barely turned (a wobble, [`intent_symbols`]) — or a plain stroke that
//!    tilted a few degrees about one axis, too slowly for a rotation token — is written in a
//!    column as the plain stroke or that wobble about the same axis (`f|f.Zn|f.Zp`), so a
//!    punch that rolls does not accept a kick's pitch ([`expand_symbol`]); a stroke that
//!    turned as it moved is written with its plain stroke too (`db.Xn|db`, [`with_plain`]:
//!    the turn may fall under the token threshold in another performance). A pattern needs
//!    two tokens at least: when its only mandatory column is a part every example performs
//!    twice or more (a run's strides), that column is written twice.
//! 5. The optional tokens found between two columns become `(o_1|…|o_k)*` before the later
//!    column — or mandatory columns when every example has the same optional sequence there.
//! 6. Every example is checked to be accepted exactly; the edit bound defaults to about one per
//!    three tokens of the shortest match.
//! 7. Against the rest of the library ([`super::separate`]): a pattern that accepts another
//!    action's example exactly is narrowed until it does not; when it cannot be without
//!    losing its own examples, the other action is made as tolerant of the shared strokes'
//!    rotations.

use std::collections::BTreeSet;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use figurine_recognizer::alignment::FULL;
use figurine_recognizer::extent::{Extent, ExtentSums};
use figurine_recognizer::features::{Accum, Shape, ShapeSums, ANGVEL, SPEED};
use figurine_recognizer::history::Run;
use figurine_recognizer::pattern::MAX_POSITIONS;
use figurine_recognizer::segment::edits_fit;
use figurine_recognizer::shape::SHAPE_SCALE;
use figurine_recognizer::token::{
    mirror_token, symbol_matches, token_from_signs, token_signs, Symbol, Token, ANY_LIN, ANY_ROT,
    NONE_BIN, STILL, TURN,
};

use super::dtw;
use super::feed::{gesture_runs, log_gesture, log_runs, log_samples};
use super::library::{full_match, parse_tokens, tokens_to_string, ActionEntry, LibraryFile};
use super::regex::{default_edits, Regex};
use crate::poselog::PoseLog;

/// Share of a gesture's moving time a run needs to be mandatory.
pub const MANDATORY_SHARE: f64 = 0.08;

/// Arguments of `figurine learn`.
#[derive(Args, Debug)]
pub struct LearnArgs {
    /// The library file to update (created if missing).
    #[arg(long)]
    pub library: PathBuf,
    /// Name of the action to learn or replace.
    #[arg(long)]
    pub name: String,
    /// Edit bound (default: one per three tokens of the shortest match, at most 3).
    #[arg(long)]
    pub max_edits: Option<u8>,
    /// Do not also accept the mirror image (left ↔ right) of the examples.
    #[arg(long)]
    pub no_mirror: bool,
    /// Example logs, one performance each (three are usually enough).
    #[arg(required = true)]
    pub examples: Vec<PathBuf>,
}

/// One tokenized gesture: (token, duration in seconds) per run, STILL removed.
pub type Tokenized = Vec<(Token, f64)>;

/// One example log, read once through the device front end: its gesture's runs (STILL
/// included) and the span (seconds, log clock) from its first to its last motion.
struct Example {
    runs: Vec<Run>,
    span: Option<(f64, f64)>,
}

impl Example {
    fn read(log: &PoseLog) -> Self {
        let (samples, _) = log_samples(log);
        let runs = log_runs(&samples);
        let g = gesture_runs(&runs);
        let clock = super::feed::Clock::new(log, &samples);
        let span = g
            .first()
            .zip(g.last())
            .map(|(a, b)| (clock.time_of(a.start.0), clock.time_of(b.end.0)));
        Example {
            runs: g.to_vec(),
            span,
        }
    }
}

/// Tokenizes the gesture of a one-performance log.
pub fn tokenize_gesture(log: &PoseLog) -> Tokenized {
    tokens_of(&log_gesture(log))
}

/// The moving runs of a gesture as (token, duration).
fn tokens_of(g: &[Run]) -> Tokenized {
    g.iter()
        .filter(|r| r.token != STILL)
        .map(|r| (r.token, run_seconds(r)))
        .collect()
}

/// A run's duration as the learner weighs it, seconds (one tick more than first to last).
fn run_seconds(r: &Run) -> f64 {
    (r.end.1.saturating_sub(r.start.1)) as f64 * 1e-6 + 0.01
}

/// The motion shape of a one-performance log's gesture, from its first to its last motion
/// (`figurine_recognizer::features::Shape`) — what the device measures over a match
/// (`figurine_recognizer::shape::shape_penalty`). None without motion.
pub fn motion_shape(log: &PoseLog) -> Option<Shape> {
    shape_of_runs(&log_gesture(log))
}

/// [`motion_shape`] of a gesture's runs.
fn shape_of_runs(g: &[Run]) -> Option<Shape> {
    if g.is_empty() {
        return None;
    }
    let mut sums = ShapeSums::new();
    for r in g {
        sums.add(&r.acc, r.token == STILL);
    }
    Some(sums.shape())
}

/// How far a gesture's runs went from where it began ([`figurine_recognizer::extent`]).
fn extent_of_runs(g: &[Run]) -> Extent {
    let mut sums = ExtentSums::new();
    for r in g {
        sums.add(&r.acc);
    }
    sums.extent()
}

/// The longest stillness inside any of the gestures (each from its first to its last motion),
/// seconds; None when none held still inside.
pub fn longest_hold<'a>(gestures: impl IntoIterator<Item = &'a [Run]>) -> Option<f32> {
    gestures
        .into_iter()
        .flat_map(|g| g.iter().filter(|r| r.token == STILL))
        .map(|r| run_seconds(r) as f32)
        .reduce(f32::max)
}

/// The least extent among gestures that moved, dimension by dimension: how far the least of
/// an action's examples went, what the device holds a performance to
/// ([`figurine_recognizer::extent::far_enough`]). None without a gesture.
pub fn least_extent<'a>(gestures: impl IntoIterator<Item = &'a [Run]>) -> Option<Extent> {
    gestures
        .into_iter()
        .filter(|g| !g.is_empty())
        .map(extent_of_runs)
        .reduce(|a, b| Extent {
            moved_m: a.moved_m.min(b.moved_m),
            turned_rad: a.turned_rad.min(b.turned_rad),
            travel_m: a.travel_m.min(b.travel_m),
        })
}

/// The motion shapes of the examples that moved ([`motion_shape`]), read once for
/// [`mean_shape`] and [`shape_tolerance`].
pub fn example_shapes(logs: &[PoseLog]) -> Vec<Shape> {
    logs.iter().filter_map(motion_shape).collect()
}

/// Least tolerance of a shape dimension ([`shape_tolerance`]), in its weighted units (a share
/// of speed): a few examples that happened to agree closely in a dimension still leave some
/// room for the next performance.
pub const SHAPE_TOLERANCE_FLOOR: f32 = 0.06;

/// How far the shapes lie from their mean ([`mean_shape`]) in each dimension: the largest
/// |shape − mean|, weighted by `SHAPE_SCALE` as the device weighs it
/// (`figurine_recognizer::shape::shape_penalty`), at least [`SHAPE_TOLERANCE_FLOOR`].
/// None without shapes.
pub fn shape_tolerance(shapes: &[Shape]) -> Option<Shape> {
    let mean = mean_shape(shapes)?;
    Some(core::array::from_fn(|k| {
        let far = shapes
            .iter()
            .map(|s| (s[k] - mean[k]).abs())
            .fold(0.0f32, f32::max);
        (SHAPE_SCALE[k] * far).max(SHAPE_TOLERANCE_FLOOR)
    }))
}

/// The mean of motion shapes ([`example_shapes`]); None without shapes.
pub fn mean_shape(shapes: &[Shape]) -> Option<Shape> {
    if shapes.is_empty() {
        return None;
    }
    let n = shapes.len() as f32;
    Some(core::array::from_fn(|k| {
        shapes.iter().map(|s| s[k]).sum::<f32>() / n
    }))
}

/// Rotation (rad) below which a run's rotation half is a wobble, not part of the gesture.
pub const INCIDENTAL_ANGLE_RAD: f64 = 0.35;
/// Share of the gesture's path length below which a run's translation half is incidental.
pub const INCIDENTAL_PATH_SHARE: f64 = 0.05;

/// A wobble symbol without the sign it was seen turning with (both signs about its axis).
fn unsigned(s: Symbol) -> Symbol {
    if s & ANY_ROT != 0 && s & WOBBLE_AXES != 0 {
        plain(s) | (s & (ANY_ROT | WOBBLE_AXES))
    } else {
        s
    }
}

/// `s` without its learner-only marks: a rotation wildcard (`f~`) as the written pattern has
/// it, whatever wobble it was seen with.
fn bare(s: Symbol) -> Symbol {
    unsigned(s) & !WOBBLE_AXES
}

/// The plain stroke of symbol `s`: its translation, no rotation, no marks.
fn plain(s: Symbol) -> Symbol {
    (s & 0x3ff) / 27 * 27 + NONE_BIN
}

/// Learner-only bits on an incidental-rotation wildcard (`f~`): the axes the wobble was seen
/// about (bit 10 X, 11 Y, 12 Z). A wobble the tokenizer saw turning one way also keeps that
/// token in its low bits (`f.Zp` with [`ANY_ROT`]); a slow one, read without a rotation, keeps
/// the plain token. They never reach a library: [`expand_symbol`] writes such a symbol out as
/// the plain token and its wobbles about that one axis (`f|f.Zp`, or `f|f.Zp|f.Zn` when no
/// sign was seen), so a punch that rolls a little does not also accept a kick's deliberate
/// pitch.
pub const WOBBLE_AXES: Symbol = 0b111 << WOBBLE_SHIFT;
/// Bit of the X axis in [`WOBBLE_AXES`] (Y and Z follow).
const WOBBLE_SHIFT: u16 = 10;

/// The [`WOBBLE_AXES`] bits of the axes token `t` rotates about.
fn wobble_axes(t: Token) -> Symbol {
    let (_, a) = token_signs(t & 0x3ff);
    a.iter()
        .enumerate()
        .filter(|(_, s)| **s != 0)
        .fold(0, |m, (i, _)| m | (1 << (WOBBLE_SHIFT as usize + i)))
}

/// Angle (rad, ≈ 7°) a plain stroke must turn about one axis for that turn to count as a
/// wobble of it ([`intent_symbols`]).
pub const SLOW_WOBBLE_RAD: f64 = 0.12;
/// Share of a plain stroke's turning that one axis needs to be its wobble axis.
pub const SLOW_WOBBLE_SHARE: f64 = 0.6;

/// The axis a plain stroke (`d`: translation, no rotation token) tilted about, when it did so
/// by [`SLOW_WOBBLE_RAD`] or more and mostly about that one axis: too slowly for a rotation
/// token, as a sustained performance tilts, while a sudden performance of the same stroke
/// turns as far in less time and is written `d.Xp`. Learning such a stroke as its wobble
/// (`d|d.Xn|d.Xp`) keeps the pattern from depending on the examples' speed.
fn slow_wobble_axis(acc: &Accum, t: Token) -> Option<u16> {
    let (lin, ang) = (t / 27, t % 27);
    if lin == NONE_BIN || ang != NONE_BIN {
        return None;
    }
    let dt = f64::from(figurine_recognizer::intake::TICK_S);
    let a: [f64; 3] = core::array::from_fn(|i| dt * f64::from(acc.sum[ANGVEL + i]));
    let total: f64 = a.iter().sum();
    let (axis, &most) = a.iter().enumerate().max_by(|x, y| x.1.total_cmp(y.1))?;
    (most >= SLOW_WOBBLE_RAD && most >= SLOW_WOBBLE_SHARE * total).then_some(axis as u16)
}

/// The symbols a learnt symbol stands for in a written pattern: a wildcard with wobble axes
/// becomes the plain token plus the sign it was seen turning with about its one axis, or both
/// signs when none was seen (a wobble about two or three axes stays the full wildcard); every
/// other symbol stands for itself.
pub fn expand_symbol(s: Symbol) -> Vec<Symbol> {
    let axes = s & WOBBLE_AXES;
    if axes.count_ones() != 1 || s & ANY_ROT == 0 {
        return vec![bare(s)];
    }
    let lin = (s & 0x3ff) / 27;
    if s & 0x3ff != plain(s) {
        return vec![plain(s), s & 0x3ff];
    }
    let axis = (axes >> WOBBLE_SHIFT).trailing_zeros() as usize;
    let (l, _) = token_signs(lin * 27 + NONE_BIN);
    let mut out = vec![lin * 27 + NONE_BIN];
    for sign in [-1i8, 1] {
        let mut a = [0i8; 3];
        a[axis] = sign;
        out.push(token_from_signs(l, a));
    }
    out
}

/// Like [`tokenize_gesture`], but each run is written as the symbol of what it means: a half
/// that barely moved (a rotation of less than [`INCIDENTAL_ANGLE_RAD`], a translation shorter
/// than [`INCIDENTAL_PATH_SHARE`] of the path) becomes a wildcard, so `d.Xp` with a 5° tilt is
/// learnt as `d~` about X, seen turning `.Xp` ([`WOBBLE_AXES`]). A one-shot action's pattern
/// then accepts `d` and `d.Xp`; a cyclic one's, which rocks each way in turn, `d.Xn` too.
pub fn intent_symbols(log: &PoseLog) -> Tokenized {
    intent_of(&log_gesture(log))
}

/// [`intent_symbols`] of a gesture's runs.
fn intent_of(runs: &[Run]) -> Tokenized {
    let g: Vec<&Run> = runs.iter().filter(|r| r.token != STILL).collect();
    let dt = f64::from(figurine_recognizer::intake::TICK_S);
    let path: f64 = g.iter().map(|r| f64::from(r.acc.sum[SPEED]) * dt).sum();
    g.iter()
        .map(|r| {
            let t = r.token;
            let (lin, ang) = (t / 27, t % 27);
            let angle = dt * f64::from(r.acc.turn_sum());
            let dist = dt * f64::from(r.acc.sum[SPEED]);
            let sym = if lin != NONE_BIN && ang != NONE_BIN && angle < INCIDENTAL_ANGLE_RAD {
                t | ANY_ROT | wobble_axes(t)
            } else if let Some(axis) = slow_wobble_axis(&r.acc, t) {
                (lin * 27 + NONE_BIN) | ANY_ROT | (1 << (WOBBLE_SHIFT + axis))
            } else if lin != NONE_BIN && ang != NONE_BIN && dist < INCIDENTAL_PATH_SHARE * path {
                (NONE_BIN * 27 + ang) | ANY_LIN
            } else {
                t
            };
            (sym, run_seconds(r))
        })
        .collect()
}

/// The symbol meaning both `a` and `b` when one is a wildcard covering the other (`d~` for
/// `d` and `d~`), else `None`.
pub fn common_symbol(a: Symbol, b: Symbol) -> Option<Symbol> {
    let flags = ANY_LIN | ANY_ROT;
    if a == b || (a & flags != 0 && b & flags == 0 && symbol_matches(a, b)) {
        Some(a)
    } else if b & flags != 0 && a & flags == 0 && symbol_matches(b, a) {
        Some(b)
    } else {
        None
    }
}

/// Token string as the automata see it (STILL already removed).
pub fn tokens_only(t: &Tokenized) -> Vec<Token> {
    t.iter().map(|x| x.0).collect()
}

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
fn mandatory_runs(t: &Tokenized) -> Vec<(Token, usize)> {
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

/// Mandatory columns a learnt pattern keeps at least (when its reference has that many).
pub const MIN_MANDATORY: usize = 1;

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
    learn_regex_within(seqs, MAX_POSITIONS)
}

/// [`learn_regex`] with at most `budget` token positions (optional groups are dropped first).
pub fn learn_regex_within(seqs: &[Tokenized], budget: usize) -> Result<Regex> {
    let mut seqs: Vec<&Tokenized> = seqs.iter().filter(|s| !s.is_empty()).collect();
    // Reference: the sequence with the fewest mandatory runs (the first — the average — on
    // ties). Performances differ most in how many times they repeat a cycle; longer ones are
    // covered by repeating the whole pattern.
    // (At least two mandatory runs: a one-token pattern would fire on any motion.)
    let counts: Vec<usize> = seqs.iter().map(|s| mandatory_runs(s).len()).collect();
    let Some(best) = (0..seqs.len())
        .filter(|&i| counts[i] >= 2)
        .min_by_key(|&i| (counts[i], i))
        .or_else(|| (0..seqs.len()).max_by_key(|&i| (counts[i], usize::MAX - i)))
    else {
        bail!("no motion found in any example (all still?)");
    };
    // Cyclic when some performance is closer to the reference done twice than once.
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
    // … or when some performance is two near-copies of one part (by translation, as above):
    // its halves differ by at most one run.
    let halves = |s: &Tokenized| {
        let m: Vec<Token> = mand_of(s).into_iter().map(key).collect();
        m.len() >= 4 && (2..=m.len() - 2).any(|p| edit_distance(&m[..p], &m[p..]) <= 1)
    };
    let cyclic = periodic
        || seqs.iter().any(|s| {
            let m = mand_of(s);
            edit_distance(&m, &twice) < edit_distance(&m, &once)
        })
        || seqs.iter().any(|s| halves(s));
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
    let mut cols: Vec<BTreeSet<Token>> = ref_m.iter().map(|&t| BTreeSet::from([t])).collect();
    let mut missing = vec![0usize; n];
    // Columns a performance too short to afford one edit on the device lacks.
    let mut lacked_by_short = vec![false; n];
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
                    cols[i].insert(mt[j]);
                    col_of[j] = Some(i);
                }
                Op::Del(i) => {
                    missing[i] += 1;
                    lacked_by_short[i] |= !edits_fit(FULL, s.len());
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
                    cols[c].insert(s[i].0);
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
        let set: BTreeSet<Token> = per_seq.iter().flatten().map(|&t| bare(t)).collect();
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
        .map(|(&m, &short)| 2 * m >= seqs.len() || short)
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

/// Learns a pattern that also accepts the mirror images (left ↔ right) of the examples: a
/// figurine action done to the other side is the same action. When both sides do not fit the
/// device together:
///
/// | the mirror images … | then |
/// |---|---|
/// | make the same strokes (a walk, a crouch: only the wobbles' signs differ) | one pattern is learnt from the examples and their mirror images together, when it fits whole |
/// | make other strokes (a sidestep's `l` is `r`), or the joint pattern does not fit | each side sheds optional groups evenly, then rotation variants become wildcards ([`compact_rotations`]); only when even that does not fit is it the examples' own side |
///
/// A shed optional group loses the examples that needed it; a joint pattern loses none.
pub fn learn_regex_mirrored(seqs: &[Tokenized]) -> Result<Regex> {
    let direct = learn_regex(seqs)?;
    let mirrored: Vec<Tokenized> = seqs.iter().map(mirror_seq).collect();
    let Ok(mirror) = learn_regex(&mirrored) else {
        return Ok(direct);
    };
    if mirror.to_source() == direct.to_source() {
        return Ok(direct);
    }
    // Both sides within the device's positions: shed optional groups evenly if needed.
    let half = MAX_POSITIONS / 2;
    let both = Regex::Alt(vec![direct.clone(), mirror.clone()]);
    if both.positions() <= MAX_POSITIONS {
        return Ok(both);
    }
    if seqs
        .iter()
        .zip(&mirrored)
        .all(|(a, b)| strokes(a) == strokes(b))
    {
        let joint: Vec<Tokenized> = seqs.iter().chain(&mirrored).cloned().collect();
        if let Ok(re) = learn_regex_within(&joint, usize::MAX) {
            if re.positions() <= MAX_POSITIONS && re.compile()?.min_len() != usize::MAX {
                return Ok(re);
            }
        }
    }
    if let (Ok(d), Ok(m)) = (
        learn_regex_within(seqs, half),
        learn_regex_within(&mirrored, half),
    ) {
        return Ok(Regex::Alt(vec![d, m]));
    }
    // Still too big: a stroke's rotation variants (`lu.Zn|lu|lu.Zp`) become one wildcard
    // (`lu~`) — a rotation that differs costs only half an edit on the device anyway — so
    // that both sides fit; one side alone would never recognise the other.
    let (d, m) = (compact_rotations(&direct), compact_rotations(&mirror));
    let both = Regex::Alt(vec![d, m]);
    if both.positions() <= MAX_POSITIONS {
        Ok(both)
    } else {
        Ok(direct)
    }
}

/// The translation halves (strokes) of a gesture's mandatory runs, in order ([`NONE_BIN`] for a
/// run that only turned).
fn strokes(s: &Tokenized) -> Vec<u16> {
    mandatory_runs(s)
        .iter()
        .map(|m| (m.0 & 0x3ff) / 27)
        .collect()
}

/// `re` with every alternation of plain tokens that share one translation (`f.Zn|f|f.Zp`)
/// written as that translation with any rotation (`f~`).
pub fn compact_rotations(re: &Regex) -> Regex {
    let lin = |r: &Regex| match r {
        Regex::Sym(s) if s & (ANY_LIN | ANY_ROT) == 0 && s / 27 != NONE_BIN => Some(s / 27),
        Regex::Sym(s) if s & ANY_ROT != 0 => Some((s & 0x3ff) / 27),
        _ => None,
    };
    match re {
        Regex::Alt(v) if v.len() > 1 => {
            let first = lin(&v[0]);
            if first.is_some() && v.iter().all(|r| lin(r) == first) {
                let l = first.unwrap_or(NONE_BIN);
                Regex::Sym((l * 27 + NONE_BIN) | ANY_ROT)
            } else {
                Regex::Alt(v.iter().map(compact_rotations).collect())
            }
        }
        Regex::Alt(v) => Regex::Alt(v.iter().map(compact_rotations).collect()),
        Regex::Cat(v) => Regex::Cat(v.iter().map(compact_rotations).collect()),
        Regex::Star(r) => Regex::Star(Box::new(compact_rotations(r))),
        Regex::Plus(r) => Regex::Plus(Box::new(compact_rotations(r))),
        Regex::Opt(r) => Regex::Opt(Box::new(compact_rotations(r))),
        Regex::Sym(s) => Regex::Sym(*s),
    }
}

/// Which examples to mirror so that all are performed to the side of the median-length one:
/// those whose mirror image is closer to it, compared by [`side_keys`].
fn to_one_side(seqs: &[Tokenized]) -> Vec<bool> {
    let mut order: Vec<usize> = (0..seqs.len()).collect();
    order.sort_by_key(|&i| seqs[i].len());
    let Some(&r) = order.get(order.len() / 2) else {
        return Vec::new();
    };
    let reference = side_keys(&seqs[r]);
    seqs.iter()
        .map(|s| {
            edit_distance(&side_keys(&mirror_seq(s)), &reference)
                < edit_distance(&side_keys(s), &reference)
        })
        .collect()
}

/// What tells a performance's side: each run's translation when it translates, else its
/// rotation — not the wobble marks or the tilt of a stroke, which differ between performances
/// of the same side and would hide a mirrored one.
fn side_keys(s: &Tokenized) -> Vec<Token> {
    s.iter()
        .map(|&(t, _)| {
            let lin = (t & 0x3ff) / 27;
            if t & ANY_LIN == 0 && lin != NONE_BIN {
                lin
            } else {
                27 + (t & 0x3ff) % 27
            }
        })
        .collect()
}

fn mirror_seq(s: &Tokenized) -> Tokenized {
    // A mirror flips signs, not axes: the wobble axes stay.
    let flags = ANY_LIN | ANY_ROT | WOBBLE_AXES;
    s.iter()
        .map(|&(t, d)| (mirror_token(t & !flags) | (t & flags), d))
        .collect()
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

/// Learns action `name` from example logs (one performance each); `mirror` also accepts the
/// left–right mirror images.
pub fn learn_action(
    name: &str,
    logs: &[PoseLog],
    max_edits: Option<u8>,
    mirror: bool,
) -> Result<ActionEntry> {
    let read: Vec<Example> = logs.iter().map(Example::read).collect();
    let mut spans: Vec<_> = logs
        .iter()
        .zip(&read)
        .map(|(log, e)| {
            e.span
                .map(|(t0, t1)| dtw::normalised_span(log, t0 - 0.05, t1 + 0.05))
                .unwrap_or_default()
        })
        .collect();
    let mut seqs: Vec<Tokenized> = read.iter().map(|e| intent_of(&e.runs)).collect();
    if mirror {
        // Bring every example to one side, so a left and a right performance average and
        // align as the same gesture (the mirror is added back below).
        for (i, flip) in to_one_side(&seqs).into_iter().enumerate() {
            if flip {
                seqs[i] = mirror_seq(&seqs[i]);
                dtw::mirror_span(&mut spans[i]);
            }
        }
    }
    let avg = dtw::average(&spans);
    let mut all = vec![intent_symbols(&avg)];
    all.extend(seqs.iter().cloned());
    let re = if mirror {
        learn_regex_mirrored(&all)?
    } else {
        learn_regex(&all)?
    };
    let c = re.compile()?;
    let shapes: Vec<Shape> = read.iter().filter_map(|e| shape_of_runs(&e.runs)).collect();
    let examples: Vec<String> = read
        .iter()
        .map(|e| tokens_to_string(&tokens_only(&tokens_of(&e.runs))))
        .collect();
    let entry = ActionEntry::new(
        name,
        &re.to_source(),
        Some(max_edits.unwrap_or_else(|| default_edits(c.min_len()))),
        examples,
    )?
    .with_shape(mean_shape(&shapes))
    .with_shape_tolerance(shape_tolerance(&shapes))
    .with_extent(least_extent(read.iter().map(|e| &e.runs[..])))
    .with_hold(longest_hold(read.iter().map(|e| &e.runs[..])));
    Ok(entry)
}

/// Collision warnings between `entry` and the other actions of `lib`.
pub fn collisions(lib: &LibraryFile, entry: &ActionEntry) -> Result<Vec<String>> {
    let mut out = Vec::new();
    for other in lib.actions.iter().filter(|a| a.name != entry.name) {
        for ex in &entry.examples {
            let t = parse_tokens(ex)?;
            if let Some(d) = full_match(other, &t)? {
                out.push(format!(
                    "an example of `{}` ({ex}) is also matched by existing action `{}` \
                     (pattern `{}`, {} edits)",
                    entry.name,
                    other.name,
                    other.regex,
                    f32::from(d) / 2.0
                ));
                break;
            }
        }
        for ex in &other.examples {
            let t = parse_tokens(ex)?;
            if let Some(d) = full_match(entry, &t)? {
                out.push(format!(
                    "the new pattern of `{}` also matches an example of existing action `{}` \
                     ({ex}, {} edits)",
                    entry.name,
                    other.name,
                    f32::from(d) / 2.0
                ));
                break;
            }
        }
    }
    Ok(out)
}

/// `figurine learn`.
pub fn run(args: &LearnArgs) -> Result<()> {
    let mut lib = if args.library.exists() {
        LibraryFile::read(&args.library)?
    } else {
        LibraryFile::default()
    };
    let logs = args
        .examples
        .iter()
        .map(|p| PoseLog::read_path(p).map_err(anyhow::Error::from))
        .collect::<Result<Vec<_>>>()?;
    let entry = learn_action(&args.name, &logs, args.max_edits, !args.no_mirror)
        .with_context(|| format!("learning `{}`", args.name))?;
    for (p, ex) in args.examples.iter().zip(&entry.examples) {
        let t = parse_tokens(ex)?;
        let ok = full_match(&entry, &t)?;
        eprintln!(
            "  {}: {ex}  [{}]",
            p.display(),
            match ok {
                Some(d) => format!("matched, {} edits", f32::from(d) / 2.0),
                None => "NOT matched".into(),
            }
        );
    }
    for w in collisions(&lib, &entry)? {
        eprintln!("warning: {w}");
    }
    let shape = entry.shape.map_or(String::new(), |[l, u, f]| {
        format!(", moves left/up/front {l:.2}/{u:.2}/{f:.2} of its speed")
    });
    println!(
        "{}: {}  (max {} edits{shape})",
        entry.name, entry.regex, entry.max_edits
    );
    lib.upsert(entry);
    for step in super::separate::separate(&mut lib)? {
        eprintln!("{step}");
    }
    lib.write(&args.library)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::{self, Action, Knobs};
    use figurine_recognizer::token::parse_token;

    #[test]
    fn a_plain_stroke_that_tilted_slowly_is_learnt_as_its_wobble() {
        // Σ|ω| per axis in rad/s over 10 ms ticks: 15 → 0.15 rad about X.
        let mut acc = Accum::new();
        acc.sum[ANGVEL] = 15.0;
        acc.sum[ANGVEL + 2] = 3.0;
        let d = parse_token("d").unwrap();
        assert_eq!(slow_wobble_axis(&acc, d), Some(0));
        // Already a rotation token: the incidental-angle rule decides, not this one.
        assert_eq!(slow_wobble_axis(&acc, parse_token("d.Xp").unwrap()), None);
        // Tilting about two axes alike, or too little: no one wobble axis.
        acc.sum[ANGVEL + 2] = 12.0;
        assert_eq!(slow_wobble_axis(&acc, d), None);
        let mut small = Accum::new();
        small.sum[ANGVEL + 1] = 8.0;
        assert_eq!(slow_wobble_axis(&small, d), None);
        // The symbol is written as the plain stroke and its two wobbles about that axis.
        let sym = (d | ANY_ROT) | (1 << WOBBLE_SHIFT);
        let mut out = expand_symbol(sym);
        out.sort_unstable();
        let mut want: Vec<Symbol> = ["d", "d.Xn", "d.Xp"]
            .iter()
            .map(|n| parse_token(n).unwrap())
            .collect();
        want.sort_unstable();
        assert_eq!(out, want);
    }

    /// Three generated learning examples of `action` (seed `seed`).
    fn example_logs(action: Action, seed: u64) -> Vec<PoseLog> {
        synth::examples(seed, &Knobs::default(), action, 3, None)
            .into_iter()
            .map(|d| d.log)
            .collect()
    }

    #[test]
    fn a_walk_bobs_where_a_run_skims_and_a_sidestep_goes_sideways() {
        let shape = |action: Action, seed: u64| {
            mean_shape(&example_shapes(&example_logs(action, seed))).unwrap()
        };
        for seed in [1, 2, 3] {
            let (walk, run, side) = (
                shape(Action::Walk, seed),
                shape(Action::Run, seed),
                shape(Action::Sidestep, seed),
            );
            // Shares of the speed, left / up / front of the figurine, whatever its heading.
            assert!(walk[1] > run[1] + 0.15, "walk {walk:?} run {run:?}");
            assert!(run[2] > walk[2], "walk {walk:?} run {run:?}");
            assert!(
                side[0] > side[2] && side[0] > walk[0] + 0.3,
                "sidestep {side:?}"
            );
            for s in [walk, run, side] {
                assert!(s[..5].iter().all(|x| (0.0..=1.0).contains(x)), "{s:?}");
                assert!((-1.0..=1.0).contains(&s[5]), "{s:?}");
            }
        }
        // No motion, no shape.
        assert_eq!(mean_shape(&[]), None);
        assert_eq!(shape_tolerance(&[]), None);
    }

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
    fn a_jump_is_performed_above_where_it_began_and_a_crouch_below() {
        // Both are written `d u` often enough; the height (the last dimension) tells them
        // apart, whatever the doodle's size, place and heading. A gesture hardly louder than
        // its tracker's noise (a small, slow crouch under a noisy tracker) may not move at
        // all: the learner does without that example.
        let mut read = 0;
        for seed in [1, 2, 3, 4] {
            for log in example_logs(Action::Jump, seed) {
                if let Some(s) = motion_shape(&log) {
                    assert!(s[5] > 0.0, "jump {s:?}");
                    read += 1;
                }
            }
            for log in example_logs(Action::Crouch, seed) {
                if let Some(s) = motion_shape(&log) {
                    assert!(s[5] < -0.02, "crouch {s:?}");
                    read += 1;
                }
            }
        }
        assert!(read >= 22, "only {read} of 24 examples moved");
    }

    #[test]
    fn a_kick_flicked_flat_or_high_spreads_its_shape_more_than_a_walk() {
        // Up share (dimension 1), over a few example sets: a kick's flick rises 0.3–1.4× as
        // far as it goes forward, a walk's hops bob alike.
        let up = |action: Action, seed: u64| {
            shape_tolerance(&example_shapes(&example_logs(action, seed))).unwrap()[1]
        };
        let kick: f32 = (1..=4).map(|s| up(Action::Kick, s)).sum();
        let walk: f32 = (1..=4).map(|s| up(Action::Walk, s)).sum();
        assert!(kick > walk, "kick {kick} walk {walk}");
        // Each dimension on its own, weighted as the device weighs it, never below the floor.
        let shapes = [
            [0.1, 0.5, 0.8, 1.0, 0.2, 0.0],
            [0.1, 0.7, 0.6, 1.4, 0.2, 0.1],
        ];
        let tol = shape_tolerance(&shapes).unwrap();
        let want = [0.06, 0.1, 0.1, 0.1, 0.06, 0.15];
        for (got, want) in tol.iter().zip(want) {
            assert!((got - want).abs() < 1e-6, "{tol:?}");
        }
    }

    /// Whether `re` accepts the token string `tokens` (names separated by spaces) exactly.
    #[test]
    fn examples_to_the_other_side_are_mirrored_whatever_their_wobbles() {
        let seq = |names: &str| -> Tokenized {
            names
                .split_whitespace()
                .map(|n| {
                    let (name, wobble) = n.strip_suffix('~').map_or((n, false), |b| (b, true));
                    let t = parse_token(name).unwrap();
                    (if wobble { t | ANY_ROT } else { t }, 0.2)
                })
                .collect()
        };
        // A sidestep to the left (its hops learnt with roll wobbles), the median one to the
        // left with other marks, and one to the right in plain tokens: only the right one
        // turns, though no token of it equals one of the reference's.
        let seqs = [
            seq("lu.Zn ld~ lu~ ld~ l"),
            seq("lu~ ld.Zp lu.Zn ld~ lu"),
            seq("ru rd ru rd"),
        ];
        assert_eq!(to_one_side(&seqs), [false, false, true]);
        assert!(to_one_side(&[]).is_empty());
    }

    fn accepts(re: &Regex, tokens: &str) -> bool {
        re.compile()
            .unwrap()
            .accepts(&parse_tokens(tokens).unwrap())
    }

    fn seq(s: &str) -> Tokenized {
        s.split_whitespace()
            .map(|w| {
                let (name, dur) = w.split_once(':').unwrap();
                (parse_token(name).unwrap(), dur.parse().unwrap())
            })
            .collect()
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
    fn a_gesture_that_is_its_own_mirror_image_is_learnt_from_both_sides_at_once() {
        // Walks whose hops rock and roll one way and back: mirrored, they make the same
        // strokes, and two sides with every example's optional runs do not fit the device.
        let seqs = vec![
            seq("uf:0.2 f.Zp:0.1 df.XnZp:0.2 .Zn:0.05 uf:0.2 f.Zn:0.1 df.XnZn:0.2 .Zp:0.05 uf:0.2 df:0.2"),
            seq("uf.Zp:0.2 d.XnZp:0.05 df:0.2 u:0.05 uf:0.2 df.XpZp:0.2 .XnZn:0.05 uf:0.2 df.Zn:0.2"),
            seq("uf:0.2 .Zp:0.05 df.Zp:0.2 ub:0.05 uf.Zn:0.2 f:0.05 df:0.2 .XnZp:0.05 uf:0.2 df:0.2 d:0.05"),
        ];
        let mirrored: Vec<Tokenized> = seqs.iter().map(mirror_seq).collect();
        let sides = Regex::Alt(vec![
            learn_regex_within(&seqs, usize::MAX).unwrap(),
            learn_regex_within(&mirrored, usize::MAX).unwrap(),
        ]);
        assert!(sides.positions() > MAX_POSITIONS, "{}", sides.to_source());
        let re = learn_regex_mirrored(&seqs).unwrap();
        let c = re.compile().unwrap();
        for s in seqs.iter().chain(&mirrored) {
            let t = tokens_only(s);
            assert!(
                c.accepts(&t),
                "{} rejects {}",
                re.to_source(),
                tokens_to_string(&t)
            );
        }
    }

    #[test]
    fn a_performance_made_of_two_near_copies_makes_the_action_cyclic() {
        // Every example already holds two hops, each a little differently: no exact period,
        // and none is closer to the reference done twice — but each is two near-copies.
        let seqs = vec![
            seq("uf:0.3 df:0.3 f:0.3 uf:0.3 df:0.3"),
            seq("uf:0.3 df:0.3 uf:0.3 df:0.3 f:0.3"),
            seq("uf:0.3 f:0.3 df:0.3 uf:0.3 df:0.3"),
        ];
        let re = learn_regex(&seqs).unwrap();
        assert!(re.compile().unwrap().cyclic, "{}", re.to_source());
        // A back-and-forth stroke is no cycle: three runs cannot hold two copies.
        let seqs = vec![seq("b:0.3 f:0.3 b:0.3"), seq("b:0.3 f:0.3 b:0.3")];
        let re = learn_regex(&seqs).unwrap();
        assert!(!re.compile().unwrap().cyclic, "{}", re.to_source());
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

    /// `name` written as a wobble of either sign about its axes (a slow wobble, or any wobble
    /// of a cyclic action): `f.Zp` → `f~` about Z.
    fn wobble(name: &str) -> Symbol {
        let t = parse_token(name).unwrap();
        ((t / 27) * 27 + NONE_BIN) | ANY_ROT | wobble_axes(t)
    }

    /// `name` written as an incidental wobble seen turning its way (what [`intent_symbols`]
    /// makes of a run whose rotation half barely turned): `f.Zp` → `f~` about Z, seen `.Zp`.
    fn seen(name: &str) -> Symbol {
        let t = parse_token(name).unwrap();
        t | ANY_ROT | wobble_axes(t)
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
    fn a_wobble_is_written_as_the_plain_token_and_its_own_axis() {
        let names = |s: Symbol| -> Vec<String> {
            expand_symbol(s)
                .into_iter()
                .map(super::super::regex::symbol_name)
                .collect()
        };
        assert_eq!(names(wobble("f.Zp")), ["f", "f.Zn", "f.Zp"]);
        assert_eq!(names(wobble("db.Xn")), ["db", "db.Xn", "db.Xp"]);
        // About two axes: no axis to keep, the whole wildcard.
        assert_eq!(names(wobble("f.XpZn")), ["f~"]);
        assert_eq!(names(parse_token("f.Xn").unwrap()), ["f.Xn"]);
        // A mirror flips the wobble's sign, not its axis.
        let m = mirror_seq(&vec![(wobble("lu.Zp"), 0.1)]);
        assert_eq!(m[0].0, wobble("ru.Zp"));
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
    fn mirrored_patterns_accept_the_other_side() {
        let seqs = vec![seq("l:0.3 .Yp:0.3"), seq("l:0.3 .Yp:0.4")];
        let re = learn_regex_mirrored(&seqs).unwrap();
        let c = re.compile().unwrap();
        assert!(c.accepts(&tokens_only(&seq("l:1 .Yp:1"))));
        assert!(c.accepts(&tokens_only(&seq("r:1 .Yn:1"))));
        assert!(!c.accepts(&tokens_only(&seq("r:1 .Yp:1"))));
    }

    #[test]
    fn a_mirrored_pattern_too_big_for_both_sides_writes_rotations_as_wildcards() {
        let re = Regex::parse("(f.Zn|f|f.Zp)+ (b|d)* lu.Zn").unwrap();
        assert_eq!(compact_rotations(&re).to_source(), "f~+ (b|d)* lu.Zn");
        // Nine strokes, each rolling (and so written plain too, `lu.Zn|lu`): 18 positions a
        // side, too many for two.
        let a = "lu.Zn:0.2 ld.Zp:0.2 u.Zn:0.2 d.Zp:0.2 lb.Zn:0.2 lf.Zp:0.2 ub.Zn:0.2 \
                 df.Zp:0.2 l.Zn:0.2";
        let seqs = vec![seq(a), seq(a), seq(a)];
        assert!(learn_regex(&seqs).unwrap().positions() > MAX_POSITIONS / 2);
        let re = learn_regex_mirrored(&seqs).unwrap();
        assert!(re.to_source().contains("lu~"), "{}", re.to_source());
        let c = re.compile().unwrap();
        assert!(c.accepts(&tokens_only(&seqs[0])), "{}", re.to_source());
        assert!(
            c.accepts(&tokens_only(&mirror_seq(&seqs[0]))),
            "{}",
            re.to_source()
        );
    }

    #[test]
    fn identical_optional_sequences_become_mandatory() {
        let seqs = vec![seq("u:1 l:0.01 d:1"), seq("u:1 l:0.01 d:1")];
        assert_eq!(learn_regex(&seqs).unwrap().to_source(), "u+ l+ d+");
    }
}
