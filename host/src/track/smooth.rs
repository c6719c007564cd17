//! An adaptive low-pass on the tracked orientation (the "1€ filter" of Casiez, Roussel and
//! Vogel, CHI 2012, on the quaternion): at rest it smooths hard, in motion it lets the turn
//! through with little lag.
//!
//! Why: a 4 cm tag is 20–45 px wide at 0.5–1 m, and its tilt comes from how much its near
//! edges outgrow its far ones — fractions of a pixel — so a single frame's orientation
//! jitters by 1–2° where its position jitters by tenths of a millimetre. Unfiltered, that
//! jitter reads as turning (≈ 0.4 rad/s at rest at 30 Hz). Position is left as measured.

use glam::DQuat;

/// Cut-off at rest, Hz.
pub const MIN_CUTOFF_HZ: f64 = 1.0;
/// How fast the cut-off rises with the filtered turn rate, Hz per rad/s.
pub const BETA: f64 = 4.0;
/// Cut-off of the turn-rate estimate itself, Hz.
pub const RATE_CUTOFF_HZ: f64 = 1.0;
/// A gap longer than this (seconds, a lost tag) restarts the filter from the next sample.
pub const MAX_GAP_S: f64 = 0.25;

fn alpha(cutoff_hz: f64, dt: f64) -> f64 {
    let tau = 1.0 / (std::f64::consts::TAU * cutoff_hz);
    1.0 / (1.0 + tau / dt)
}

/// The filter's state.
#[derive(Debug, Clone, Default)]
pub struct OrientationFilter {
    last: Option<(f64, DQuat)>,
    rate: f64,
}

impl OrientationFilter {
    /// Filters the orientation measured at `t` seconds.
    pub fn push(&mut self, t: f64, q: DQuat) -> DQuat {
        let Some((t0, prev)) = self.last else {
            self.last = Some((t, q));
            self.rate = 0.0;
            return q;
        };
        let dt = t - t0;
        if dt.is_nan() || dt <= 0.0 || dt > MAX_GAP_S {
            self.last = Some((t, q));
            self.rate = 0.0;
            return q;
        }
        let q = if q.dot(prev) < 0.0 { -q } else { q };
        let raw_rate = prev.angle_between(q) / dt;
        self.rate += alpha(RATE_CUTOFF_HZ, dt) * (raw_rate - self.rate);
        let a = alpha(MIN_CUTOFF_HZ + BETA * self.rate, dt);
        let out = prev.slerp(q, a).normalize();
        self.last = Some((t, out));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jitter_at_rest_shrinks_and_a_turn_gets_through() {
        let mut f = OrientationFilter::default();
        let mut worst_rest: f64 = 0.0;
        for i in 0..60 {
            let wobble = if i % 2 == 0 { 0.02 } else { -0.02 };
            let out = f.push(i as f64 / 30.0, DQuat::from_rotation_x(wobble));
            if i > 10 {
                worst_rest = worst_rest.max(out.angle_between(DQuat::IDENTITY));
            }
        }
        assert!(worst_rest < 0.01, "rest jitter {worst_rest} rad of 0.02");
        // Then a steady 3 rad/s turn for half a second: the filter trails it by little.
        let mut lag = 0.0;
        for i in 1..=15 {
            let t = 2.0 + i as f64 / 30.0;
            let truth = DQuat::from_rotation_y(3.0 * i as f64 / 30.0);
            lag = f.push(t, truth).angle_between(truth);
        }
        assert!(lag < 0.25, "lag {lag} rad after 0.5 s of turning");
    }

    #[test]
    fn a_gap_restarts_it() {
        let mut f = OrientationFilter::default();
        f.push(0.0, DQuat::IDENTITY);
        let q = DQuat::from_rotation_z(1.0);
        assert_eq!(f.push(1.0, q), q);
    }
}
