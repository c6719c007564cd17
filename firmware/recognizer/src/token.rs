//! Stage 3 — motion tokens: 27 translation bins × 27 rotation bins, plus STILL.
//!
//! Each of the 3 linear and 3 angular object-frame velocity components gets a sign in
//! {−, 0, +}. A component counts only when it carries a real share of its vector's norm
//! (≥ [`DOM_ON`] to switch on, stays on down to [`DOM_OFF`]: hysteresis against flicker on bin
//! borders), so direction bins depend on the direction of motion only — not on its size or
//! speed. A whole vector (translation or rotation) counts only when it moves against the
//! sensor's noise as learnt from the stream ([`crate::noise`]; motion found only by its slow
//! mean takes its direction from that mean) and exceeds [`REL_ACTIVE`] ×
//! its own recent peak (decaying with time constant [`PEAK_TAU_S`]): thresholds are relative
//! to the tracker's noise and to the motion's own scale, and sensor noise during a pure turn
//! does not become translation (nor tremor during a slide rotation). Translation smaller than [`ARM_M`] × |ω| is what a figurine
//! held off its centre does when turning, and is ignored too. Neither active → STILL.
//!
//! A new token must persist [`MIN_TOKEN_US`] before it counts (flicker suppression); a shorter
//! blip is merged into the current run. Runs of one token are one symbol by construction.
//!
//! Names (used in regex sources): translation letters in x, y, z order — `l`/`r` (±X, left /
//! right), `u`/`d` (±Y, up / down), `f`/`b` (±Z, front / back) — then, if rotating, `.` and the
//! rotation axes as `Xp`/`Xn`, `Yp`/`Yn`, `Zp`/`Zn` (positive / negative rate about the local
//! axis). `uf` = up-and-forward; `.Yp` = turning left in place; `f.Zn` = forward while rolling;
//! `_` = STILL.

use core::fmt;

use crate::fmath;
use crate::frame::Kinematics;
use crate::intake::{TICK_S, TICK_US};
use crate::noise::{Motion, NoiseFloor};

/// A token code: `lin × 27 + ang` for motion, [`STILL`] for stillness.
pub type Token = u16;
/// The STILL token.
pub const STILL: Token = 729;
/// The half-turn marker (written `O`): a rotation that continues past [`ROT_CHUNK_RAD`] in one
/// direction about one axis goes on as a run of this token. It uses the one code of the 27×27
/// grid that motion never produces (both halves empty).
pub const TURN: Token = NONE_BIN * 27 + NONE_BIN;
/// Number of distinct token codes (27 × 27 + STILL).
pub const TOKEN_COUNT: u16 = 730;
/// The bin code meaning "no component" for one of the two halves.
pub const NONE_BIN: u16 = 13;

/// Component share of its vector norm needed to switch a sign on.
pub const DOM_ON: f32 = 0.55;
/// Component share below which an active sign switches off.
pub const DOM_OFF: f32 = 0.35;
/// Share of the recent peak below which a vector is inactive.
pub const REL_ACTIVE: f32 = 0.10;
/// Time constant of the decaying peak, seconds.
pub const PEAK_TAU_S: f32 = 1.0;
/// Lever arm (m): translation below `ARM_M × |ω|` during rotation is ignored.
pub const ARM_M: f32 = 0.1;
/// Minimum duration of a token, µs.
pub const MIN_TOKEN_US: u64 = 40_000;
/// Ticks (10 ms each) of motion after stillness within which some bin must be confirmed. A
/// quick stroke sweeps through bins faster than any one of them persists for [`MIN_TOKEN_US`]
/// (a sudden sidestep hop passes `u`, `ru`, `r`, `rd` within 15 ticks); without this rule its
/// ticks would all be merged into the STILL run before it and the gesture lost. After this
/// many ticks without STILL and without a confirmed bin, the bin seen most often among them
/// (the later one on a tie) opens the next run. Between two moving bins the rule does not
/// apply: there a blip merged into the run before it keeps the gesture. Also the capacity of
/// the tokenizer's record of those ticks (2 bytes each).
pub const SWEEP_TICKS: usize = 8;
/// Rotation angle (rad, ≈ 229°) about one axis, in one direction, after which the current run
/// starts again as a new run of the same token: the string then tells a spin from a turn,
/// while angles — unlike distances — do not depend on the doodle's size.
pub const ROT_CHUNK_RAD: f32 = 4.0;

