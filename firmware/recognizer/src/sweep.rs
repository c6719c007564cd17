//! Stages 3 and 6d — sub-movements: whether a motion was one sweep of the hand, or several pushes.
//!
//! A child who carries the toy to another spot moves it in one smooth sweep: from rest, the
//! speed rises once and falls once (a minimum-jerk reach), and the toy goes up and comes down
//! once. Its tokens can spell a sidestep or a run all the same. A performance is made of
//! several pushes: a walk's or a sidestep's steps, a kick's raise and strike, a throw's
//! wind-up and release. So the front end counts, per run, the sub-movements that began in it
//! ([`Sweeps`], in the run's spare bytes: [`crate::history::Run::sweeps`]), two ways:
//!
//! | count | one of them | what makes it |
//! |---|---|---|
//! | [`Sweeps::peaks`] | the speed, while moving, rises back to 1/[`PEAK_DROP`] of the least since the last peak fell to [`PEAK_DROP`] of itself | a push of the hand |
//! | [`Sweeps::bobs`] | the vertical speed rises above [`BOB_SHARE`] of the speed, then falls below −[`BOB_SHARE`] of it | a stride at a steady speed: a person's pelvis glides, but bobs twice a gait cycle |
//!
//! A motion's count is the more of the two ([`Sweeps::count`]). A rise or a dip counts only
//! when it also stands out of the tracker's learnt noise: for an action's examples, which set
//! what a performance must make, by [`LEARN_MARGIN`] × the noise rms, as far as motion itself
//! must; for a performance, by [`EVENT_MARGIN`] × the rms, the front end's quiet level, so that
//! a ripple the noise puts on a carry's one sweep is no second push. Each action learns the
//! fewest any of its examples made. The decision stage refuses a new event
//! when the motion around it, from rest to rest, was [`one_sweep`], its action's examples
//! each made [`MANY_SWEEPS`] or more, and its match cost at most [`SWEEP_COST`] (its pattern
//! as written, bar one near token): a match that needed an edit may have left out the very
//! parts that make sub-movements (a jump played as one arc, without its crouch). Only for an
//! action that moving carries ([`crate::extent`]): a turn is one sweep of the wrist; and only
//! for a motion long enough for several pushes to be told apart ([`RESOLVABLE_US`]).
//!
//! RAM: the counter's 8 B, a token candidate's counts included; a run's counts take two bytes
//! that were its padding.

use crate::extent::{Extent, CARRY_SHARE};
use crate::fmath;
use crate::history::{History, Sweeps, HISTORY_RUNS};
use crate::token::{ARM_M, STILL};

/// Share of a speed peak the speed must fall to for the peak to end, and of the least speed
/// since which it must rise back (as 1/share) for the next to begin: hysteresis, so that the
/// ripple of a steady motion is no new push.
pub const PEAK_DROP: f32 = 0.6;
/// Share of the speed the vertical speed must reach, up and then down, for a bob.
pub const BOB_SHARE: f32 = 0.15;
/// Rise or dip, in units of the learnt translation noise rms (m/s), that an example's
/// sub-movement must also make to count: as far out of the noise as the front end's own
/// hysteresis ([`crate::noise::ON_FACTOR`]) asks of motion.
pub const LEARN_MARGIN: f32 = 2.5;
/// Rise or dip, in units of the learnt translation noise rms (m/s), that a performance's
/// sub-movement must also make to count: the front end's quiet level
/// ([`crate::noise::QUIET_FACTOR`]), within which the figurine is at rest. Counted raw, the
/// noise's ripple on a carry made a second peak, and the carry read as an action whose
/// examples made several pushes.
pub const EVENT_MARGIN: f32 = crate::noise::QUIET_FACTOR;
/// Sub-movements every example of an action must have made for one sweep to be refused as
/// that action: an action whose examples made two may be played as one push and its settling.
pub const MANY_SWEEPS: u8 = 3;
/// Least time a motion takes, from rest to rest, for its one sweep to be refused, µs: the
/// time [`MANY_SWEEPS`] pushes need for the filter to tell them apart, a window
/// ([`crate::filter::SG_WINDOW`] ticks) each (330 ms). Briefer, a performance's pushes blur
/// into one (a run played small and sudden, 0.2 s across a tabletop).
pub const RESOLVABLE_US: u64 =
    MANY_SWEEPS as u64 * crate::filter::SG_WINDOW as u64 * crate::intake::TICK_US;
/// Most a match may cost, in half-edits ([`crate::alignment`]), for one sweep to be refused
/// as its action: its pattern as written, or with one near token.
pub const SWEEP_COST: u8 = crate::alignment::HALF;

