//! Stage 0 — sample intake: validation, counters, and resampling onto the internal tick grid.
//!
//! Samples arrive at any rate (30–1000 Hz) with jitter. Every later stage runs on a fixed
//! internal grid of [`TICK_US`] so that timestamps, not sample counts, define rates: a 30 Hz and
//! a 240 Hz log of the same motion produce the same ticks up to interpolation error. Position is
//! interpolated linearly, orientation by normalised lerp on the sign-aligned quaternion (q and −q
//! are the same rotation, and the sign says which way round the figurine turned since the
//! previous sample: the short way, unless the previous step's turn rate, carried over this
//! step, passes the half turn — a fast spin across frames the tracker lost). Before that,
//! each sample passes a first-order low-pass cut at the grid's Nyquist rate
//! ([`ANTI_ALIAS_TAU_US`]), so a fast tracker's jitter is averaged rather than aliased onto
//! the grid.
//!
//! Bad samples are counted in [`IntakeCounters`] and skipped; they never reach the filter.

use crate::fmath;

/// Internal tick period, µs (100 Hz grid).
pub const TICK_US: u64 = 10_000;
/// Internal tick period, seconds.
pub const TICK_S: f32 = 0.01;
/// A gap between accepted samples longer than this (µs) restarts the pipeline (tracker lost).
pub const MAX_GAP_US: u64 = 250_000;
/// A position step larger than this (m) between accepted samples is a glitch, skipped.
pub const MAX_STEP_M: f32 = 0.5;
/// A step at least this many times as long as the one before it lost samples in between:
/// only across such a gap does a turn that was speeding up carry on speeding up.
pub const LOST_STEP_RATIO: u64 = 2;
/// Speed (m/s) above which a position step is a glitch (a toy does not move at 25 m/s).
pub const MAX_SPEED_M_S: f32 = 25.0;
/// Absolute coordinate bound (m); larger values are treated as garbage.
pub const MAX_ABS_POS_M: f32 = 1.0e5;
/// Squared quaternion norms below this are zero-length or corrupt: rejected, not renormalised.
pub const QUAT_NORM2_MIN: f32 = 0.25;
/// Upper bound of the accepted squared quaternion norm (see [`QUAT_NORM2_MIN`]).
pub const QUAT_NORM2_MAX: f32 = 4.0;
/// Time constant (µs) of the anti-alias low-pass applied to samples before they are
/// interpolated onto the grid: a first-order cut at the grid's Nyquist rate (50 Hz),
/// τ = [`TICK_US`] / π. A fast tracker's white jitter then averages over the samples of a
/// tick instead of being picked at the grid points (σ ÷ 2.7 at 1000 Hz, ÷ 1.6 at 240 Hz,
/// ÷ 1.1 at 100 Hz); a stroke, whose content lies below 10 Hz, is delayed by about 3 ms.
pub const ANTI_ALIAS_TAU_US: u64 = TICK_US * 1000 / 3142;

/// One pose sample as the recognizer receives it (from the wire or a log).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Caller's sequence number (wraps freely; only echoed in events).
    pub seq: u32,
    /// Timestamp, µs on the caller's clock; must strictly increase.
    pub t_us: u64,
    /// Position, metres, world frame, +Y up.
    pub pos: [f32; 3],
    /// Orientation (w, x, y, z), object → world; need not be normalised; q ≡ −q.
    pub quat: [f32; 4],
}

/// Counts of skipped input, by reason.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct IntakeCounters {
    /// Samples accepted.
    pub accepted: u32,
    /// Samples with NaN or infinite values, or absurd coordinates.
    pub non_finite: u32,
    /// Samples with a zero-length or far-from-unit quaternion.
    pub bad_quat: u32,
    /// Samples whose time is not after the previous accepted sample (backwards or duplicate).
    pub time_not_increasing: u32,
    /// Samples whose position jumped implausibly far or fast.
    pub jumps: u32,
    /// Gaps longer than [`MAX_GAP_US`] (pipeline restarted; the sample itself is accepted).
    pub gaps: u32,
}

impl IntakeCounters {
    /// Total number of skipped samples.
    pub fn skipped(&self) -> u32 {
        self.non_finite
            .saturating_add(self.bad_quat)
            .saturating_add(self.time_not_increasing)
            .saturating_add(self.jumps)
    }
}

