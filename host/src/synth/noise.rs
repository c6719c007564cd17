//! Sensor and hand imperfections laid over the clean trajectory.
//!
//! Four effects, each drawn per doodle and scaled by the `noise` multiplier (0 = a perfect
//! tracker and a perfectly steady hand):
//! * **white sensor noise** per sample: position σ 0.1–1.5 mm, orientation σ 0.02–0.3°;
//! * **hand tremor**: physiological 8–12 Hz oscillation, two partials per axis with a slow
//!   (0.15–0.6 Hz) swell, position 0.2–1.2 mm, orientation 0.05–0.35° — present during pauses too;
//! * **slow drift**: low-frequency (0.01–0.12 Hz) wander of 1–8 mm plus a linear creep up to
//!   0.5 mm/s, and a heading (yaw) drift up to 0.3°/s, as IMU-assisted trackers show;
//! * all three are continuous functions of time except the white noise, so a 30 Hz and a
//!   240 Hz log of the same seed see the same tremor and drift.

use std::f64::consts::TAU;

use glam::{DQuat, DVec3};

use super::rng::SynthRng;

/// Number of sinusoidal partials of tremor per axis.
const TREMOR_PARTIALS: usize = 2;
/// Number of sinusoidal partials of positional drift per axis.
const DRIFT_PARTIALS: usize = 3;

#[derive(Debug, Clone, Copy, Default)]
struct Partial {
    amp: f64,
    freq: f64,
    phase: f64,
}

impl Partial {
    fn at(&self, t: f64) -> f64 {
        self.amp * (TAU * self.freq * t + self.phase).sin()
    }
}

/// Draws `n` partials per axis for 3 axes; amplitudes split so their sum peaks near `amp`.
fn partials<const N: usize>(
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

fn eval3<const N: usize>(ps: &[[Partial; N]; 3], t: f64) -> DVec3 {
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
    creep: DVec3,
    yaw_rate: f64,
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
        let drift_pos = partials(rng, drift_amp, 0.01, 0.12);
        let creep = DVec3::new(rng.normal(), rng.normal() * 0.3, rng.normal())
            * (m * rng.uniform(0.0, 0.5e-3) / 1.4);
        let yaw_rate = m * rng.uniform(-0.3, 0.3).to_radians();
        Self {
            pos_sigma,
            rot_sigma,
            tremor_pos,
            tremor_rot,
            swell,
            drift_pos,
            creep,
            yaw_rate,
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
        let dt = t - self.t0;
        let swell = 1.0 + self.swell.at(t);
        let drift = eval3(&self.drift_pos, t) - eval3(&self.drift_pos, self.t0) + self.creep * dt;
        let tremor = eval3(&self.tremor_pos, t) * swell;
        let n = DVec3::new(white.normal(), white.normal(), white.normal()) * self.pos_sigma;
        let p = pos + drift + tremor + n;
        let rot_tremor = eval3(&self.tremor_rot, t) * swell;
        let rn = DVec3::new(white.normal(), white.normal(), white.normal()) * self.rot_sigma;
        let q = DQuat::from_rotation_y(self.yaw_rate * dt)
            * q
            * DQuat::from_scaled_axis(rot_tremor + rn);
        (p, q.normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::rng::Stream;

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
