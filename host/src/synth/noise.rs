//! Sensor and hand imperfections laid over the clean trajectory.
//!
//! Four effects, each drawn per doodle and scaled by the `noise` multiplier (0 = a perfect
//! tracker and a perfectly steady hand):
//! * **white sensor noise** per sample: position σ 0.1–1.5 mm, orientation σ 0.02–0.3°;
//! * **hand tremor**: physiological 8–12 Hz oscillation, two partials per axis with a slow
//!   (0.15–0.6 Hz) swell, position 0.2–1.2 mm, orientation 0.05–0.35° — present during pauses too;
//! * **slow drift**: low-frequency (0.005–0.12 Hz) wander of 1–8 mm in position and up to 3° in
//!   heading (yaw), bounded however long the log, as IMU-assisted trackers show;
//! * all three are continuous functions of time except the white noise, so a 30 Hz and a
//!   240 Hz log of the same seed see the same tremor and drift;
//! * optional **glitches** ([`Glitcher`], off by default): the faults a recognizer must count
//!   and skip — a one-sample position spike, a NaN row, a zero quaternion, a repeated or a
//!   backward timestamp.

use std::f64::consts::TAU;

use glam::{DQuat, DVec3};

use super::rng::SynthRng;

/// Number of sinusoidal partials of tremor per axis.
const TREMOR_PARTIALS: usize = 2;
/// Number of sinusoidal partials of positional drift per axis.
const DRIFT_PARTIALS: usize = 3;

/// One sinusoid `amp·sin(2π·freq·t + phase)` (units of `amp`; `freq` in Hz, `phase` radians);
/// shared with [`super::rest`], whose hand and stand motions are made of the same stuff.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Partial {
    pub(super) amp: f64,
    pub(super) freq: f64,
    pub(super) phase: f64,
}

impl Partial {
    pub(super) fn at(&self, t: f64) -> f64 {
        self.amp * (TAU * self.freq * t + self.phase).sin()
    }
}

/// Draws `n` partials per axis for 3 axes; amplitudes split so their sum peaks near `amp`.
pub(super) fn partials<const N: usize>(
    rng: &mut SynthRng,
    amp: f64,
    f_lo: f64,
    f_hi: f64,
) -> [[Partial; N]; 3] {
    let mut out = [[Partial::default(); N]; 3];
    for axis in &mut out {
        for p in axis.iter_mut() {
            p.freq = rng.uniform(f_lo, f_hi);
            p.phase = rng.uniform(0.0, TAU);
            p.amp = amp * rng.uniform(0.4, 1.0) / N as f64;
        }
    }
    out
}

pub(super) fn eval3<const N: usize>(ps: &[[Partial; N]; 3], t: f64) -> DVec3 {
    let axis = |a: &[Partial; N]| a.iter().map(|p| p.at(t)).sum::<f64>();
    DVec3::new(axis(&ps[0]), axis(&ps[1]), axis(&ps[2]))
}

/// The imperfections of one doodle's tracker and hand.
#[derive(Debug, Clone)]
pub struct SensorModel {
    /// White position noise σ, metres.
    pub pos_sigma: f64,
    /// White orientation noise σ, radians.
    pub rot_sigma: f64,
    tremor_pos: [[Partial; TREMOR_PARTIALS]; 3],
    tremor_rot: [[Partial; TREMOR_PARTIALS]; 3],
    swell: Partial,
    drift_pos: [[Partial; DRIFT_PARTIALS]; 3],
    yaw_drift: Partial,
    t0: f64,
}

impl SensorModel {
    /// Draws a model scaled by `noise` (dimensionless multiplier, 0 = clean); `t0` is the log's
    /// start time in seconds (drift is zero there).
    pub fn draw(rng: &mut SynthRng, noise: f64, t0: f64) -> Self {
        let m = if noise.is_finite() {
            noise.max(0.0)
        } else {
            0.0
        };
        let pos_sigma = m * rng.uniform(0.1e-3, 1.5e-3);
        let rot_sigma = m * rng.uniform(0.02, 0.3).to_radians();
        let tremor_mm = m * rng.uniform(0.2e-3, 1.2e-3);
        let tremor_deg = m * rng.uniform(0.05, 0.35).to_radians();
        let tremor_pos = partials(rng, tremor_mm, 8.0, 12.0);
        let tremor_rot = partials(rng, tremor_deg, 8.0, 12.0);
        let swell = Partial {
            amp: 0.5,
            freq: rng.uniform(0.15, 0.6),
            phase: rng.uniform(0.0, TAU),
        };
        let drift_amp = m * rng.uniform(1e-3, 8e-3);
        let drift_pos = partials(rng, drift_amp, 0.005, 0.12);
        let yaw_drift = Partial {
            amp: m * rng.uniform(0.0, 3.0).to_radians(),
            freq: rng.uniform(0.005, 0.05),
            phase: rng.uniform(0.0, TAU),
        };
        Self {
            pos_sigma,
            rot_sigma,
            tremor_pos,
            tremor_rot,
            swell,
            drift_pos,
            yaw_drift,
            t0,
        }
    }

    /// A perfect sensor and hand.
    pub fn clean(t0: f64) -> Self {
        Self::draw(&mut SynthRng::from_u64(0), 0.0, t0)
    }

