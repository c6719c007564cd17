//! Stage 6c — how far a gesture went: what tells an action from a fidget.
//!
//! A hand holding the figurine still fidgets: it shifts it a few millimetres, tilts it a few
//! degrees and back. Those strokes can spell an action's tokens as well as a performance does
//! (a yaw there and back is written as a turn is), and their shape can be the action's too.
//! What they never do is go as far as the action's examples went. So each action learns, from
//! its examples, how far the least of them went (an [`Extent`]), and an event is reported only
//! when its motion phrase went at least a share of that — [`ACCEPT_SHARE`] of a displacement,
//! [`TURN_ACCEPT_SHARE`] of a rotation — in a dimension that carries
//! the action ([`far_enough`]), and farther than a fidget goes ([`FIDGET_MOVED_M`],
//! [`FIDGET_TURNED_RAD`]): a tabletop player's examples of a few centimetres would otherwise
//! admit a share smaller than the fidget itself. Seen through a noisy tracker a fidget seems
//! to go farther — its farthest point is read from noisy poses — so the fidget's reach grows
//! with the noise the front end learnt at rest ([`noise_reach`]).
//!
//! | measure | what | units |
//! |---|---|---|
//! | [`Extent::moved_m`] | farthest world displacement from where the phrase began | m |
//! | [`Extent::turned_rad`] | farthest rotation from where it rested before it began (\|Σ ω·dt\| about the object's axes) | rad |
//! | [`Extent::travel_m`] | how far from where it began it ended, across the floor | m |
//! | [`Extent::travel_share`] | learnt: the least share of its own reach that an example ended away | 0–1 |
//! | carries | a dimension whose least extent, rotation weighed by [`ARM_M`], is at least [`CARRY_SHARE`] of the other's | — |
//!
//! An action whose every example travelled — a jump lands ahead of where it took off, a walk
//! ends elsewhere — is held to its travel too, as to a dimension that carries it: a toy lifted
//! and set back down where it was goes up and down as a jump does, but goes nowhere. And an
//! action whose every example went somewhere — ended [`AWAY_SHARE`] of its own reach away or
//! more (its learnt travel share) — is reported only for motion that went somewhere too, give
//! or take a fidget: a share does not depend on the gesture's size, so a lift that comes down
//! a few centimetres off the spot is still no jump, even for a library whose least jump landed
//! only that far ahead (a drifting tracker's).
//!
//! The two shares differ because a doodle's size scales how far it moves, not how far it
//! turns: a displacement's share must span the player's scale (the generator draws examples
//! and performances at 0.5–2 each, a factor of 4 between them) on top of effort and the
//! action's own range; a rotation's spans effort and range only. The widest the generator
//! draws is a bow's, 30–70° times √(0.6–1.45) for Weight: its least performance 0.27 of its
//! greatest example. And a rotation counts from where the figurine rested before the
//! gesture ([`ExtentSums::add_rest`]): a sustained, light bow turns slower than the rotation
//! floor for most of its way down, so its moving runs alone see only part of it.
//!
//! The farthest point, not the path: tracker noise lengthens a path without end, but moves
//! the figurine only as far as the noise's own size. It is read at the ends of token runs,
//! where strokes turn back. A dimension that does not carry the action tells nothing: the
//! few millimetres a turn's examples drifted say nothing about how far a turn goes.

use crate::features::{Accum, MOVED_UNIT_M, TURNED_UNIT_RAD};
use crate::fmath;
use crate::history::{History, Run};
use crate::token::ARM_M;