/// Counts sub-movements tick by tick.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SweepCounter {
    /// Inside a speed peak (it has not yet fallen to [`PEAK_DROP`] of itself).
    in_peak: bool,
    /// A bob has risen and not yet fallen.
    risen: bool,
    /// Inside a peak, its highest speed; outside, the least speed since the last peak ended
    /// (m/s): only one of the two is ever needed, and the device's RAM is scarce.
    extreme: f32,
    /// Sub-movements of ticks whose run is not yet known (a token candidate's).
    deferred: Sweeps,
}

impl SweepCounter {
    /// Before any motion.
    pub const fn new() -> Self {
        SweepCounter {
            in_peak: false,
            risen: false,
            extreme: 0.0,
            deferred: Sweeps::NONE,
        }
    }

    /// Holds sub-movements `s` until the run their ticks belong to is known.
    pub fn defer(&mut self, s: Sweeps) {
        self.deferred.merge(s);
    }

    /// The sub-movements held by [`SweepCounter::defer`], which are no longer held.
    pub fn take_deferred(&mut self) -> Sweeps {
        core::mem::take(&mut self.deferred)
    }

    /// One tick of `speed` and vertical speed `up` (m/s, world +Y), while `moving` (not STILL)
    /// or not; a rise or dip must also exceed `margin()` (m/s) to count. Returns what began on
    /// this tick. The margin is asked for only when a rise or dip is otherwise enough (most
    /// ticks need none: the noise rms behind it costs a square root).
    pub fn step(&mut self, speed: f32, up: f32, moving: bool, margin: impl Fn() -> f32) -> Sweeps {
        let mut began = Sweeps::NONE;
        if self.in_peak {
            self.extreme = fmath::max(self.extreme, speed);
            if speed <= PEAK_DROP * self.extreme && self.extreme - speed >= margin() {
                self.in_peak = false;
                self.extreme = speed;
            }
        } else {
            self.extreme = fmath::min(self.extreme, speed);
            if moving && PEAK_DROP * speed >= self.extreme && speed - self.extreme >= margin() {
                self.in_peak = true;
                self.extreme = speed;
                began.peaks = 1;
            }
        }
        if moving {
            if up > BOB_SHARE * speed && up > margin() {
                self.risen = true;
            } else if -up > BOB_SHARE * speed && self.risen && -up > margin() {
                self.risen = false;
                began.bobs = 1;
            }
        }
        began
    }
}

/// Whether a new event over runs `from..=to` of `hist`, matched at `cost` half-edits, is a
/// toy carried rather than its action: the action's examples went `least` (moving carries it)
/// and each made at least `made` sub-movements, [`MANY_SWEEPS`] or more, where the motion
/// was [`one_sweep`].
pub fn carried(least: Extent, made: u8, cost: u8, hist: &History, from: u32, to: u32) -> bool {
    least.moved_m >= CARRY_SHARE * ARM_M * least.turned_rad
        && made >= MANY_SWEEPS
        && cost <= SWEEP_COST
        && one_sweep(hist, from, to)
}