/// Per-tick decay of the peak trackers (first-order: 1 − dt/τ).
const PEAK_DECAY: f32 = 1.0 - TICK_S / PEAK_TAU_S;

/// Builds a token from sign triples (each component −1, 0 or +1); both zero gives STILL.
pub fn token_from_signs(lin: [i8; 3], ang: [i8; 3]) -> Token {
    let code = |s: [i8; 3]| -> u16 {
        let d = |v: i8| (v.signum() + 1) as u16;
        d(s[0]) + 3 * d(s[1]) + 9 * d(s[2])
    };
    let (l, a) = (code(lin), code(ang));
    if l == NONE_BIN && a == NONE_BIN {
        STILL
    } else {
        l * 27 + a
    }
}

/// The sign triples of a token (STILL gives all zeros; out-of-range codes too).
pub fn token_signs(t: Token) -> ([i8; 3], [i8; 3]) {
    if t >= STILL {
        return ([0; 3], [0; 3]);
    }
    let split = |c: u16| -> [i8; 3] {
        [
            (c % 3) as i8 - 1,
            ((c / 3) % 3) as i8 - 1,
            ((c / 9) % 3) as i8 - 1,
        ]
    };
    (split(t / 27), split(t % 27))
}

const LIN_LETTERS: [[u8; 2]; 3] = [[b'r', b'l'], [b'd', b'u'], [b'b', b'f']];
const ROT_AXES: [u8; 3] = [b'X', b'Y', b'Z'];

/// Writes a token's name (see the module docs).
pub fn write_token<W: fmt::Write>(t: Token, w: &mut W) -> fmt::Result {
    if t >= STILL {
        return w.write_char('_');
    }
    if t == TURN {
        return w.write_char('O');
    }
    let (lin, ang) = token_signs(t);
    for (i, &s) in lin.iter().enumerate() {
        if s != 0 {
            w.write_char(LIN_LETTERS[i][usize::from(s > 0)] as char)?;
        }
    }
    if ang.iter().any(|&s| s != 0) {
        w.write_char('.')?;
        for (i, &s) in ang.iter().enumerate() {
            if s != 0 {
                w.write_char(ROT_AXES[i] as char)?;
                w.write_char(if s > 0 { 'p' } else { 'n' })?;
            }
        }
    }
    Ok(())
}

/// Pattern-symbol flag: any rotation half (written `uf~`).
pub const ANY_ROT: u16 = 1 << 14;
/// Pattern-symbol flag: any translation half (written `~.Yp`).
pub const ANY_LIN: u16 = 1 << 15;

/// A pattern symbol: a token code, possibly with one wildcard half ([`ANY_ROT`] with the
/// rotation half empty, or [`ANY_LIN`] with the translation half empty).
pub type Symbol = u16;

/// Whether a pattern symbol is well formed.
pub fn symbol_valid(s: Symbol) -> bool {
    let code = s & 0x3ff;
    if code >= STILL {
        return false;
    }
    match s & (ANY_ROT | ANY_LIN) {
        0 => s == code,
        _ if code == TURN => false,
        ANY_ROT => code % 27 == NONE_BIN,
        ANY_LIN => code / 27 == NONE_BIN,
        _ => false,
    }
}

/// Whether token `t` matches pattern symbol `s`.
#[inline]
pub fn symbol_matches(s: Symbol, t: Token) -> bool {
    if t >= STILL {
        return false;
    }
    let code = s & 0x3ff;
    if s & ANY_ROT != 0 {
        code / 27 == t / 27
    } else if s & ANY_LIN != 0 {
        code % 27 == t % 27
    } else {
        code == t
    }
}

/// Mirror image of a token under the left–right reflection of the figurine (x → −x):
/// translation x flips; angular velocity, a pseudovector, keeps x and flips y and z.
pub fn mirror_token(t: Token) -> Token {
    if t >= STILL || t == TURN {
        return t;
    }
    let (l, a) = token_signs(t);
    token_from_signs([-l[0], l[1], l[2]], [a[0], -a[1], -a[2]])
}