/// Least share of its action's learnt displacement an event must reach when displacement
/// carries the action. The project's generator draws the doodle scale of examples and
/// performances alike from 0.5–2; with three libraries learnt from it (seeds 11–13), its 216
/// test gestures went at least 0.18 of their action's least example, and every fidget of 90
/// minutes of hand rest that was read as an action went at most 0.11 (measured from the
/// logs' poses).
pub const ACCEPT_SHARE: f32 = 0.15;
/// Least share of its action's learnt rotation an event must reach when rotation carries the
/// action: a doodle's scale does not change how far it turns, so only effort and the action's
/// own range part a performance from its least example — at most 0.27 in the generator (a
/// light 30° bow against a strong 70° one). A hand that talks twists up to 50° between beats
/// (`figurine synth handling --kind talk`), a fifth of a turn's least example or more;
/// measured on the thirteen own sets of `figurine eval --pairs 10` (issue 26's note), this
/// share silences 613 of its 8,931 events and loses no gesture, where 0.3 loses 11.
pub const TURN_ACCEPT_SHARE: f32 = 0.25;
/// Displacement that is far enough for any action, m, however far its examples went: a hand
/// holding the figurine still shifts it by millimetres, never 2 cm, and a child who plays a
/// library learnt at arm's length on a tabletop goes a fraction of its examples. Rotation has
/// no such bound: a doodle's size scales how far it moves, not how far it turns (a quarter
/// turn is a quarter turn on a tabletop), and a webcam's tilt jitter at 1 m reaches 5–10°.
pub const ENOUGH_MOVED_M: f32 = 0.02;
/// Displacement that is never far enough for an action, m, whatever its examples: just beyond
/// the largest shift a hand's fidget makes (2–8 mm in `figurine synth rest`).
pub const FIDGET_MOVED_M: f32 = 0.010;
/// Rotation that is never far enough for an action, rad (about 6°): just beyond the largest
/// tilt a hand's fidget makes (1–5°).
pub const FIDGET_TURNED_RAD: f32 = 0.10;
/// How far the tracker's noise alone seems to take the figurine, per unit of its learnt
/// velocity noise rms (s): the farthest point of a phrase is read from the Savitzky–Golay
/// smoothed pose at its runs' ends, and white position noise that makes a velocity rms σᵥ
/// puts two such readings √2·σ apart with σ ≈ 0.026 s × σᵥ at 100–1000 Hz (0.036 s at
/// 30 Hz); the farthest of a few readings lies about 1.5–2 times that.
pub const NOISE_REACH_S: f32 = 0.05;
/// Least share of its own reach (farthest displacement) a gesture ends away across the floor
/// to have gone somewhere, an action's every example and each performance of it alike. The
/// project's generator at noise ×3, read from the logs' poses (first and last sample against
/// the farthest): a jump's examples 0.29–1.0 (60 of them), a lift set back down 0.01–0.23
/// (20); learnt by ten ×3 libraries, a punch's, crouch's, bow's or throw's least share
/// 0.01–0.19, a jump's 0.38–0.76.
pub const AWAY_SHARE: f32 = 0.25;
/// Share of the other dimension's least extent (rotation × [`ARM_M`]) a dimension must reach
/// to carry an action: a punch barely turns and a turn barely moves; a kick and a throw carry
/// both.
pub const CARRY_SHARE: f32 = 0.5;
/// The learnt extents' byte code ([`to_byte`]): steps per doubling (4.4 % a step).
const STEPS_PER_OCTAVE: f32 = 16.0;
/// Unit of the learnt moved extent's byte code, m (codes 1–255 span 0.1 mm – 6.3 m).
pub const MOVED_CODE_UNIT_M: f32 = 1.0e-4;
/// Unit of the learnt turned extent's byte code, rad (codes 1–255 span 1 mrad – 63 rad).
pub const TURNED_CODE_UNIT_RAD: f32 = 1.0e-3;

/// How far a span of motion went from where it began.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Extent {
    /// Farthest world displacement from the start, m.
    pub moved_m: f32,
    /// Farthest rotation from the start, rad.
    pub turned_rad: f32,
    /// Horizontal distance from the start to the end, m.
    pub travel_m: f32,
    /// Of a learnt extent, the least share of how far an example went that it travelled
    /// ([`Extent::travel_m`] over [`Extent::moved_m`], each example's own), 0–1; 0 when not
    /// learnt, and in a span's extent (where the two fields say it).
    pub travel_share: f32,
}