/// One point of the internal 100 Hz grid, with the input sample that closed it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tick {
    /// Tick time, µs on the caller's clock.
    pub t_us: u64,
    /// Position relative to the stream's origin (first accepted sample), metres, world.
    pub pos: [f32; 3],
    /// Unit orientation, sign-continuous along the stream.
    pub quat: [f32; 4],
    /// Sequence number of the input sample at or after this tick.
    pub seq: u32,
    /// Time of that input sample, µs.
    pub sample_t_us: u64,
}

/// What [`Intake::push`] did with a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Accept {
    /// The sample was skipped (see the counters).
    Rejected,
    /// Accepted; ticks up to it can be drained with [`Intake::next_tick`].
    Accepted,
    /// Accepted after a long gap: downstream state must be restarted before draining.
    AcceptedAfterGap,
}

/// Validates samples and interpolates them onto the tick grid.
#[derive(Debug, Clone)]
pub struct Intake {
    counters: IntakeCounters,
    origin: [f32; 3],
    prev: Option<(u64, [f32; 3], [f32; 4])>,
    cur: Option<(u64, [f32; 3], [f32; 4], u32)>,
    /// The latest accepted sample's unit orientation as received, sign-aligned: the next
    /// sample's sign continues this one, not the low-passed state, whose lag would turn a
    /// step near half a turn (a fast spin at 30 Hz) the other way round.
    raw_quat: [f32; 4],
    /// The last step's turn rate, rad/s, as a rotation vector in the figurine's frame (the
    /// step `q_prev⁻¹ q` over its time; its axis is the same before and after the step): what
    /// carries a spin across frames the tracker lost.
    raw_rate: [f32; 3],
    /// How fast the last step's turn rate grew on the one before, rad/s²: a spin speeding up
    /// as the tracker lost it turns further across the gap than its first frames' rate says.
    raw_gain: f32,
    next_tick_us: u64,
}

impl Default for Intake {
    fn default() -> Self {
        Self::new()
    }
}

impl Intake {
    /// A fresh intake with zeroed counters.
    pub const fn new() -> Self {
        Intake {
            counters: IntakeCounters {
                accepted: 0,
                non_finite: 0,
                bad_quat: 0,
                time_not_increasing: 0,
                jumps: 0,
                gaps: 0,
            },
            origin: [0.0; 3],
            prev: None,
            cur: None,
            raw_quat: [1.0, 0.0, 0.0, 0.0],
            raw_rate: [0.0; 3],
            raw_gain: 0.0,
            next_tick_us: 0,
        }
    }

    /// The counters so far.
    pub fn counters(&self) -> IntakeCounters {
        self.counters
    }