/// Writes a pattern symbol (a token name, `uf~` or `~.Yp`).
pub fn write_symbol<W: fmt::Write>(s: Symbol, w: &mut W) -> fmt::Result {
    if s & ANY_LIN != 0 {
        w.write_char('~')?;
    }
    write_token(s & 0x3ff, w)?;
    if s & ANY_ROT != 0 {
        w.write_char('~')?;
    }
    Ok(())
}

/// Parses a pattern symbol; `None` if malformed.
pub fn parse_symbol(name: &str) -> Option<Symbol> {
    if let Some(rest) = name.strip_suffix('~') {
        let t = parse_token(rest)?;
        let s = t | ANY_ROT;
        return symbol_valid(s).then_some(s);
    }
    if let Some(rest) = name.strip_prefix('~') {
        let t = parse_token(rest)?;
        let s = t | ANY_LIN;
        return symbol_valid(s).then_some(s);
    }
    parse_token(name).filter(|&t| t != STILL)
}

/// A token as a `Display` value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TokenName(pub Token);

impl fmt::Display for TokenName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_token(self.0, f)
    }
}

/// Parses a token name; `None` for anything that is not a canonical-order name.
pub fn parse_token(s: &str) -> Option<Token> {
    if s == "_" {
        return Some(STILL);
    }
    if s == "O" {
        return Some(TURN);
    }
    let b = s.as_bytes();
    let mut lin = [0i8; 3];
    let mut ang = [0i8; 3];
    let mut i = 0;
    let mut axis = 0;
    while i < b.len() && b[i] != b'.' {
        let c = b[i];
        let mut found = false;
        while axis < 3 {
            let letters = LIN_LETTERS[axis];
            axis += 1;
            if c == letters[0] || c == letters[1] {
                lin[axis - 1] = if c == letters[1] { 1 } else { -1 };
                found = true;
                break;
            }
        }
        if !found {
            return None;
        }
        i += 1;
    }
    if i < b.len() {
        i += 1; // '.'
        let mut axis = 0;
        let start = i;
        while i < b.len() {
            let (c, sgn) = (b[i], *b.get(i + 1)?);
            let mut found = false;
            while axis < 3 {
                axis += 1;
                if c == ROT_AXES[axis - 1] {
                    ang[axis - 1] = match sgn {
                        b'p' => 1,
                        b'n' => -1,
                        _ => return None,
                    };
                    found = true;
                    break;
                }
            }
            if !found {
                return None;
            }
            i += 2;
        }
        if i == start {
            return None;
        }
    }
    let t = token_from_signs(lin, ang);
    (t != STILL).then_some(t)
}

/// What the tokenizer did with one tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TokenStep {
    /// The tick extends the current run (or there is no run yet).
    Run,
    /// The tick is part of a candidate that has not yet persisted long enough.
    Candidate,
    /// A candidate was confirmed as a new token: the candidate's ticks and this one form the
    /// new run (for the very first tick there are no candidate ticks).
    NewToken {
        /// The new token.
        token: Token,
    },
    /// A candidate blip was dropped: its ticks belong to the current run. If `starts_candidate`
    /// this tick starts a new candidate, otherwise it belongs to the current run too.
    BlipMerged {
        /// Whether this tick begins a new candidate.
        starts_candidate: bool,
    },
}

/// Streaming tokenizer with scale-relative thresholds and flicker suppression.
#[derive(Debug, Clone)]
pub struct Tokenizer {
    v_peak: f32,
    w_peak: f32,
    lin: [i8; 3],
    ang: [i8; 3],
    current: Option<Token>,
    candidate: Option<(Token, u64)>,
    turned: [f32; 3],
    /// Raw tokens of the moving ticks since the current STILL run was last seen (the first
    /// `swept`; recorded only while the current run is STILL).
    sweep: [Token; SWEEP_TICKS],
    swept: usize,
    floor: NoiseFloor,
}

impl Default for Tokenizer {
    fn default() -> Self {
        Self::new()
    }
}