/// Running sums over consecutive runs ([`Accum::moved`], [`Accum::turned`]) and the farthest
/// point they reached.
#[derive(Debug, Clone, Copy, Default)]
pub struct ExtentSums {
    moved: [i32; 3],
    turned: [i32; 3],
    far: Extent,
}

impl ExtentSums {
    /// Nothing added: the start.
    pub const fn new() -> Self {
        ExtentSums {
            moved: [0; 3],
            turned: [0; 3],
            far: Extent {
                moved_m: 0.0,
                turned_rad: 0.0,
                travel_m: 0.0,
                travel_share: 0.0,
            },
        }
    }

    /// Adds the stillness the runs that follow began from: its rotation only. A still run keeps
    /// the motion of its blips, ticks that stood above the floor too briefly to make a token,
    /// and a turn or a bow begun slower than the rotation floor starts as such blips: how far
    /// it turned counts from where it rested. Its displacement is left out: counted too, a
    /// tabletop walk's slow last stride, 3 cm in blips after the walk, was read as a run of its
    /// own (validation, 2026-12-07), and displacement's share is small enough for blips to fill.
    pub fn add_rest(&mut self, acc: &Accum) {
        for k in 0..3 {
            self.turned[k] = self.turned[k].saturating_add(i32::from(acc.turned[k]));
        }
        let turned = fmath::norm3(self.turned.map(|x| x as f32)) * TURNED_UNIT_RAD;
        self.far.turned_rad = fmath::max(self.far.turned_rad, turned);
    }

    /// Adds the run after those added.
    pub fn add(&mut self, acc: &Accum) {
        for k in 0..3 {
            self.moved[k] = self.moved[k].saturating_add(i32::from(acc.moved[k]));
            self.turned[k] = self.turned[k].saturating_add(i32::from(acc.turned[k]));
        }
        let norm = |v: [i32; 3]| fmath::norm3(v.map(|x| x as f32));
        self.far.moved_m = fmath::max(self.far.moved_m, norm(self.moved) * MOVED_UNIT_M);
        self.far.turned_rad = fmath::max(self.far.turned_rad, norm(self.turned) * TURNED_UNIT_RAD);
    }

    /// How far the runs added went, and where they ended.
    pub fn extent(&self) -> Extent {
        let [x, _, z] = self.moved.map(|v| v as f32 * MOVED_UNIT_M);
        Extent {
            travel_m: fmath::sqrt(x * x + z * z),
            ..self.far
        }
    }
}

/// The extent of history runs `from..=to` (those still held).
pub fn span_extent(hist: &History, from: u32, to: u32) -> Extent {
    rested_extent(hist, None, from, to)
}

/// The extent of history runs `from..=to`, its rotation counted from the start of `rest`,
/// the still run they began from ([`ExtentSums::add_rest`]).
pub fn rested_extent(hist: &History, rest: Option<&Run>, from: u32, to: u32) -> Extent {
    let mut sums = ExtentSums::new();
    if let Some(r) = rest {
        sums.add_rest(&r.acc);
    }
    for r in hist.runs(from, to) {
        sums.add(&r.acc);
    }
    sums.extent()
}

/// How far the noise alone seems to take the figurine ([`NOISE_REACH_S`]), from the learnt
/// noise rms of translation (m/s) and rotation (rad/s).
pub fn noise_reach(rms: (f32, f32)) -> Extent {
    Extent {
        moved_m: NOISE_REACH_S * rms.0,
        turned_rad: NOISE_REACH_S * rms.1,
        travel_m: 0.0,
        travel_share: 0.0,
    }
}