    /// Offers one sample. On acceptance, call [`Intake::next_tick`] until it returns `None`.
    pub fn push(&mut self, s: &Sample) -> Accept {
        let finite = s
            .pos
            .iter()
            .chain(s.quat.iter())
            .all(|&v| fmath::is_finite(v))
            && s.pos.iter().all(|&v| fmath::abs(v) <= MAX_ABS_POS_M);
        if !finite {
            self.counters.non_finite = self.counters.non_finite.saturating_add(1);
            return Accept::Rejected;
        }
        let n2 = fmath::qdot(s.quat, s.quat);
        if !(QUAT_NORM2_MIN..=QUAT_NORM2_MAX).contains(&n2) {
            self.counters.bad_quat = self.counters.bad_quat.saturating_add(1);
            return Accept::Rejected;
        }
        let inv = 1.0 / fmath::sqrt(n2);
        let mut q = [
            s.quat[0] * inv,
            s.quat[1] * inv,
            s.quat[2] * inv,
            s.quat[3] * inv,
        ];
        let Some((t_prev, p_prev, q_prev, _)) = self.cur else {
            self.start(s, q);
            return Accept::Accepted;
        };
        if s.t_us <= t_prev {
            self.counters.time_not_increasing = self.counters.time_not_increasing.saturating_add(1);
            return Accept::Rejected;
        }
        let dt_us = s.t_us - t_prev;
        if dt_us > MAX_GAP_US {
            self.counters.gaps = self.counters.gaps.saturating_add(1);
            self.start(s, q);
            return Accept::AcceptedAfterGap;
        }
        let p = [
            s.pos[0] - self.origin[0],
            s.pos[1] - self.origin[1],
            s.pos[2] - self.origin[2],
        ];
        let step = fmath::norm3([p[0] - p_prev[0], p[1] - p_prev[1], p[2] - p_prev[2]]);
        let dt_s = dt_us as f32 * 1e-6;
        if step > MAX_STEP_M || step > MAX_SPEED_M_S * dt_s {
            self.counters.jumps = self.counters.jumps.saturating_add(1);
            return Accept::Rejected;
        }
        // Samples were lost when this step is much longer than the one before it.
        let last_us = self.prev.map_or(0, |(t0, _, _)| t_prev.saturating_sub(t0));
        let lost = last_us > 0 && dt_us >= LOST_STEP_RATIO.saturating_mul(last_us);
        q = self.continue_turn(q, dt_s, lost);
        // First-order low-pass, exact for any sample spacing up to the discretisation
        // (dt / (τ + dt)): slow trackers pass nearly untouched, fast ones are averaged.
        let a = dt_us as f32 / (ANTI_ALIAS_TAU_US + dt_us) as f32;
        let p = [
            p_prev[0] + a * (p[0] - p_prev[0]),
            p_prev[1] + a * (p[1] - p_prev[1]),
            p_prev[2] + a * (p[2] - p_prev[2]),
        ];
        let mut q = [
            q_prev[0] + a * (q[0] - q_prev[0]),
            q_prev[1] + a * (q[1] - q_prev[1]),
            q_prev[2] + a * (q[2] - q_prev[2]),
            q_prev[3] + a * (q[3] - q_prev[3]),
        ];
        let inv = 1.0 / fmath::sqrt(fmath::qdot(q, q));
        for c in &mut q {
            *c *= inv;
        }
        self.counters.accepted = self.counters.accepted.saturating_add(1);
        self.prev = Some((t_prev, p_prev, q_prev));
        self.cur = Some((s.t_us, p, q, s.seq));
        Accept::Accepted
    }

    /// `q` with the sign that says which way round the figurine turned since the last sample
    /// (nlerp from `raw_quat` follows it), remembering the step's rate for the next one.
    ///
    /// The short way (≤ half a turn) unless the last step's rate, carried over `dt_s`, reaches
    /// past the half turn the other way: of the two rotations that end at `q`, the one nearer
    /// the rate the figurine already had. Between samples of a steady tracker the two agree;
    /// across frames lost mid-spin (≈ 1 rad a frame at 30 Hz) the short way runs backwards.
    fn continue_turn(&mut self, q: [f32; 4], dt_s: f32, lost: bool) -> [f32; 4] {
        let mut q = q;
        if fmath::qdot(q, self.raw_quat) < 0.0 {
            q = [-q[0], -q[1], -q[2], -q[3]];
        }
        let step = fmath::qmul(fmath::qconj(self.raw_quat), q);
        let v = [step[1], step[2], step[3]];
        let s = fmath::norm3(v);
        self.raw_quat = q;
        let was = fmath::norm3(self.raw_rate);
        if s <= 0.0 {
            self.raw_rate = [0.0; 3];
            self.raw_gain = -was / dt_s;
            return q;
        }
        let axis = [v[0] / s, v[1] / s, v[2] / s];
        let short = 2.0 * fmath::atan2(s, step[0]);
        // Rate of the last step along this one's axis, carried over this step (radians),
        // still speeding up if it was: below −(π − short) the rotation the long way round is
        // the nearer one.
        let along = fmath::dot3(self.raw_rate, axis);
        let gain = if lost && was > 0.0 {
            0.5 * fmath::max(self.raw_gain, 0.0) * (along / was) * dt_s * dt_s
        } else {
            0.0
        };
        let carried = along * dt_s + gain;
        let angle = if carried < short - core::f32::consts::PI {
            q = [-q[0], -q[1], -q[2], -q[3]];
            self.raw_quat = q;
            short - 2.0 * core::f32::consts::PI
        } else {
            short
        };
        let rate = angle / dt_s;
        self.raw_rate = [axis[0] * rate, axis[1] * rate, axis[2] * rate];
        self.raw_gain = (fmath::abs(rate) - was) / dt_s;
        q
    }