fn signs(v: [f32; 3], active: bool, prev: [i8; 3]) -> [i8; 3] {
    let mut out = [0i8; 3];
    if !active {
        return out;
    }
    let n = fmath::norm3(v);
    if n <= 0.0 {
        return out;
    }
    for i in 0..3 {
        let share = v[i] / n;
        let s = if share > 0.0 { 1 } else { -1 };
        let thr = if prev[i] == s { DOM_OFF } else { DOM_ON };
        if fmath::abs(share) >= thr {
            out[i] = s;
        }
    }
    out
}

impl Tokenizer {
    /// A fresh tokenizer (no current token).
    pub const fn new() -> Self {
        Tokenizer {
            v_peak: 0.0,
            w_peak: 0.0,
            lin: [0; 3],
            ang: [0; 3],
            current: None,
            candidate: None,
            turned: [0.0; 3],
            sweep: [STILL; SWEEP_TICKS],
            swept: 0,
            floor: NoiseFloor::new(),
        }
    }

    /// A fresh tokenizer that keeps the noise floor learnt so far (after a tracker gap the
    /// tracker is still the same).
    pub fn restart(&mut self) {
        *self = Tokenizer {
            floor: self.floor,
            ..Tokenizer::new()
        };
    }

    /// The token seen most often among the swept ticks (the later one on a tie).
    fn sweep_mode(&self) -> Option<Token> {
        let seen = self.sweep.get(..self.swept)?;
        let mut best: Option<(Token, usize)> = None;
        for (i, &t) in seen.iter().enumerate() {
            let n = seen.iter().filter(|&&u| u == t).count();
            let later = seen.get(i + 1..).is_some_and(|rest| rest.contains(&t));
            if !later && best.is_none_or(|(_, m)| n >= m) {
                best = Some((t, n));
            }
        }
        best.map(|(t, _)| t)
    }

    /// The instantaneous (unsuppressed) token of a tick; updates the peak trackers.
    pub fn raw_token(&mut self, k: &Kinematics) -> Token {
        let vn = fmath::norm3(k.v);
        let wn = fmath::norm3(k.w);
        self.v_peak = fmath::max(vn, self.v_peak * PEAK_DECAY);
        self.w_peak = fmath::max(wn, self.w_peak * PEAK_DECAY);
        // A rotation keeps the norm: the object-frame speed is the world speed.
        self.floor.push(k.world_v, vn, k.v, k.w, wn);
        let (slow_v, slow_w) = self.floor.slow();
        let (v, v_norm) = match self.floor.translating(k.world_v, vn, self.lin != [0; 3]) {
            Motion::Still => ([0.0; 3], 0.0),
            Motion::Fast => (k.v, vn),
            Motion::Slow => (slow_v, fmath::norm3(slow_v)),
        };
        let (w, w_norm) = match self.floor.rotating(k.w, wn, self.ang != [0; 3]) {
            Motion::Still => ([0.0; 3], 0.0),
            Motion::Fast => (k.w, wn),
            Motion::Slow => (slow_w, fmath::norm3(slow_w)),
        };
        let v_on = v_norm > 0.0 && v_norm >= REL_ACTIVE * self.v_peak && v_norm >= ARM_M * wn;
        let w_on = w_norm > 0.0 && w_norm >= REL_ACTIVE * self.w_peak;
        self.lin = signs(v, v_on, self.lin);
        self.ang = signs(w, w_on, self.ang);
        token_from_signs(self.lin, self.ang)
    }

    /// Whether tick `k` (already stepped) is quiet: the figurine at rest within the noise
    /// ([`NoiseFloor::quiet`]).
    pub fn quiet(&self, k: &Kinematics) -> bool {
        self.floor.quiet(k.world_v, k.w)
    }

    /// The learnt noise rms of translation (m/s) and rotation (rad/s).
    pub fn noise_rms(&self) -> (f32, f32) {
        self.floor.rms()
    }

    /// The token of the current run, if any.
    pub fn current(&self) -> Option<Token> {
        self.current
    }

