//! `figurine learn`, step 3: an example's token runs as pattern symbols — the strokes it meant,
//! not how it wobbled.
//!
//! A run whose rotation barely turned ([`INCIDENTAL_ANGLE_RAD`]) is a wobble, not part of the
//! gesture; so is a plain stroke that tilted a few degrees about one axis too slowly for a
//! rotation token (`slow_wobble_axis`). A wobble is kept as a symbol that remembers its axis
//! and the sign it was seen turning with, and a pattern column writes it as the plain stroke or
//! that wobble about the same axis (`f|f.Zn|f.Zp`, [`expand_symbol`]), so a punch that rolls
//! does not accept a kick's pitch. A run whose translation covered under
//! [`INCIDENTAL_PATH_SHARE`] of the gesture's path is incidental too.
//!
//! | symbol part | bits | meaning |
//! |---|---|---|
//! | token | 0–9 | translation half × 27 + rotation half ([`figurine_recognizer::token`]) |
//! | [`WOBBLE_AXES`] | 10–12 | the axes a wobble turned about |
//! | `ANY_ROT` / `ANY_LIN` | 14 / 15 | either half is a wildcard |

use figurine_recognizer::features::{Accum, ANGVEL, SPEED};
use figurine_recognizer::history::Run;
use figurine_recognizer::token::{
    mirror_token, symbol_matches, token_from_signs, token_signs, Symbol, Token, ANY_LIN, ANY_ROT,
    NONE_BIN, STILL,
};

use super::feed::log_gesture;
use crate::poselog::PoseLog;

/// One tokenized gesture: (token, duration in seconds) per run, STILL removed.
pub type Tokenized = Vec<(Token, f64)>;

/// A run's duration as the learner weighs it, seconds (one tick more than first to last).
pub(super) fn run_seconds(r: &Run) -> f64 {
    (r.end.1.saturating_sub(r.start.1)) as f64 * 1e-6 + 0.01
}

/// Rotation (rad) below which a run's rotation half is a wobble, not part of the gesture.
pub const INCIDENTAL_ANGLE_RAD: f64 = 0.35;

/// Share of the gesture's path length below which a run's translation half is incidental.
pub const INCIDENTAL_PATH_SHARE: f64 = 0.05;

/// A wobble symbol without the sign it was seen turning with (both signs about its axis).
pub(super) fn unsigned(s: Symbol) -> Symbol {
    if s & ANY_ROT != 0 && s & WOBBLE_AXES != 0 {
        plain(s) | (s & (ANY_ROT | WOBBLE_AXES))
    } else {
        s
    }
}

/// `s` without its learner-only marks: a rotation wildcard (`f~`) as the written pattern has
/// it, whatever wobble it was seen with.
pub(super) fn bare(s: Symbol) -> Symbol {
    unsigned(s) & !WOBBLE_AXES
}

/// The plain stroke of symbol `s`: its translation, no rotation, no marks.
pub(super) fn plain(s: Symbol) -> Symbol {
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
pub(super) const WOBBLE_SHIFT: u16 = 10;

/// The [`WOBBLE_AXES`] bits of the axes token `t` rotates about.
pub(super) fn wobble_axes(t: Token) -> Symbol {
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
pub(super) fn slow_wobble_axis(acc: &Accum, t: Token) -> Option<u16> {
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

/// Like [`super::learn::tokenize_gesture`], but each run is written as the symbol of what it means: a half
/// that barely moved (a rotation of less than [`INCIDENTAL_ANGLE_RAD`], a translation shorter
/// than [`INCIDENTAL_PATH_SHARE`] of the path) becomes a wildcard, so `d.Xp` with a 5° tilt is
/// learnt as `d~` about X, seen turning `.Xp` ([`WOBBLE_AXES`]). A one-shot action's pattern
/// then accepts `d` and `d.Xp`; a cyclic one's, which rocks each way in turn, `d.Xn` too.
pub fn intent_symbols(log: &PoseLog) -> Tokenized {
    intent_of(&log_gesture(log))
}

/// [`intent_symbols`] of a gesture's runs.
pub(super) fn intent_of(runs: &[Run]) -> Tokenized {
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

pub(super) fn mirror_seq(s: &Tokenized) -> Tokenized {
    // A mirror flips signs, not axes: the wobble axes stay.
    let flags = ANY_LIN | ANY_ROT | WOBBLE_AXES;
    s.iter()
        .map(|&(t, d)| (mirror_token(t & !flags) | (t & flags), d))
        .collect()
}

#[cfg(test)]
pub(crate) mod testing {
    //! Token strings for the learner's tests.
    use super::*;
    use crate::recognize::library::parse_tokens;
    use crate::recognize::regex::Regex;
    use figurine_recognizer::token::parse_token;

    /// Whether `re` accepts the token string `tokens` (names separated by spaces) exactly.
    pub(crate) fn accepts(re: &Regex, tokens: &str) -> bool {
        re.compile()
            .unwrap()
            .accepts(&parse_tokens(tokens).unwrap())
    }

    pub(crate) fn seq(s: &str) -> Tokenized {
        s.split_whitespace()
            .map(|w| {
                let (name, dur) = w.split_once(':').unwrap();
                (parse_token(name).unwrap(), dur.parse().unwrap())
            })
            .collect()
    }

    /// `name` written as a wobble of either sign about its axes (a slow wobble, or any wobble
    /// of a cyclic action): `f.Zp` → `f~` about Z.
    pub(crate) fn wobble(name: &str) -> Symbol {
        let t = parse_token(name).unwrap();
        ((t / 27) * 27 + NONE_BIN) | ANY_ROT | wobble_axes(t)
    }

    /// `name` written as an incidental wobble seen turning its way (what [`intent_symbols`]
    /// makes of a run whose rotation half barely turned): `f.Zp` → `f~` about Z, seen `.Zp`.
    pub(crate) fn seen(name: &str) -> Symbol {
        let t = parse_token(name).unwrap();
        t | ANY_ROT | wobble_axes(t)
    }
}

#[cfg(test)]
mod tests {
    use super::testing::wobble;
    use super::*;
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
}
