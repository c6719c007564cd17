//! An adaptive low-pass on the tracked orientation (the "1€ filter" of Casiez, Roussel and
//! Vogel, CHI 2012, on the quaternion): at rest it smooths hard, in motion it lets the turn
//! through with little lag.
//!
//! Why: a 4 cm tag is 20–45 px wide at 0.5–1 m, and its tilt comes from how much its near
//! edges outgrow its far ones — fractions of a pixel — so a single frame's orientation
//! jitters by 1–2° where its position jitters by tenths of a millimetre. Unfiltered, that
//! jitter reads as turning (≈ 0.4 rad/s at rest at 30 Hz). Position is left as measured.
//!
//! The filter opens with the measured turn rate, and the jitter is measured turning too: a
//! face-on tag at 1 m jitters by about a degree a frame, which alone would hold the cut-off
//! near 3 Hz, so the filter would smooth least where the jitter is worst. So the rate that
//! opens it is the measured rate less the jitter's, in power (the two are independent): the
//! jitter's rate is [`FLOOR_FACTOR`] × a floor learnt from the stream as the recognizer learns
//! its noise (minimum statistics: the quietest of the last [`FLOOR_BLOCKS`] blocks' mean rate,
//! among blocks whose net turn is under [`COHERENCE_MAX`] of their path: a turn is no jitter).
//!
//! | measured rate r, jitter's j | cut-off |
//! |---|---|
//! | r ≤ j (a tag at rest) | [`MIN_CUTOFF_HZ`] |
//! | r > j (a turn) | [`MIN_CUTOFF_HZ`] + [`BETA`] × √(r² − j²) |

use glam::DQuat;

/// Cut-off at rest, Hz.
pub const MIN_CUTOFF_HZ: f64 = 1.0;
/// How fast the cut-off rises with the filtered turn rate, Hz per rad/s.
pub const BETA: f64 = 4.0;
/// Cut-off of the turn-rate estimate itself, Hz.
pub const RATE_CUTOFF_HZ: f64 = 1.0;
/// A gap longer than this (seconds, a lost tag) restarts the filter from the next sample.
pub const MAX_GAP_S: f64 = 0.25;
/// Length of a block over which the measured turn rate is averaged for the jitter floor, s.
pub const FLOOR_BLOCK_S: f64 = 0.25;
/// Blocks among which the quietest sets the jitter floor: 4 s, longer than a gesture, so
/// that a rest is among them while the figurine plays.
pub const FLOOR_BLOCKS: usize = 16;
/// A block counts toward the jitter floor only if the tag's net turn over it stays below this
/// share of the turns summed frame to frame (the recognizer's `noise::COHERENCE_MAX`).
pub const COHERENCE_MAX: f64 = 0.5;
/// Multiple of the jitter floor taken as a held tag's jitter: the quietest block's mean
/// lies below a typical block's, and the low-passed rate swings about that (at 2, a held tag
/// still fired 8 actions in 78 minutes of the track bench's holds; at 3, 2).
pub const FLOOR_FACTOR: f64 = 3.0;

fn alpha(cutoff_hz: f64, dt: f64) -> f64 {
    let tau = 1.0 / (std::f64::consts::TAU * cutoff_hz);
    1.0 / (1.0 + tau / dt)
}

/// The filter's state.
#[derive(Debug, Clone, Default)]
pub struct OrientationFilter {
    last: Option<(f64, DQuat)>,
    rate: f64,
    floor: JitterFloor,
}

/// The measured turn rate of a tag at rest: the quietest of the last [`FLOOR_BLOCKS`] blocks'
/// mean rate (minimum statistics, as the recognizer learns its noise), among the blocks that
/// went nowhere: jitter turns the tag to and fro, a turn takes it somewhere, and a steady
/// turn longer than the window must not be learnt as jitter.
#[derive(Debug, Clone, Default)]
struct JitterFloor {
    /// Σ rate, samples, and the first sample's time of the block being filled.
    sum: f64,
    n: u32,
    start: f64,
    /// The measured orientation where the block began, and the last one.
    from: Option<DQuat>,
    last: Option<DQuat>,
    /// Σ of the turns between the block's measured orientations, rad.
    path: f64,
    /// Mean rate of the last counted blocks (rad/s), oldest overwritten first.
    means: [f64; FLOOR_BLOCKS],
    counted: usize,
    /// The quietest of `means` once two have counted, else 0 (rad/s).
    floor: f64,
}

impl JitterFloor {
    /// Adds the rate measured at `t` seconds with the measured orientation `q`.
    fn push(&mut self, t: f64, rate: f64, q: DQuat) {
        if self.n == 0 {
            self.start = t;
            self.from = self.last.or(Some(q));
            self.path = 0.0;
        }
        if let Some(last) = self.last {
            self.path += last.angle_between(q);
        }
        self.last = Some(q);
        self.sum += rate;
        self.n += 1;
        if t - self.start >= FLOOR_BLOCK_S {
            let net = self.from.map_or(0.0, |from| from.angle_between(q));
            if net < COHERENCE_MAX * self.path {
                self.means[self.counted % FLOOR_BLOCKS] = self.sum / f64::from(self.n);
                self.counted += 1;
                let known = &self.means[..self.counted.min(FLOOR_BLOCKS)];
                if known.len() >= 2 {
                    self.floor = known.iter().copied().fold(f64::INFINITY, f64::min);
                }
            }
            (self.sum, self.n) = (0.0, 0);
        }
    }

    /// The floor, rad/s (0 until two blocks have counted).
    fn rate(&self) -> f64 {
        self.floor
    }
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
        self.floor.push(t, raw_rate, q);
        // Motion and jitter are independent: their rates add in power.
        let jitter = FLOOR_FACTOR * self.floor.rate();
        let moving = (self.rate * self.rate - jitter * jitter).max(0.0).sqrt();
        let a = alpha(MIN_CUTOFF_HZ + BETA * moving, dt);
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

    /// Frame-to-frame turns of the filter's output, radians, over `frames` of a tag held
    /// still that jitters by `jitter` radians a frame (deterministic, about both tilt axes),
    /// after `settle` frames.
    fn rest_turns(
        f: &mut OrientationFilter,
        jitter: f64,
        settle: usize,
        frames: usize,
    ) -> Vec<f64> {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut last = None;
        let mut turns = Vec::new();
        for i in 0..settle + frames {
            let q =
                DQuat::from_rotation_x(jitter * next()) * DQuat::from_rotation_y(jitter * next());
            let out = f.push(i as f64 / 30.0, q);
            if i >= settle {
                if let Some(prev) = last {
                    turns.push(out.angle_between(prev));
                }
            }
            last = Some(out);
        }
        turns
    }

    #[test]
    fn a_far_tags_jitter_does_not_open_it() {
        // A face-on tag at 1 m: ±1.5° a frame. Its jitter alone, read as a turn rate, would
        // raise the cut-off to a few hertz; measured against the floor it learnt, it does not.
        let mut f = OrientationFilter::default();
        let turns = rest_turns(&mut f, 1.5f64.to_radians(), 150, 300);
        let mean = turns.iter().sum::<f64>() / turns.len() as f64;
        assert!(
            mean.to_degrees() < 0.25,
            "output turns {:.2}° a frame",
            mean.to_degrees()
        );
        // And a turn after the rest still gets through.
        let mut lag = 0.0;
        let t0 = 15.0;
        for i in 1..=15 {
            let truth = DQuat::from_rotation_y(3.0 * i as f64 / 30.0);
            lag = f.push(t0 + i as f64 / 30.0, truth).angle_between(truth);
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