    /// Feeds one tick.
    pub fn step(&mut self, k: &Kinematics) -> TokenStep {
        let raw = self.raw_token(k);
        let now = k.tick.t_us;
        let Some(cur) = self.current else {
            self.current = Some(raw);
            return TokenStep::NewToken { token: raw };
        };
        // Angle turned about each axis while its sign stays the same, across token changes.
        let mut chunk = false;
        for i in 0..3 {
            if self.ang[i] == 0
                || (self.turned[i] != 0.0 && (self.turned[i] > 0.0) != (self.ang[i] > 0))
            {
                self.turned[i] = 0.0;
            }
            if self.ang[i] != 0 {
                self.turned[i] += k.w[i] * TICK_S;
                if fmath::abs(self.turned[i]) >= ROT_CHUNK_RAD {
                    self.turned[i] = 0.0;
                    chunk = true;
                }
            }
        }
        if raw == cur {
            self.swept = 0;
            if chunk && self.candidate.is_none() && raw != STILL {
                // A marker run opens; `current` stays the rotating token, so the marker run
                // lasts while the rotation does (see `TURN`).
                return TokenStep::NewToken { token: TURN };
            }
            return if self.candidate.take().is_some() {
                TokenStep::BlipMerged {
                    starts_candidate: false,
                }
            } else {
                TokenStep::Run
            };
        }
        if cur == STILL {
            if let Some(slot) = self.sweep.get_mut(self.swept) {
                *slot = raw;
                self.swept += 1;
            }
        }
        if self.swept >= SWEEP_TICKS {
            if let Some(token) = self.sweep_mode() {
                self.current = Some(token);
                self.candidate = None;
                self.swept = 0;
                return TokenStep::NewToken { token };
            }
        }
        match self.candidate {
            Some((c, since)) if c == raw => {
                // Confirm once the candidate spans MIN_TOKEN_US (counting this tick's period).
                if now + TICK_US - since >= MIN_TOKEN_US {
                    self.current = Some(raw);
                    self.candidate = None;
                    self.swept = 0;
                    TokenStep::NewToken { token: raw }
                } else {
                    TokenStep::Candidate
                }
            }
            Some(_) => {
                // A different candidate: the old blip goes to the current run, a new one starts.
                self.candidate = Some((raw, now));
                TokenStep::BlipMerged {
                    starts_candidate: true,
                }
            }
            None => {
                self.candidate = Some((raw, now));
                TokenStep::Candidate
            }
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::string::{String, ToString};

    #[test]
    fn names_round_trip_for_every_token() {
        for t in 0..TOKEN_COUNT {
            let mut s = String::new();
            write_token(t, &mut s).unwrap();
            assert_eq!(parse_token(&s), Some(t), "{t} {s}");
        }
        assert_eq!(parse_token("uf"), Some(token_from_signs([0, 1, 1], [0; 3])));
        assert_eq!(
            parse_token(".Yp"),
            Some(token_from_signs([0; 3], [0, 1, 0]))
        );
        for bad in ["", "fu", "uu", "x", ".", ".Yq", ".Y", "u.", "u.YpXp"] {
            assert_eq!(parse_token(bad), None, "{bad}");
        }
    }

    fn kin(t_us: u64, v: [f32; 3], w: [f32; 3]) -> Kinematics {
        let tick = crate::intake::Tick {
            t_us,
            pos: [0.0; 3],
            quat: [1.0, 0.0, 0.0, 0.0],
            seq: 0,
            sample_t_us: t_us,
        };
        Kinematics {
            tick,
            v,
            a: [0.0; 3],
            j: [0.0; 3],
            w,
            wa: [0.0; 3],
            wj: [0.0; 3],
            world_v: v,
            world_a: [0.0; 3],
            world_j: [0.0; 3],
        }
    }

    /// A tokenizer that has watched a clean tracker at rest for the stream's first noise
    /// block, and the time of its next tick.
    fn primed() -> (Tokenizer, u64) {
        let mut tk = Tokenizer::new();
        let mut t = 0;
        for _ in 0..crate::noise::BLOCK_TICKS {
            tk.step(&kin(t, [0.0; 3], [0.0; 3]));
            t += TICK_US;
        }
        (tk, t)
    }

    #[test]
    fn nothing_moves_while_the_sensor_is_being_learnt() {
        let mut tk = Tokenizer::new();
        let t = tk.raw_token(&kin(0, [0.0, 1.0, 1.0], [0.0; 3]));
        assert_eq!(t, STILL);
        let (mut tk, t0) = primed();
        let t = tk.raw_token(&kin(t0, [0.0, 1.0, 1.0], [0.0; 3]));
        assert_eq!(TokenName(t).to_string(), "uf");
    }

    #[test]
    fn direction_not_size_decides_the_bin() {
        for scale in [0.1f32, 1.0, 10.0] {
            let (mut tk, t0) = primed();
            let t = tk.raw_token(&kin(t0, [0.0, 0.7 * scale, 0.7 * scale], [0.0; 3]));
            assert_eq!(TokenName(t).to_string(), "uf");
        }
        let (mut tk, t0) = primed();
        // Noise-level rotation during a slide is not a rotation token.
        let t = tk.raw_token(&kin(t0, [0.0, 0.0, 0.5], [0.1, 0.2, 0.0]));
        assert_eq!(TokenName(t).to_string(), "f");
        // Tiny translation during a fast turn is not a translation token.
        let t = tk.raw_token(&kin(t0 + 10_000, [0.05, 0.0, 0.0], [0.0, 4.0, 0.0]));
        assert_eq!(TokenName(t).to_string(), ".Yp");
        let t = tk.raw_token(&kin(t0 + 20_000, [0.001, 0.0, 0.0], [0.0, 0.01, 0.0]));
        assert_eq!(t, STILL);
    }

    #[test]
    fn short_blips_are_suppressed() {
        let (mut tk, mut t) = primed();
        let up = [0.0, 1.0, 0.0];
        let fwd = [0.0, 0.0, 1.0];
        let mut feed = |tk: &mut Tokenizer, v, n: u64| {
            let mut out = std::vec::Vec::new();
            for _ in 0..n {
                out.push(tk.step(&kin(t, v, [0.0; 3])));
                t += TICK_US;
            }
            out
        };
        assert_eq!(
            feed(&mut tk, up, 5)[3],
            TokenStep::NewToken {
                token: parse_token("u").unwrap()
            }
        );
        let blip = feed(&mut tk, fwd, 2);
        assert_eq!(blip, [TokenStep::Candidate, TokenStep::Candidate]);
        assert_eq!(
            feed(&mut tk, up, 1),
            [TokenStep::BlipMerged {
                starts_candidate: false
            }]
        );
        let steps = feed(&mut tk, fwd, 5);
        assert_eq!(
            steps[3],
            TokenStep::NewToken {
                token: parse_token("f").unwrap()
            }
        );
        assert_eq!(tk.current(), parse_token("f"));
    }

    #[test]
    fn a_quick_sweep_after_stillness_is_not_lost() {
        let (mut tk, mut t) = primed();
        let mut feed = |tk: &mut Tokenizer, v: [f32; 3], n: u64| {
            let mut out = std::vec::Vec::new();
            for _ in 0..n {
                out.push(tk.step(&kin(t, v, [0.0; 3])));
                t += TICK_US;
            }
            out
        };
        feed(&mut tk, [0.0; 3], 5);
        assert_eq!(tk.current(), Some(STILL));
        // Up, up-right, right, down-right: no bin lasts MIN_TOKEN_US.
        let (u, ru, r, rd) = (
            [0.0, 1.0, 0.0],
            [-0.7, 0.7, 0.0],
            [-1.0, 0.0, 0.0],
            [-0.7, -0.7, 0.0],
        );
        let mut steps = feed(&mut tk, u, 3);
        steps.extend(feed(&mut tk, ru, 2));
        steps.extend(feed(&mut tk, r, 3));
        assert_eq!(
            steps.last(),
            Some(&TokenStep::NewToken {
                token: parse_token("r").unwrap()
            }),
            "{steps:?}"
        );
        // Before the rule fires nothing was confirmed, and afterwards a blip merges as usual.
        assert!(steps[..7]
            .iter()
            .all(|s| !matches!(s, TokenStep::NewToken { .. })));
        feed(&mut tk, rd, 2);
        assert_eq!(
            feed(&mut tk, r, 1),
            [TokenStep::BlipMerged {
                starts_candidate: false
            }]
        );
        assert_eq!(tk.current(), parse_token("r"));
    }
}