/// Whether motion that went `went` went far enough to be an action whose least example went
/// `least`: at least [`ACCEPT_SHARE`] of a displacement (or [`ENOUGH_MOVED_M`] if less), or
/// [`TURN_ACCEPT_SHARE`] of a rotation, in a dimension that carries the action, and as far
/// across the floor when moving carries it and its examples travelled (at least
/// [`CARRY_SHARE`] of how far they moved, and farther than a fidget), and ends
/// [`AWAY_SHARE`] of its own reach away when each of its examples did
/// ([`Extent::travel_share`]). A fidget seen through a tracker's `noise` ([`noise_reach`])
/// reaches as far as the two together (in quadrature: they are independent).
pub fn far_enough(went: Extent, least: Extent, noise: Extent) -> bool {
    let moved = least.moved_m;
    let turned = ARM_M * least.turned_rad;
    let fidget_moved = fmath::norm3([FIDGET_MOVED_M, noise.moved_m, 0.0]);
    let need_moved = fmath::max(
        fmath::min(ACCEPT_SHARE * least.moved_m, ENOUGH_MOVED_M),
        fidget_moved,
    );
    let need_turned = fmath::max(
        TURN_ACCEPT_SHARE * least.turned_rad,
        fmath::norm3([FIDGET_TURNED_RAD, noise.turned_rad, 0.0]),
    );
    // Travel is part of moving: it carries an action that moving carries, when its examples
    // ended at least that share as far off as they went (a turn's grip swings the tracked
    // point aside, but the turn is carried by its rotation) and farther than a fidget.
    let travels = moved >= CARRY_SHARE * turned
        && least.travel_m >= CARRY_SHARE * moved
        && least.travel_m > FIDGET_MOVED_M;
    let need_travel = if travels {
        fmath::min(ACCEPT_SHARE * least.travel_m, ENOUGH_MOVED_M)
    } else {
        0.0
    };
    // And it went somewhere when each of its examples did: a jump that went 20 cm lands 5 cm
    // or more ahead, where a toy lifted 20 cm comes down within a fidget of where it rose.
    let ends_away = moved < CARRY_SHARE * turned
        || least.travel_share < AWAY_SHARE
        || went.travel_m + fidget_moved >= AWAY_SHARE * went.moved_m;
    went.travel_m >= need_travel && ends_away && reaches(went, least, need_moved, need_turned)
}

/// Whether a span that `went` so far reached the whole of the `least` extent an action's
/// examples went — not a share of it, as [`far_enough`] asks — in a dimension that carries
/// the action (at least [`CARRY_SHARE`] of the other's): what a match briefer than any
/// gesture must show to be one ([`crate::segment::MIN_ACTION_US`]).
pub fn went_as_far(went: Extent, least: Extent) -> bool {
    reaches(went, least, least.moved_m, least.turned_rad)
}

/// Whether `went` reached `need_moved` (m) or `need_turned` (rad) in a dimension that carries
/// an action whose examples went `least` at the least: one whose least extent, rotation
/// weighed by [`ARM_M`], is at least [`CARRY_SHARE`] of the other's.
fn reaches(went: Extent, least: Extent, need_moved: f32, need_turned: f32) -> bool {
    let moved = least.moved_m;
    let turned = ARM_M * least.turned_rad;
    (moved >= CARRY_SHARE * turned && went.moved_m >= need_moved)
        || (turned >= CARRY_SHARE * moved && went.turned_rad >= need_turned)
}

/// A learnt extent `x` (in the code's `unit`) as the library's byte: 1 + 16·log2(x / unit),
/// rounded, 1–255 (0 is "not learnt").
pub fn to_byte(x: f32, unit: f32) -> u8 {
    let code = 1.0 + STEPS_PER_OCTAVE * fmath::ln(x / unit) / core::f32::consts::LN_2;
    // The cast saturates, and maps NaN to 0: clamp to the codes that mean a value.
    (fmath::round(code) as u8).max(1)
}