    fn start(&mut self, s: &Sample, q: [f32; 4]) {
        self.counters.accepted = self.counters.accepted.saturating_add(1);
        self.origin = s.pos;
        self.prev = None;
        self.cur = Some((s.t_us, [0.0; 3], q, s.seq));
        self.raw_quat = q;
        self.raw_rate = [0.0; 3];
        self.raw_gain = 0.0;
        self.next_tick_us = s.t_us;
    }

    /// The next grid tick at or before the latest accepted sample, if any.
    pub fn next_tick(&mut self) -> Option<Tick> {
        let (t1, p1, q1, seq) = self.cur?;
        if self.next_tick_us > t1 {
            return None;
        }
        let t = self.next_tick_us;
        self.next_tick_us = t.saturating_add(TICK_US);
        let (pos, quat) = match self.prev {
            Some((t0, p0, q0)) if t < t1 && t >= t0 => {
                let a = (t - t0) as f32 / (t1 - t0) as f32;
                let b = 1.0 - a;
                let p = [
                    b * p0[0] + a * p1[0],
                    b * p0[1] + a * p1[1],
                    b * p0[2] + a * p1[2],
                ];
                let mut q = [
                    b * q0[0] + a * q1[0],
                    b * q0[1] + a * q1[1],
                    b * q0[2] + a * q1[2],
                    b * q0[3] + a * q1[3],
                ];
                let n2 = fmath::qdot(q, q);
                let inv = if n2 > 1e-12 {
                    1.0 / fmath::sqrt(n2)
                } else {
                    1.0
                };
                for c in &mut q {
                    *c *= inv;
                }
                (p, q)
            }
            _ => (p1, q1),
        };
        Some(Tick {
            t_us: t,
            pos,
            quat,
            seq,
            sample_t_us: t1,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(seq: u32, t_us: u64, x: f32) -> Sample {
        Sample {
            seq,
            t_us,
            pos: [x, 1.0, 0.0],
            quat: [1.0, 0.0, 0.0, 0.0],
        }
    }

    fn drain(i: &mut Intake) -> usize {
        let mut n = 0;
        while i.next_tick().is_some() {
            n += 1;
        }
        n
    }

    #[test]
    fn bad_samples_are_counted_and_skipped() {
        let mut i = Intake::new();
        assert_eq!(i.push(&s(0, 1000, 0.0)), Accept::Accepted);
        let mut nan = s(1, 2000, 0.0);
        nan.pos[1] = f32::NAN;
        assert_eq!(i.push(&nan), Accept::Rejected);
        let mut zq = s(2, 3000, 0.0);
        zq.quat = [0.0; 4];
        assert_eq!(i.push(&zq), Accept::Rejected);
        assert_eq!(i.push(&s(3, 1000, 0.0)), Accept::Rejected);
        assert_eq!(i.push(&s(4, 500, 0.0)), Accept::Rejected);
        assert_eq!(i.push(&s(5, 5000, 3.0)), Accept::Rejected);
        assert_eq!(i.push(&s(6, 6000, 0.001)), Accept::Accepted);
        let c = i.counters();
        assert_eq!(
            (c.non_finite, c.bad_quat, c.time_not_increasing, c.jumps),
            (1, 1, 2, 1)
        );
        assert_eq!(c.accepted, 2);
        assert_eq!(c.skipped(), 5);
    }

    #[test]
    fn ticks_follow_time_not_sample_count() {
        for rate in [30u64, 60, 240, 1000] {
            let mut i = Intake::new();
            let mut ticks = 0;
            let period = 1_000_000 / rate;
            let mut t = 0;
            while t <= 1_000_000 {
                i.push(&s(0, t, t as f32 * 1e-7));
                ticks += drain(&mut i);
                t += period;
            }
            assert!((99..=101).contains(&ticks), "{rate} Hz gave {ticks} ticks");
        }
    }

    #[test]
    fn interpolation_is_linear_in_position_and_origin_relative() {
        let mut i = Intake::new();
        i.push(&s(0, 0, 100.0));
        drain(&mut i);
        i.push(&s(1, 20_000, 100.2));
        let t = i.next_tick().unwrap();
        assert_eq!(t.t_us, 10_000);
        // Half way to the second sample as the low-pass let it through.
        let a = 20_000.0 / (ANTI_ALIAS_TAU_US + 20_000) as f32;
        assert!((t.pos[0] - 0.1 * a).abs() < 1e-5, "{:?}", t.pos);
        assert_eq!(t.seq, 1);
    }

    /// The tick positions' spread about their mean for pseudo-random ±1 mm jitter at `rate` Hz.
    fn jitter_at_ticks(rate: u64) -> f32 {
        let mut i = Intake::new();
        let period = 1_000_000 / rate;
        let (mut n, mut sum, mut sum2) = (0.0f32, 0.0f32, 0.0f32);
        for k in 0..(rate * 2) {
            // A deterministic pseudo-random ±1 mm, white enough for the test.
            let x = if (k.wrapping_mul(2_654_435_761) >> 7) & 1 == 0 {
                1e-3
            } else {
                -1e-3
            };
            i.push(&s(0, k * period, x));
            while let Some(t) = i.next_tick() {
                if t.t_us > 200_000 {
                    n += 1.0;
                    sum += t.pos[0];
                    sum2 += t.pos[0] * t.pos[0];
                }
            }
        }
        let mean = sum / n;
        (sum2 / n - mean * mean).sqrt()
    }

    #[test]
    fn a_fast_trackers_jitter_is_averaged_not_picked() {
        let at_100 = jitter_at_ticks(100);
        let at_1000 = jitter_at_ticks(1000);
        assert!(at_100 > 0.6e-3, "{at_100}");
        assert!(
            at_1000 < 0.5 * at_100,
            "1000 Hz {at_1000} vs 100 Hz {at_100}"
        );
    }

    #[test]
    fn a_steady_motion_is_delayed_by_the_low_pass_only() {
        // 1 m/s along x at 1000 Hz: the ticks trail the truth by τ (≈ 3 ms) = 3 mm.
        let mut i = Intake::new();
        let mut last = None;
        for k in 0..=500u64 {
            i.push(&s(0, k * 1000, k as f32 * 1e-3));
            while let Some(t) = i.next_tick() {
                last = Some(t);
            }
        }
        let t = last.unwrap();
        let lag_m = t.t_us as f32 * 1e-6 - t.pos[0];
        let tau_s = ANTI_ALIAS_TAU_US as f32 * 1e-6;
        assert!(
            (lag_m - tau_s).abs() < 0.5e-3,
            "lag {lag_m} m, tau {tau_s} s"
        );
    }

    #[test]
    fn a_spin_stepping_near_half_a_turn_per_sample_keeps_its_direction() {
        // 172° about +Y per sample at 30 Hz: the low-pass trails each sample by about 15°, so
        // the new sample is more than half a turn from the filtered state the short way; its
        // sign must continue the previous sample, or the ticks turn back.
        let step = 172.0f32.to_radians();
        let mut i = Intake::new();
        let mut ticks = heapless::Vec::<[f32; 4], 64>::new();
        for k in 0..12u32 {
            let half = 0.5 * step * k as f32;
            let q = [libm::cosf(half), 0.0, libm::sinf(half), 0.0];
            let quat = if k % 2 == 0 { q } else { q.map(|c| -c) };
            i.push(&Sample {
                seq: k,
                t_us: u64::from(k) * 33_333,
                pos: [0.0, 1.0, 0.0],
                quat,
            });
            while let Some(t) = i.next_tick() {
                ticks.push(t.quat).unwrap();
            }
        }
        assert!(ticks.len() > 30);
        for w in ticks.windows(2) {
            let r = fmath::qmul(fmath::qconj(w[0]), w[1]);
            assert!(
                r[0] * r[2] > 0.0,
                "a tick turned back: {:?} -> {:?}",
                w[0],
                w[1]
            );
        }
    }

    /// Ticks' orientations of samples turning about +Y: `(t_us, yaw in radians)` each, the
    /// quaternion's sign flipped on every third sample, as a tracker may send it.
    fn yaw_ticks(samples: &[(u64, f32)]) -> heapless::Vec<[f32; 4], 128> {
        let mut i = Intake::new();
        let mut ticks = heapless::Vec::new();
        for (k, &(t_us, yaw)) in samples.iter().enumerate() {
            let q = [libm::cosf(0.5 * yaw), 0.0, libm::sinf(0.5 * yaw), 0.0];
            let quat = if k % 3 == 1 { q.map(|c| -c) } else { q };
            i.push(&Sample {
                seq: k as u32,
                t_us,
                pos: [0.0, 1.0, 0.0],
                quat,
            });
            while let Some(t) = i.next_tick() {
                ticks.push(t.quat).unwrap();
            }
        }
        ticks
    }

    /// Signed turns about +Y from each tick to the next, radians.
    fn yaw_steps(ticks: &[[f32; 4]]) -> heapless::Vec<f32, 128> {
        ticks
            .windows(2)
            .map(|w| {
                let r = fmath::qmul(fmath::qconj(w[0]), w[1]);
                let r = if r[0] < 0.0 { r.map(|c| -c) } else { r };
                2.0 * libm::atan2f(r[2], r[0])
            })
            .collect()
    }

    #[test]
    fn a_spin_keeps_turning_across_frames_the_tracker_lost() {
        // 1 rad a frame at 30 Hz; frames 6-9 lost, so the sample after the gap is 5 rad on —
        // 1.28 rad back the short way.
        let samples: heapless::Vec<(u64, f32), 16> = (0..14u64)
            .filter(|k| !(6..10).contains(k))
            .map(|k| (k * 33_333, k as f32))
            .collect();
        let steps = yaw_steps(&yaw_ticks(&samples));
        assert!(
            steps.iter().all(|&a| a > 0.0),
            "a tick turned back: {steps:?}"
        );
        let total: f32 = steps.iter().sum();
        // The low-pass trails the last sample by a few hundredths of a radian.
        assert!((total - 13.0).abs() < 0.2, "turned {total} rad of 13");
    }

    #[test]
    fn a_spin_speeding_up_as_the_tracker_lost_it_keeps_turning_the_long_way() {
        // A spin starting (0.05, then 0.25 rad a frame at 30 Hz) as the tracker loses it for
        // four frames: the sample after the gap is 5.5 rad on, 0.78 rad back the short way.
        // The rate before the gap alone carries 5 × 0.25 rad, nearer the short way back;
        // still speeding up (180 rad/s²), it carries 3.75 rad, nearer the long way on.
        let yaw = [0.0, 0.0, 0.0, 0.05, 0.3, 5.8, 6.3, 6.3];
        let times = [0, 1, 2, 3, 4, 9, 10, 11];
        let samples: heapless::Vec<(u64, f32), 8> = times
            .iter()
            .zip(yaw)
            .map(|(&k, y)| (k * 33_333, y))
            .collect();
        let steps = yaw_steps(&yaw_ticks(&samples));
        assert!(
            steps.iter().all(|&a| a >= 0.0),
            "a tick turned back: {steps:?}"
        );
        let total: f32 = steps.iter().sum();
        assert!((total - 6.3).abs() < 0.2, "turned {total} rad of 6.3");
        // The same start with no frame lost: 2.84 rad back is nearer the 0.25 rad a frame had
        // than 3.44 on (speeding on, it would not be).
        let yaw = [0.0, 0.0, 0.0, 0.05, 0.3, 0.3 - 2.84];
        let samples: heapless::Vec<(u64, f32), 8> = yaw
            .iter()
            .enumerate()
            .map(|(k, &y)| (k as u64 * 33_333, y))
            .collect();
        let total: f32 = yaw_steps(&yaw_ticks(&samples)).iter().sum();
        assert!(total < 0.0, "turned {total} rad");
    }

    #[test]
    fn after_a_gap_at_rest_the_short_way_round_stands() {
        // Still, then seen again 0.2 s later 160° round: nothing said it spun the long way.
        let steps = yaw_steps(&yaw_ticks(&[
            (0, 0.0),
            (33_333, 0.0),
            (66_666, 0.0),
            (266_666, -160f32.to_radians()),
        ]));
        assert!(
            steps.iter().all(|&a| a <= 0.0),
            "a tick turned on: {steps:?}"
        );
        // Ticks stop at the last one before the sample (6.7 ms short of it).
        let total: f32 = steps.iter().sum();
        assert!((-2.8..-2.6).contains(&total), "turned {total} rad");
    }

    #[test]
    fn long_gap_restarts() {
        let mut i = Intake::new();
        i.push(&s(0, 0, 0.0));
        drain(&mut i);
        assert_eq!(i.push(&s(1, 2_000_000, 5.0)), Accept::AcceptedAfterGap);
        assert_eq!(i.counters().gaps, 1);
        let t = i.next_tick().unwrap();
        assert_eq!(t.t_us, 2_000_000);
        assert_eq!(t.pos, [0.0; 3]);
    }
}
