//! The tracker's clock and quaternion conventions: when samples are taken and which sign of
//! the quaternion is reported.
//!
//! Samples arrive at a nominal rate (30–240 Hz by default, up to [`MAX_RATE_HZ`]) with
//! timestamp jitter (each instant moved by up to ±`jitter` of a period, uniformly — times stay
//! strictly increasing because jitter is capped below half a period) and occasionally a dropped
//! sample. Trackers disagree on quaternion sign: some keep it continuous, some report the
//! canonical `w ≥ 0` half (flipping whenever `w` crosses zero), some flip at arbitrary moments.

use std::fmt;
use std::str::FromStr;

use glam::DQuat;

use super::rng::SynthRng;

/// Highest nominal sample rate accepted, Hz.
pub const MAX_RATE_HZ: f64 = 2000.0;
/// Lowest nominal sample rate accepted, Hz.
pub const MIN_RATE_HZ: f64 = 5.0;
/// Largest timestamp jitter accepted, as a fraction of the nominal period.
pub const MAX_JITTER: f64 = 0.45;

/// Sample instants in `[start, end]` (seconds) at `rate_hz` with `jitter` (fraction of a period)
/// and dropout probability `drop` per sample. The first and last instants are never dropped.
pub fn sample_times(
    start: f64,
    end: f64,
    rate_hz: f64,
    jitter: f64,
    drop: f64,
    rng: &mut SynthRng,
) -> Vec<f64> {
    let rate = rate_hz.clamp(MIN_RATE_HZ, MAX_RATE_HZ);
    let jitter = jitter.clamp(0.0, MAX_JITTER);
    let drop = drop.clamp(0.0, 0.5);
    if !(start.is_finite() && end.is_finite()) || end < start {
        return Vec::new();
    }
    let period = 1.0 / rate;
    let n = ((end - start) * rate).floor() as usize;
    let mut out = Vec::with_capacity(n + 1);
    out.push(start);
    for k in 1..=n {
        let u = rng.uniform(-1.0, 1.0);
        let dropped = rng.chance(drop);
        let t = start + (k as f64 + jitter * u) * period;
        if k < n && dropped {
            continue;
        }
        out.push(t.min(end));
    }
    out
}

/// How the reported quaternion's sign is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SignMode {
    /// Continuous: each sample in the hemisphere of the previous one.
    Continuous,
    /// Canonical half `w ≥ 0` (flips whenever the true `w` crosses zero).
    Canonical,
    /// Continuous, but the whole sign flips at random moments (every 0.3–3 s).
    Flips,
}

impl SignMode {
    /// All modes.
    pub const ALL: [SignMode; 3] = [SignMode::Continuous, SignMode::Canonical, SignMode::Flips];
}

impl fmt::Display for SignMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SignMode::Continuous => "continuous",
            SignMode::Canonical => "canonical",
            SignMode::Flips => "flips",
        })
    }
}

impl FromStr for SignMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "continuous" => Ok(SignMode::Continuous),
            "canonical" => Ok(SignMode::Canonical),
            "flips" => Ok(SignMode::Flips),
            other => Err(format!(
                "unknown quaternion sign mode `{other}`: expected continuous, canonical or flips"
            )),
        }
    }
}

/// Applies a [`SignMode`] sample by sample.
#[derive(Debug, Clone)]
pub struct SignPolicy {
    mode: SignMode,
    prev: Option<DQuat>,
    flipped: bool,
    next_flip: f64,
}

impl SignPolicy {
    /// A policy starting at time `t0` seconds.
    pub fn new(mode: SignMode, t0: f64, rng: &mut SynthRng) -> Self {
        let first = rng.uniform(0.3, 3.0);
        Self {
            mode,
            prev: None,
            flipped: false,
            next_flip: t0 + first,
        }
    }

    /// The quaternion to report at time `t` for the true orientation `q`.
    pub fn apply(&mut self, t: f64, q: DQuat, rng: &mut SynthRng) -> DQuat {
        let continuous = match self.prev {
            Some(p) if p.dot(q) < 0.0 => -q,
            _ => q,
        };
        self.prev = Some(continuous);
        match self.mode {
            SignMode::Continuous => continuous,
            SignMode::Canonical => {
                if q.w < 0.0 {
                    -q
                } else {
                    q
                }
            }
            SignMode::Flips => {
                while t >= self.next_flip {
                    self.flipped = !self.flipped;
                    self.next_flip += rng.uniform(0.3, 3.0);
                }
                if self.flipped {
                    -continuous
                } else {
                    continuous
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::rng::Stream;

    #[test]
    fn times_increase_and_count_follows_rate() {
        let mut r = SynthRng::new(5, Stream::Clock);
        for rate in [30.0, 60.0, 240.0, 1000.0] {
            let ts = sample_times(10.0, 14.0, rate, 0.45, 0.0, &mut r);
            assert!(ts.windows(2).all(|w| w[1] > w[0]));
            assert_eq!(ts.len(), (4.0 * rate) as usize + 1);
            assert_eq!(ts[0], 10.0);
            assert!(*ts.last().unwrap() <= 14.0);
        }
        let ts = sample_times(0.0, 10.0, 100.0, 0.1, 0.1, &mut r);
        assert!(ts.len() > 850 && ts.len() < 950, "{}", ts.len());
        assert!(sample_times(1.0, 0.0, 60.0, 0.0, 0.0, &mut r).is_empty());
        assert!(sample_times(f64::NAN, 1.0, 60.0, 0.0, 0.0, &mut r).is_empty());
    }

    #[test]
    fn sign_modes() {
        let mut r = SynthRng::new(6, Stream::Sensor);
        let qs: Vec<DQuat> = (0..400)
            .map(|i| DQuat::from_rotation_y(i as f64 * 0.05))
            .collect();
        for mode in SignMode::ALL {
            let mut p = SignPolicy::new(mode, 0.0, &mut r);
            let out: Vec<DQuat> = qs
                .iter()
                .enumerate()
                .map(|(i, q)| p.apply(i as f64 * 0.05, *q, &mut r))
                .collect();
            for (a, b) in out.iter().zip(&qs) {
                assert!((a.dot(*b).abs() - 1.0).abs() < 1e-12);
            }
            let jumps = out.windows(2).filter(|w| w[0].dot(w[1]) < 0.0).count();
            match mode {
                SignMode::Continuous => assert_eq!(jumps, 0),
                SignMode::Canonical => {
                    assert!(jumps > 0);
                    assert!(out.iter().all(|q| q.w >= 0.0));
                }
                SignMode::Flips => assert!(jumps > 2),
            }
        }
    }
}