/// The learnt extent (in `unit`s × unit) a library byte stands for; None for 0 (not learnt).
pub fn from_byte(b: u8, unit: f32) -> Option<f32> {
    (b != 0)
        .then(|| unit * fmath::exp(f32::from(b - 1) * core::f32::consts::LN_2 / STEPS_PER_OCTAVE))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::QUANTITIES;
    use crate::intake::TICK_S;
    use crate::token::parse_token;

    /// A noiseless tracker's reach.
    const QUIET: Extent = Extent {
        moved_m: 0.0,
        turned_rad: 0.0,
        travel_m: 0.0,
        travel_share: 0.0,
    };

    fn ext(moved_m: f32, turned_rad: f32) -> Extent {
        Extent {
            moved_m,
            turned_rad,
            travel_m: 0.0,
            travel_share: 0.0,
        }
    }

    /// A run of `ticks` ticks, each moving `t.0` m and turning `t.1` rad.
    fn run(ticks: u32, t: ([f32; 3], [f32; 3])) -> Accum {
        let mut acc = Accum::new();
        for _ in 0..ticks {
            acc.add(&[0.0; QUANTITIES], t.0[1]);
            acc.travel(t.0.map(|x| x / TICK_S), t.1.map(|x| x / TICK_S));
        }
        acc
    }

    fn moving(v: [f32; 3]) -> ([f32; 3], [f32; 3]) {
        (v, [0.0; 3])
    }

    #[test]
    fn the_extent_is_the_farthest_point_not_the_path() {
        // Out 20 cm forward, 10 cm up, back down and home: 20.6 cm the farthest, 60 cm of path.
        let mut s = ExtentSums::new();
        for t in [
            [0.0, 0.0, 0.01],
            [0.0, 0.005, 0.0],
            [0.0, -0.005, 0.0],
            [0.0, 0.0, -0.01],
        ] {
            s.add(&run(20, moving(t)));
        }
        let e = s.extent();
        assert!((e.moved_m - libm::hypotf(0.2, 0.1)).abs() < 1e-4, "{e:?}");
        assert_eq!(e.turned_rad, 0.0);
        // A yaw of 3 rad about the up axis, in one run, and back.
        let yaw = |w: f32| ([0.0; 3], [0.0, w, 0.0]);
        let mut s = ExtentSums::new();
        s.add(&run(100, yaw(0.03)));
        s.add(&run(100, yaw(-0.03)));
        assert!(
            (s.extent().turned_rad - 3.0).abs() < 1e-3,
            "{:?}",
            s.extent()
        );
        // Jitter of ±0.2 mm a tick goes nowhere, however long it lasts.
        let mut s = ExtentSums::new();
        for k in 0..100 {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            s.add(&run(1, moving([2e-4 * sign, 0.0, 0.0])));
        }
        assert!(s.extent().moved_m <= 2.5e-4, "{:?}", s.extent());
    }

    #[test]
    fn the_history_span_sums_its_runs() {
        let mut h = History::new();
        let f = parse_token("f").unwrap();
        let first = h.open(f, (0, 0), run(10, moving([0.0, 0.0, 0.01])));
        let last = h.open(f, (1, 100_000), run(10, moving([0.01, 0.0, 0.0])));
        let e = span_extent(&h, first, last);
        assert!((e.moved_m - libm::hypotf(0.1, 0.1)).abs() < 1e-4, "{e:?}");
        assert!((span_extent(&h, last, last).moved_m - 0.1).abs() < 1e-4);
    }

    #[test]
    fn as_far_is_the_whole_of_the_least_example_in_a_carrying_dimension() {
        let sidestep = ext(0.08, 0.1);
        let turn = ext(0.02, 1.6);
        let throw = ext(0.1, 0.8);
        // A sidestep flicked as far as its least example, or farther: as far.
        assert!(went_as_far(ext(0.08, 0.0), sidestep));
        assert!(went_as_far(ext(0.12, 0.0), sidestep));
        // Far enough for an event (a share of it), but not as far.
        assert!(far_enough(ext(0.03, 0.0), sidestep, QUIET));
        assert!(!went_as_far(ext(0.03, 0.0), sidestep));
        // A turn is carried by its rotation: a wrist's twist that moves 5 cm and turns 1 rad
        // is not as far as a turn whose least example turned 1.6; the whole of it is.
        assert!(!went_as_far(ext(0.05, 1.0), turn));
        assert!(went_as_far(ext(0.0, 1.6), turn));
        // A throw is carried by both: either reaching its least will do.
        assert!(went_as_far(ext(0.1, 0.2), throw));
        assert!(went_as_far(ext(0.02, 0.8), throw));
        assert!(!went_as_far(ext(0.09, 0.7), throw));
    }

    #[test]
    fn only_a_dimension_that_carries_the_action_admits_it() {
        let punch = ext(0.2, 0.05);
        let turn = ext(0.02, 1.6);
        let throw = ext(0.1, 0.8);
        let fidget = ext(0.008, 0.08);
        // A fidget moves more than a turn's examples drifted and turns more than a punch's:
        // neither dimension carries those actions, so it is neither.
        for least in [punch, turn, throw] {
            assert!(!far_enough(fidget, least, QUIET), "{least:?}");
        }
        // A small punch, a quick quarter turn, a throw that swung without reaching: all far
        // enough.
        let small_punch = ext(0.04, 0.0);
        assert!(far_enough(small_punch, punch, QUIET));
        let quarter = ext(0.0, 0.4);
        assert!(far_enough(quarter, turn, QUIET));
        let swing = ext(0.01, 0.2);
        assert!(far_enough(swing, throw, QUIET));
        // Examples that went nowhere admit anything that goes farther than a fidget.
        assert!(far_enough(ext(0.012, 0.0), Extent::default(), QUIET));
        assert!(!far_enough(Extent::default(), Extent::default(), QUIET));
    }

    #[test]
    fn a_small_doodle_moves_less_but_turns_as_far() {
        // A run learnt at arm's length (72 cm): a 3 cm tabletop run is far enough.
        let run = ext(0.72, 0.1);
        assert!(far_enough(ext(0.03, 0.0), run, QUIET));
        // A turn learnt at 136°: a 10° wobble there and back (a webcam's tilt jitter at 1 m)
        // is no turn, however small the doodle, nor a talking hand's 30° twist; a 40° turn is.
        let turn = ext(0.009, 2.37);
        assert!(!far_enough(ext(0.0, 0.17), turn, QUIET));
        assert!(!far_enough(ext(0.0, 0.52), turn, QUIET));
        assert!(far_enough(ext(0.0, 0.7), turn, QUIET));
        // A bow learnt at 43° admits a light 12° nod.
        let bow = ext(0.024, 0.75);
        assert!(far_enough(ext(0.0, 0.21), bow, QUIET));
    }

    #[test]
    fn rotation_counts_from_the_rest_before_and_displacement_from_the_first_motion() {
        // A still run whose brief flickers of motion, too short for a token, bowed 0.15 rad
        // and slid 3 cm; then the moving run, 0.1 rad on.
        let pitch = |w: f32, v: f32| ([0.0, 0.0, v], [w, 0.0, 0.0]);
        let rest = run(10, pitch(0.015, 0.003));
        let bowed = run(10, pitch(0.01, 0.0));
        let mut s = ExtentSums::new();
        s.add_rest(&rest);
        s.add(&bowed);
        let e = s.extent();
        assert!((e.turned_rad - 0.25).abs() < 1e-3, "{e:?}");
        assert_eq!((e.moved_m, e.travel_m), (0.0, 0.0), "{e:?}");
        // Against a bow whose least example turned 0.75 rad, a quarter is 0.19: the motion
        // counted from its first moving run falls short, counted from the rest it is a bow.
        let bow = ext(0.024, 0.75);
        let mut moving_only = ExtentSums::new();
        moving_only.add(&bowed);
        assert!(!far_enough(moving_only.extent(), bow, QUIET));
        assert!(far_enough(e, bow, QUIET));
        // The history's view: the still run before the span, as the recognizer passes it.
        let mut h = History::new();
        let first = h.open(crate::token::STILL, (0, 0), rest);
        let then = h.open(parse_token(".Xp").unwrap(), (10, 100_000), bowed);
        let held = h.get(first).copied();
        assert_eq!(rested_extent(&h, held.as_ref(), then, then), e);
        assert_eq!(span_extent(&h, then, then), moving_only.extent());
    }

    #[test]
    fn a_fidget_seen_through_a_noisy_tracker_must_go_farther() {
        // A tabletop punch (its least example 4 cm: 15 % of it is under a fidget's reach).
        let punch = ext(0.04, 0.0);
        // A small turn (its least example 0.35 rad: a quarter of it under a fidget's tilt).
        let turn = ext(0.0, 0.35);
        // A webcam-like tracker: 0.1 m/s and 0.3 rad/s of velocity noise at rest, which
        // alone seems to take the figurine 5 mm and 0.015 rad.
        let noisy = noise_reach((0.1, 0.3));
        assert!((noisy.moved_m - 0.005).abs() < 1e-6, "{noisy:?}");
        // A 10.5 mm shift clears the fidget's reach on a quiet tracker, not on this one
        // (√(10² + 5²) ≈ 11.2 mm); a 2 cm one clears both.
        assert!(far_enough(ext(0.0105, 0.0), punch, QUIET));
        assert!(!far_enough(ext(0.0105, 0.0), punch, noisy));
        assert!(far_enough(ext(0.02, 0.0), punch, noisy));
        // Alike in rotation: 0.105 rad against √(0.1² + 0.015²) ≈ 0.101 passes, 0.1005 fails.
        assert!(far_enough(ext(0.0, 0.105), turn, noisy));
        assert!(!far_enough(ext(0.0, 0.1005), turn, noisy));
        // The reach adds in quadrature: a quiet tracker's small noise barely moves the floor.
        assert!(far_enough(
            ext(0.01005, 0.0),
            punch,
            noise_reach((0.01, 0.03))
        ));
    }

    #[test]
    fn an_action_whose_examples_all_travelled_must_travel() {
        // A jump's least example: 25 cm from the start at the top, landing 15 cm ahead.
        let jump = Extent {
            travel_m: 0.15,
            ..ext(0.25, 0.2)
        };
        // A toy lifted 10 cm and set down where it was: as high, but nowhere.
        let lift = Extent {
            travel_m: 0.004,
            ..ext(0.1, 0.1)
        };
        assert!(!far_enough(lift, jump, QUIET));
        // A small jump that landed a few centimetres ahead is one.
        let small = Extent {
            travel_m: 0.03,
            ..ext(0.08, 0.05)
        };
        assert!(far_enough(small, jump, QUIET));
        // A crouch's examples came back where they started: its travel carries nothing.
        let crouch = Extent {
            travel_m: 0.01,
            ..ext(0.1, 0.1)
        };
        assert!(far_enough(lift, crouch, QUIET));
        // Nor does a turn's, carried by its rotation, though the grip swung it 5 cm aside.
        let turn = Extent {
            travel_m: 0.05,
            ..ext(0.05, 1.6)
        };
        assert!(far_enough(ext(0.0, 1.0), turn, QUIET));
    }

    #[test]
    fn an_action_whose_examples_went_somewhere_must_go_somewhere() {
        // A tabletop player's jumps: the least went 5 cm and landed 2.5 cm ahead, and each
        // landed at least 0.6 of its reach ahead.
        let jump = Extent {
            travel_m: 0.025,
            travel_share: 0.6,
            ..ext(0.05, 0.1)
        };
        // A toy lifted 20 cm and set down 1.5 cm off: past the jump's least travel, but not a
        // quarter of its own reach, even with a fidget's centimetre besides.
        let lift = Extent {
            travel_m: 0.015,
            ..ext(0.2, 0.1)
        };
        assert!(!far_enough(lift, jump, QUIET));
        assert!(far_enough(
            lift,
            Extent {
                travel_share: 0.0,
                ..jump
            },
            QUIET
        ));
        // A jump 6 cm high that landed 3 cm ahead is one; so is a high one, 40 cm up and
        // 17 cm ahead (0.43 of its reach, where each example landed most of its reach ahead).
        let hop = Extent {
            travel_m: 0.03,
            ..ext(0.06, 0.1)
        };
        assert!(far_enough(hop, jump, QUIET));
        let high = Extent {
            travel_m: 0.17,
            ..ext(0.4, 0.1)
        };
        let long = Extent {
            travel_share: 0.95,
            ..jump
        };
        assert!(far_enough(high, long, QUIET));
        // Examples that came back near where they began (a punch, a share of 0.1) ask for no
        // share; nor do those of an action its rotation carries (a turn's grip swings aside).
        let punch = Extent {
            travel_m: 0.01,
            travel_share: 0.1,
            ..ext(0.2, 0.1)
        };
        assert!(far_enough(lift, punch, QUIET));
        let turn = Extent {
            travel_m: 0.05,
            travel_share: 0.9,
            ..ext(0.05, 1.6)
        };
        assert!(far_enough(ext(0.0, 1.0), turn, QUIET));
    }

    #[test]
    fn the_travel_is_where_the_runs_ended_across_the_floor() {
        // Up 10 cm, 3 cm ahead, and down again: the farthest point 10.4 cm, the travel 3 cm.
        let mut s = ExtentSums::new();
        for t in [[0.0, 0.01, 0.003], [0.0, -0.01, 0.0]] {
            s.add(&run(10, moving(t)));
        }
        let e = s.extent();
        assert!((e.travel_m - 0.03).abs() < 1e-4, "{e:?}");
        assert!((e.moved_m - libm::hypotf(0.1, 0.03)).abs() < 1e-4, "{e:?}");
    }

    #[test]
    fn a_fidget_is_no_action_even_for_a_tabletop_players_library() {
        // Examples of 3 cm and 20°: a share of them is a few millimetres and degrees, which a
        // hand's fidget reaches; the fidget's own reach is the bound then.
        let small = ext(0.03, 0.0);
        assert!(ACCEPT_SHARE * small.moved_m < 0.008);
        assert!(!far_enough(ext(0.008, 0.0), small, QUIET));
        assert!(far_enough(ext(0.012, 0.0), small, QUIET));
        let small_turn = ext(0.0, 0.35);
        assert!(TURN_ACCEPT_SHARE * small_turn.turned_rad < FIDGET_TURNED_RAD);
        assert!(!far_enough(ext(0.0, 0.09), small_turn, QUIET));
        assert!(far_enough(ext(0.0, 0.12), small_turn, QUIET));
    }

    #[test]
    fn learnt_extents_round_trip_through_their_byte() {
        for x in [1.0e-4f32, 0.003, 0.05, 0.4, 2.0, 6.0] {
            let back = from_byte(to_byte(x, MOVED_CODE_UNIT_M), MOVED_CODE_UNIT_M).unwrap();
            assert!((back / x - 1.0).abs() < 0.025, "{x} → {back}");
        }
        // Below the unit, 0, negative or NaN: the least code; far above: the greatest.
        for x in [1e-6, 0.0, -1.0, f32::NAN] {
            assert_eq!(to_byte(x, TURNED_CODE_UNIT_RAD), 1, "{x}");
        }
        assert_eq!(to_byte(1e6, TURNED_CODE_UNIT_RAD), 255);
        assert_eq!(from_byte(0, TURNED_CODE_UNIT_RAD), None);
    }
}