    /// The measured pose at time `t` (seconds) of a true pose (`pos` metres, `q` object→world);
    /// `white` supplies the per-sample noise.
    pub fn measure(&self, t: f64, pos: DVec3, q: DQuat, white: &mut SynthRng) -> (DVec3, DQuat) {
        let swell = 1.0 + self.swell.at(t);
        let drift = eval3(&self.drift_pos, t) - eval3(&self.drift_pos, self.t0);
        let tremor = eval3(&self.tremor_pos, t) * swell;
        let n = DVec3::new(white.normal(), white.normal(), white.normal()) * self.pos_sigma;
        let p = pos + drift + tremor + n;
        let rot_tremor = eval3(&self.tremor_rot, t) * swell;
        let rn = DVec3::new(white.normal(), white.normal(), white.normal()) * self.rot_sigma;
        let q = DQuat::from_rotation_y(self.yaw_drift.at(t) - self.yaw_drift.at(self.t0))
            * q
            * DQuat::from_scaled_axis(rot_tremor + rn);
        (p, q.normalize())
    }
}

/// Kinds of tracker glitch, chosen uniformly.
const GLITCH_KINDS: usize = 5;

/// Injects tracker faults into a sample stream with a given probability per sample.
#[derive(Debug, Clone)]
pub struct Glitcher {
    p: f64,
    rng: SynthRng,
    /// Number of glitches injected so far.
    pub count: usize,
}

impl Glitcher {
    /// A glitcher with probability `p` per sample (clamped to [0, 0.5]) drawing from `rng`.
    pub fn new(p: f64, rng: SynthRng) -> Self {
        let p = if p.is_finite() {
            p.clamp(0.0, 0.5)
        } else {
            0.0
        };
        Self { p, rng, count: 0 }
    }

    /// Possibly corrupts one sample in place: `t` seconds, `pos` metres, `quat` (w, x, y, z);
    /// `prev_t` is the previous sample's time (`None` for the first sample, never corrupted).
    pub fn apply(
        &mut self,
        prev_t: Option<f64>,
        t: &mut f64,
        pos: &mut [f64; 3],
        quat: &mut [f64; 4],
    ) {
        let hit = self.rng.chance(self.p);
        let kind = self.rng.index(GLITCH_KINDS);
        let dir =
            DVec3::new(self.rng.normal(), self.rng.normal(), self.rng.normal()).normalize_or_zero();
        let size = self.rng.uniform(0.05, 0.5);
        let back = self.rng.uniform(0.001, 0.02);
        let Some(prev) = prev_t else { return };
        if !hit || self.p <= 0.0 {
            return;
        }
        self.count += 1;
        match kind {
            0 => {
                for (p, d) in pos.iter_mut().zip(dir.to_array()) {
                    *p += d * size;
                }
            }
            1 => {
                *pos = [f64::NAN; 3];
                *quat = [f64::NAN; 4];
            }
            2 => *quat = [0.0; 4],
            3 => *t = prev,
            _ => *t = prev - back,
        }
    }
}

/// Peak per axis of a set of partials (the largest axis sum of amplitudes).
pub(super) fn peak<const N: usize>(ps: &[[Partial; N]; 3]) -> f64 {
    ps.iter()
        .map(|a| a.iter().map(|p| p.amp.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::rng::Stream;

    #[test]
    fn glitches_happen_at_the_asked_rate_and_never_on_the_first_sample() {
        let mut g = Glitcher::new(0.1, SynthRng::new(4, Stream::Sensor));
        let mut bad = 0;
        for i in 0..5000 {
            let mut t = i as f64 * 0.01;
            let mut p = [0.0; 3];
            let mut q = [1.0, 0.0, 0.0, 0.0];
            let prev = if i == 0 { None } else { Some(t - 0.01) };
            g.apply(prev, &mut t, &mut p, &mut q);
            let changed = t != i as f64 * 0.01 || p != [0.0; 3] || q != [1.0, 0.0, 0.0, 0.0];
            assert!(i > 0 || !changed);
            bad += usize::from(changed);
        }
        assert_eq!(bad, g.count);
        assert!((400..600).contains(&bad), "{bad}");
        let mut none = Glitcher::new(0.0, SynthRng::new(4, Stream::Sensor));
        let (mut t, mut p, mut q) = (1.0, [0.0; 3], [1.0, 0.0, 0.0, 0.0]);
        none.apply(Some(0.5), &mut t, &mut p, &mut q);
        assert_eq!(none.count, 0);
    }

    #[test]
    fn clean_model_changes_nothing() {
        let m = SensorModel::clean(3.0);
        let mut w = SynthRng::new(1, Stream::Sensor);
        let q = DQuat::from_rotation_x(0.3);
        let (p, q2) = m.measure(7.5, DVec3::new(1.0, 2.0, 3.0), q, &mut w);
        assert!((p - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-12);
        assert!(q2.dot(q).abs() > 1.0 - 1e-12);
    }

    #[test]
    fn tremor_and_noise_are_millimetre_scale() {
        let mut r = SynthRng::new(2, Stream::Sensor);
        let m = SensorModel::draw(&mut r, 1.0, 0.0);
        let mut w = SynthRng::new(2, Stream::Clock);
        let mut worst: f64 = 0.0;
        let mut any: f64 = 0.0;
        for i in 0..600 {
            let t = i as f64 / 120.0;
            let (p, q) = m.measure(t, DVec3::ZERO, DQuat::IDENTITY, &mut w);
            worst = worst.max(p.length());
            any = any.max(q.angle_between(DQuat::IDENTITY));
            assert!((q.length() - 1.0).abs() < 1e-12);
        }
        assert!(worst > 1e-4 && worst < 0.02, "{worst}");
        assert!(any > 1e-4 && any < 3f64.to_radians(), "{any}");
    }
}