/// Whether the motion of runs `from..=to` of `hist`, with the moving runs just before it back
/// to the last rest, made at most one sub-movement and came to rest after: one sweep, from
/// rest to rest. False when the run after `to` is not yet a STILL one (the motion goes on),
/// and when the motion was briefer than [`RESOLVABLE_US`].
pub fn one_sweep(hist: &History, from: u32, to: u32) -> bool {
    if hist
        .get(to.wrapping_add(1))
        .is_none_or(|r| r.token != STILL)
    {
        return false;
    }
    let mut made = Sweeps::NONE;
    let ended_us = hist.get(to).map_or(0, |r| r.end.1);
    let mut began_us = hist.get(from).map_or(0, |r| r.start.1);
    hist.runs(from, to).for_each(|r| made.merge(r.sweeps));
    let mut j = from;
    for _ in 0..HISTORY_RUNS {
        j = j.wrapping_sub(1);
        match hist.get(j) {
            Some(r) if r.token != STILL => {
                made.merge(r.sweeps);
                began_us = r.start.1;
            }
            _ => break,
        }
    }
    ended_us.saturating_sub(began_us) >= RESOLVABLE_US && made.count() <= 1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::Accum;
    use crate::history::Sweeps;

    /// Counts over `n` ticks of 10 ms of a velocity profile `v(t)` (t in s), moving while the
    /// speed is above the front end's floor.
    fn count(n: usize, margin: f32, v: impl Fn(f32) -> [f32; 3]) -> Sweeps {
        let mut c = SweepCounter::new();
        let mut made = Sweeps::NONE;
        for k in 0..n {
            let v = v(k as f32 * 0.01);
            let speed = fmath::norm3(v);
            made.merge(c.step(speed, v[1], speed > crate::noise::V_FLOOR_M_S, || margin));
        }
        made
    }

    /// Minimum-jerk speed profile of a reach of `d` m over `t1` s, at time t.
    fn min_jerk(d: f32, t1: f32, t: f32) -> f32 {
        let s = (t / t1).clamp(0.0, 1.0);
        d / t1 * 30.0 * s * s * (1.0 - s) * (1.0 - s)
    }

    #[test]
    fn a_carry_is_one_sweep() {
        // 30 cm across in 0.8 s, lifted 5 cm on the way and set down.
        let made = count(100, 0.0, |t| {
            let up = 0.05 * core::f32::consts::PI / 0.8
                * libm::sinf(2.0 * core::f32::consts::PI * t / 0.8);
            [min_jerk(0.3, 0.8, t), if t < 0.8 { up } else { 0.0 }, 0.0]
        });
        assert_eq!(made.peaks, 1);
        assert!(made.bobs <= 1);
        assert_eq!(made.count(), 1);
    }

    #[test]
    fn steps_are_several_pushes() {
        // Three strides of 0.4 s: the speed dips between them, the toy hops on each.
        let made = count(130, 0.0, |t| {
            let k = (t / 0.4) as i32;
            let local = t - k as f32 * 0.4;
            if k >= 3 {
                return [0.0; 3];
            }
            let hop = 0.5 * libm::sinf(2.0 * core::f32::consts::PI * local / 0.4);
            [min_jerk(0.1, 0.4, local), hop, 0.0]
        });
        assert_eq!(made.peaks, 3);
        assert_eq!(made.bobs, 3);
    }

    #[test]
    fn a_glide_that_bobs_counts_its_bobs() {
        // A steady 1 m/s with a 0.3 m/s vertical bob at 2 Hz: one speed peak, four bobs.
        let made = count(200, 0.0, |t| {
            [
                1.0,
                0.3 * libm::sinf(2.0 * core::f32::consts::PI * 2.0 * t),
                0.0,
            ]
        });
        assert_eq!(made.peaks, 1);
        assert_eq!(made.bobs, 4);
        assert_eq!(made.count(), 4);
    }

    #[test]
    fn a_margin_ignores_ripple_the_noise_could_make() {
        let ripple = |t: f32| {
            [
                0.3 + 0.2 * libm::sinf(2.0 * core::f32::consts::PI * 3.0 * t),
                0.0,
                0.0,
            ]
        };
        assert!(count(100, 0.0, ripple).peaks >= 3);
        assert_eq!(count(100, 0.5, ripple).peaks, 1);
    }

    #[test]
    fn still_ticks_begin_nothing() {
        let mut c = SweepCounter::new();
        for _ in 0..50 {
            assert_eq!(c.step(0.54, 0.2, false, || 0.0), Sweeps::NONE);
        }
    }

    #[test]
    fn counts_saturate() {
        let mut s = Sweeps {
            peaks: 250,
            bobs: 1,
        };
        s.merge(Sweeps { peaks: 10, bobs: 2 });
        assert_eq!(
            s,
            Sweeps {
                peaks: 255,
                bobs: 3
            }
        );
    }

    /// Runs of `run_ms` each, one after the other, with the speed peaks given.
    fn history(runs: &[(crate::token::Token, u8)], run_ms: u64) -> History {
        let mut h = History::new();
        for (k, &(token, peaks)) in runs.iter().enumerate() {
            let start_us = k as u64 * run_ms * 1000;
            h.open(token, (k as u32, start_us), Accum::new());
            if let Some(r) = h.newest_mut() {
                r.sweeps = Sweeps { peaks, bobs: 0 };
                r.end = (k as u32, start_us + run_ms * 1000 - 10_000);
            }
        }
        h
    }

    #[test]
    fn one_sweep_reads_from_rest_to_rest() {
        let m: crate::token::Token = 0;
        // rest, one push over two runs, rest
        let h = history(&[(STILL, 0), (m, 1), (m, 0), (STILL, 0)], 200);
        assert!(one_sweep(&h, 1, 2));
        // The event's runs alone made one; the run before it, since the rest, made another.
        let h = history(&[(STILL, 0), (m, 1), (m, 1), (m, 0), (STILL, 0)], 200);
        assert!(!one_sweep(&h, 2, 3));
        // Not yet at rest after it: the motion may go on.
        let h = history(&[(STILL, 0), (m, 1), (m, 0)], 200);
        assert!(!one_sweep(&h, 1, 1));
        // Two pushes.
        let h = history(&[(STILL, 0), (m, 1), (m, 1), (STILL, 0)], 200);
        assert!(!one_sweep(&h, 1, 2));
        // Too brief for several pushes to be told apart: 0.3 s from rest to rest.
        let h = history(&[(STILL, 0), (m, 1), (m, 0), (STILL, 0)], 150);
        assert!(!one_sweep(&h, 1, 2));
        assert_eq!(RESOLVABLE_US, 330_000);
    }
}
