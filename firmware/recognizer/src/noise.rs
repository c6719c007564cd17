//! Stage 2½ — is the figurine moving? Against the sensor's noise, learnt from the stream.
//!
//! Trackers range from ~0.3 mm of jitter (Lighthouse) to several millimetres (a webcam tag,
//! worst along the camera's line of sight), at 30–1000 Hz, and a hand adds tremor.
//! Differentiated by the Savitzky–Golay filter, that jitter becomes a velocity that a fixed
//! floor either ignores (the noisy tracker fires at rest) or over-cuts (the quiet tracker
//! loses small doodles). So each vector (world translation, object rotation) is judged
//! against its own noise, learnt in the manner of minimum statistics (Martin 2001) and of a
//! voice-activity detector's noise model (updated only from frames that are not speech):
//!
//! | step | what | why |
//! |---|---|---|
//! | 1 | ticks are grouped into blocks of [`BLOCK_TICKS`] (0.25 s); a block's power is its mean v vᵀ | a pause between strokes is a block of its own |
//! | 2 | a block counts as noise only if both vectors went nowhere: \|Σv\| < [`COHERENCE_MAX`] × Σ\|v\| | jitter and tremor go to and fro, a stroke or a spin goes somewhere, whatever the tracker: a gesture is not learnt as noise |
//! | 3 | the noise is the counted block of median power among the last [`BLOCKS`] counted ones | robust to a stray counted block of a gesture; less biased than the least block where a block holds few independent samples (30 Hz) |
//! | 4 | a vector starts moving when vᵀ C⁻¹ v ≥ 3 × [`ON_FACTOR`]² (\|v\| ≥ [`ON_FACTOR`] × rms for noise alike on all axes) and it heads somewhere (running mean velocity ≥ [`HEADING_SHARE`] × running mean speed); it stays moving down to [`OFF_FACTOR`] | two thresholds (hysteresis); a webcam's depth jitter needs more along the depth only |
//! | 5 | failing that, the slow mean velocity (time constant [`SLOW_TAU_S`]) is judged alike against its own noise power (the mean over the counted blocks), while it is no faster than the vector is now | a sustained motion under heavy jitter stands out once averaged; a stroke that ended lingers in the mean, but the figurine no longer moves that fast |
//!
//! The fixed floors [`V_FLOOR_M_S`] and [`W_FLOOR_RAD_S`] stay as lower bounds; the token's
//! minimum duration ([`crate::token::MIN_TOKEN_US`]) is the hangover. The stream's first
//! block is spent learning (nothing moves before 0.25 s); a changed tracker (a figurine
//! picked up from a table) is learnt within [`BLOCKS`] counted blocks (1.5 s), and a quieter
//! one within half of that. RAM: 2 × 70 f32, about 0.6 KiB.

use crate::fmath;

/// Translation floor, m/s: the least speed that is motion, whatever the tracker.
pub const V_FLOOR_M_S: f32 = 0.07;
/// Rotation floor, rad/s (≈ 34 °/s): the least rate that is turning, whatever the tracker.
pub const W_FLOOR_RAD_S: f32 = 0.6;
/// Ticks per block (0.25 s on the 100 Hz grid).
pub const BLOCK_TICKS: u16 = 25;
/// Counted blocks over which the median power is taken (1.5 s of rest).
pub const BLOCKS: usize = 6;
/// A block whose mean velocity reaches this share of its mean speed (and of the vector's
/// floor) in either vector moved somewhere: it is not noise.
pub const COHERENCE_MAX: f32 = 0.5;
/// Time constant (s) of the running mean velocity and speed that tell, tick by tick, whether a
/// vector goes somewhere: long enough to average out a tremor cycle (8–12 Hz), short beside a
/// stroke.
pub const HEADING_TAU_S: f32 = 0.08;
/// A vector heads somewhere while its running mean velocity is at least this share of its
/// running mean speed.
pub const HEADING_SHARE: f32 = 0.4;
/// Share of the mean per-axis noise variance added on every axis before the covariance is
/// inverted: no tracker is noiseless along any direction, and a near-singular covariance
/// would make the least stray motion along its quiet direction "loud".
pub const ISOTROPIC_SHARE: f32 = 0.1;
/// A resting vector starts moving above this multiple of the noise rms.
pub const ON_FACTOR: f32 = 2.5;
/// A moving vector rests again below this multiple of the noise rms.
pub const OFF_FACTOR: f32 = 1.5;
/// A vector is at rest (quiet) within this multiple of the noise rms: where an event's span
/// begins and ends ([`crate::history::Run::settled`]).
pub const QUIET_FACTOR: f32 = 1.0;
/// Without any noise learnt (a noiseless tracker), a vector is quiet below this share of its
/// floor.
pub const NOISELESS_QUIET_SHARE: f32 = 1e-3;
/// Time constant (s) of the slow mean velocity, which finds motion too slow to stand out of
/// the noise tick by tick: averaging over τ cuts the derivative's noise by about τ / the
/// filter's window, while a steady motion keeps its speed.
pub const SLOW_TAU_S: f32 = 0.2;

/// Per-tick gain of the running means (first order: dt / τ).
const HEADING_GAIN: f32 = crate::intake::TICK_S / HEADING_TAU_S;
/// Per-tick gain of the slow mean velocity.
const SLOW_GAIN: f32 = crate::intake::TICK_S / SLOW_TAU_S;

/// How a vector moves this tick, judged against its noise.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// Within the noise.
    Still,
    /// Louder than the noise tick by tick: its direction is the tick's own.
    Fast,
    /// Within the noise tick by tick, but its slow mean velocity stands out of that mean's
    /// own noise: its direction is the slow mean's.
    Slow,
}

/// A symmetric 3×3 matrix as (xx, yy, zz, xy, xz, yz).
type Sym3 = [f32; 6];

/// The outer product v vᵀ.
fn outer(v: [f32; 3]) -> Sym3 {
    [
        v[0] * v[0],
        v[1] * v[1],
        v[2] * v[2],
        v[0] * v[1],
        v[0] * v[2],
        v[1] * v[2],
    ]
}

/// The inverse of `c` + [`ISOTROPIC_SHARE`] × its mean variance on every axis; `None` for a
/// zero matrix, or one too small to invert in f32.
fn regularised_inverse(c: &Sym3) -> Option<Sym3> {
    let d = ISOTROPIC_SHARE * (c[0] + c[1] + c[2]) / 3.0;
    let [a, e, i, b, cc, f] = [c[0] + d, c[1] + d, c[2] + d, c[3], c[4], c[5]];
    // Adjugate of [[a b c] [b e f] [c f i]].
    let (m00, m11, m22) = (e * i - f * f, a * i - cc * cc, a * e - b * b);
    let (m01, m02, m12) = (cc * f - b * i, b * f - cc * e, b * cc - a * f);
    let det = a * m00 + b * m01 + cc * m02;
    if det <= 0.0 || !fmath::is_finite(det) {
        return None;
    }
    let k = 1.0 / det;
    let inverse = [m00 * k, m11 * k, m22 * k, m01 * k, m02 * k, m12 * k];
    // A noise so small that its inverse overflows is no noise at all.
    inverse
        .iter()
        .all(|&x| fmath::is_finite(x))
        .then_some(inverse)
}

/// vᵀ M v for symmetric M.
fn quadratic(m: &Sym3, v: [f32; 3]) -> f32 {
    m[0] * v[0] * v[0]
        + m[1] * v[1] * v[1]
        + m[2] * v[2] * v[2]
        + 2.0 * (m[3] * v[0] * v[1] + m[4] * v[0] * v[2] + m[5] * v[1] * v[2])
}

/// One vector's block sums and its recent block covariances.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Channel {
    /// Σv over the block (the net motion).
    net: [f32; 3],
    /// Σ|v| over the block (the path).
    path: f32,
    /// Σ v vᵀ over the block.
    power: Sym3,
    /// Mean v vᵀ of the last counted blocks; infinite until counted.
    recent: [Sym3; BLOCKS],
    /// The noise's covariance currently in force (mean v vᵀ); 0 until a block has counted.
    noise: Sym3,
    /// Inverse of the regularised noise covariance; `None` until a block has counted.
    inverse: Option<Sym3>,
    /// The vector's fixed floor (m/s or rad/s).
    least: f32,
    /// Running mean velocity (time constant [`HEADING_TAU_S`]).
    mean_v: [f32; 3],
    /// Running mean speed (same).
    mean_speed: f32,
    /// Slow mean velocity (time constant [`SLOW_TAU_S`]), in the frame the directions are read in.
    slow: [f32; 3],
    /// Σ|slow|² over the block.
    slow_power: f32,
    /// Mean |slow|² of the last counted blocks (paired with `recent`).
    recent_slow: [f32; BLOCKS],
    /// The slow mean's noise power (mean |slow|²) currently in force; 0 until counted.
    slow_noise: f32,
    /// Whether the vector is moving on the strength of its slow mean.
    slow_moving: bool,
}

impl Motion {
    /// Whether the vector moves at all.
    pub fn is_moving(self) -> bool {
        self != Motion::Still
    }
}

impl Channel {
    const fn new(least: f32) -> Self {
        Channel {
            net: [0.0; 3],
            path: 0.0,
            power: [0.0; 6],
            recent: [[f32::INFINITY; 6]; BLOCKS],
            noise: [0.0; 6],
            inverse: None,
            least,
            mean_v: [0.0; 3],
            mean_speed: 0.0,
            slow: [0.0; 3],
            slow_power: 0.0,
            recent_slow: [0.0; BLOCKS],
            slow_noise: 0.0,
            slow_moving: false,
        }
    }

    /// Adds one tick: `v` in the frame the noise is fixed in, `read` (same norm) in the frame
    /// directions are read in.
    fn add(&mut self, v: [f32; 3], norm: f32, read: [f32; 3]) {
        for (m, x) in self.slow.iter_mut().zip(read) {
            *m += SLOW_GAIN * (x - *m);
        }
        self.slow_power += fmath::dot3(self.slow, self.slow);
        for ((n, m), x) in self.net.iter_mut().zip(&mut self.mean_v).zip(v) {
            *n += x;
            *m += HEADING_GAIN * (x - *m);
        }
        for (p, x) in self.power.iter_mut().zip(outer(v)) {
            *p += x;
        }
        self.mean_speed += HEADING_GAIN * (norm - self.mean_speed);
        self.path += norm;
    }

    /// Whether the vector has lately gone somewhere: its running mean velocity is at least
    /// [`HEADING_SHARE`] of its running mean speed (tremor and jitter go to and fro).
    fn heading(&self) -> bool {
        let reach = HEADING_SHARE * self.mean_speed;
        fmath::dot3(self.mean_v, self.mean_v) >= reach * reach
    }

    /// Whether the block went nowhere: its net motion stayed below [`COHERENCE_MAX`] of its
    /// path, or of the path it would have at the floor's speed (slow drift is no gesture).
    fn went_nowhere(&self) -> bool {
        let floor_path = self.least * f32::from(BLOCK_TICKS);
        fmath::norm3(self.net) < COHERENCE_MAX * fmath::max(self.path, floor_path)
    }

    /// Closes a block into slot `slot`, counting it as noise or not. The noise in force is
    /// the counted block of median power (trace) among the last [`BLOCKS`] counted.
    fn close(&mut self, slot: usize, counted: bool) {
        if counted {
            if let Some(r) = self.recent.get_mut(slot) {
                for (r, p) in r.iter_mut().zip(self.power) {
                    *r = p / f32::from(BLOCK_TICKS);
                }
            }
            if let Some(r) = self.recent_slow.get_mut(slot) {
                *r = self.slow_power / f32::from(BLOCK_TICKS);
            }
            let trace = |i: usize| {
                self.recent
                    .get(i)
                    .map_or(f32::INFINITY, |c| c[0] + c[1] + c[2])
            };
            // Blocks by power (uncounted slots, infinite, last; ties by slot, so the order is
            // one and the same on every target); the noise is the lower median.
            let mut order: [usize; BLOCKS] = core::array::from_fn(|i| i);
            order.sort_unstable_by(|&a, &b| trace(a).total_cmp(&trace(b)).then(a.cmp(&b)));
            let known = order
                .iter()
                .filter(|&&i| fmath::is_finite(trace(i)))
                .count();
            let rank = known.saturating_sub(1) / 2;
            let median = order
                .get(rank)
                .and_then(|&i| self.recent.get(i))
                .copied()
                .unwrap_or(self.noise);
            // The slow mean holds about one independent value per block: a median of so few
            // would sit well below its mean power, so the mean over the counted blocks is taken.
            let counted_slow = self
                .recent_slow
                .iter()
                .enumerate()
                .filter(|&(i, _)| fmath::is_finite(trace(i)));
            let (sum, n) = counted_slow.fold((0.0, 0.0), |(s, n), (_, &p)| (s + p, n + 1.0));
            if n > 0.0 {
                self.slow_noise = sum / n;
            }
            self.noise = median;
            self.inverse = regularised_inverse(&median);
        }
        self.net = [0.0; 3];
        self.path = 0.0;
        self.power = [0.0; 6];
        self.slow_power = 0.0;
    }

    /// Whether vector `v` (norm `norm`) moves: above the fixed floor, and louder than the
    /// noise: vᵀ C⁻¹ v ≥ 3k² for the noise covariance C, with k = [`ON_FACTOR`] while heading
    /// somewhere or, if already `moving`, [`OFF_FACTOR`]. For noise alike on every axis this
    /// is |v| ≥ k × rms; a tracker noisier along one direction (a webcam's depth) needs more
    /// along that direction only.
    ///
    /// Failing that, the slow mean velocity is judged alike against its own noise power
    /// (|slow|² ≥ k² × mean |slow|² at rest), as long as it is no faster than the vector is
    /// now: a stroke that ended lingers in the slow mean for a few τ, but the figurine no
    /// longer moves that fast.
    fn moves(&mut self, v: [f32; 3], norm: f32, moving: bool) -> Motion {
        let k = if moving { OFF_FACTOR } else { ON_FACTOR };
        if norm >= self.least
            && self.inverse.is_none_or(|m| quadratic(&m, v) >= 3.0 * k * k)
            && (moving || self.heading())
        {
            self.slow_moving = false;
            return Motion::Fast;
        }
        let k = if self.slow_moving {
            OFF_FACTOR
        } else {
            ON_FACTOR
        };
        let power = fmath::dot3(self.slow, self.slow);
        self.slow_moving = self.slow_noise > 0.0
            && power >= self.least * self.least
            && power <= norm * norm
            && power >= k * k * self.slow_noise;
        if self.slow_moving {
            Motion::Slow
        } else {
            Motion::Still
        }
    }

    /// Whether `v` lies within the noise: vᵀ C⁻¹ v < 3 × [`QUIET_FACTOR`]² (|v| below the
    /// rms for noise alike on all axes).
    fn quiet(&self, v: [f32; 3]) -> bool {
        match &self.inverse {
            Some(m) => quadratic(m, v) < 3.0 * QUIET_FACTOR * QUIET_FACTOR,
            None => {
                let least = NOISELESS_QUIET_SHARE * self.least;
                fmath::dot3(v, v) < least * least
            }
        }
    }

    /// The noise rms (same unit as the vector).
    fn rms(&self) -> f32 {
        fmath::sqrt(self.noise[0] + self.noise[1] + self.noise[2])
    }
}

/// The learnt noise floors of translation (m/s) and rotation (rad/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseFloor {
    lin: Channel,
    ang: Channel,
    ticks: u16,
    slot: usize,
    /// Whether a first block has closed (before that, nothing is known of the sensor).
    primed: bool,
}

impl Default for NoiseFloor {
    fn default() -> Self {
        Self::new()
    }
}

impl NoiseFloor {
    /// No noise learnt yet (both floors 0).
    pub const fn new() -> Self {
        NoiseFloor {
            lin: Channel::new(V_FLOOR_M_S),
            ang: Channel::new(W_FLOOR_RAD_S),
            ticks: 0,
            slot: 0,
            primed: false,
        }
    }

    /// Feeds one tick: world velocity `v` (m/s; a tracker's noise is fixed in the world) with
    /// its norm `vn` and its object-frame twin `ov`, and object-frame angular velocity `w`
    /// (rad/s) with its norm `wn`.
    pub fn push(&mut self, v: [f32; 3], vn: f32, ov: [f32; 3], w: [f32; 3], wn: f32) {
        self.lin.add(v, vn, ov);
        self.ang.add(w, wn, w);
        self.ticks += 1;
        if self.ticks >= BLOCK_TICKS {
            let counted = self.lin.went_nowhere() && self.ang.went_nowhere();
            self.lin.close(self.slot, counted);
            self.ang.close(self.slot, counted);
            self.ticks = 0;
            if counted {
                self.slot = (self.slot + 1) % BLOCKS;
            }
            self.primed = true;
        }
    }

    /// Whether world velocity `v` (m/s, norm `speed`) is motion, given whether the vector
    /// moved at the last tick. The stream's first block is spent learning the sensor: nothing
    /// moves before it closes.
    pub fn translating(&mut self, v: [f32; 3], speed: f32, moving: bool) -> Motion {
        if self.primed {
            self.lin.moves(v, speed, moving)
        } else {
            Motion::Still
        }
    }

    /// Whether angular velocity `w` (rad/s, norm `rate`) is motion; as [`Self::translating`].
    pub fn rotating(&mut self, w: [f32; 3], rate: f32, moving: bool) -> Motion {
        if self.primed {
            self.ang.moves(w, rate, moving)
        } else {
            Motion::Still
        }
    }

    /// Whether the figurine is at rest: world velocity `v` (m/s) and angular velocity `w`
    /// (rad/s) both within their noise (see [`QUIET_FACTOR`]). Stricter than "not moving",
    /// which the hysteresis holds down to [`OFF_FACTOR`]: a slow onset or settle is neither
    /// moving nor quiet.
    pub fn quiet(&self, v: [f32; 3], w: [f32; 3]) -> bool {
        !self.primed || (self.lin.quiet(v) && self.ang.quiet(w))
    }

    /// The slow mean velocity: translation in the object frame (m/s), rotation (rad/s).
    pub fn slow(&self) -> ([f32; 3], [f32; 3]) {
        (self.lin.slow, self.ang.slow)
    }

    /// The learnt noise rms of translation (m/s) and rotation (rad/s).
    pub fn rms(&self) -> (f32, f32) {
        (self.lin.rms(), self.ang.rms())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::intake::TICK_S;

    /// Deterministic roughly-normal numbers (Irwin–Hall: twelve uniforms minus six); the other
    /// modules' tests draw their noise from it too.
    pub(crate) struct Noise(pub(crate) u64);

    impl Noise {
        /// Uniform in [0, 1).
        pub(crate) fn uniform(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }

        fn normal(&mut self) -> f32 {
            (0..12).map(|_| self.uniform()).sum::<f32>() - 6.0
        }

        fn vec(&mut self, sigma: f32) -> [f32; 3] {
            [
                sigma * self.normal(),
                sigma * self.normal(),
                sigma * self.normal(),
            ]
        }
    }

    /// Velocity jitter as the filter makes it: white position noise differentiated by a
    /// least-squares slope over 11 ticks, so neighbouring ticks' velocities are correlated.
    struct Jitter {
        noise: Noise,
        ring: [[f32; 3]; 11],
        at: usize,
    }

    impl Jitter {
        fn new(seed: u64) -> Self {
            Jitter {
                noise: Noise(seed),
                ring: [[0.0; 3]; 11],
                at: 0,
            }
        }

        /// The next tick's velocity jitter, with per-component σ `sigma` (units/s).
        fn vec(&mut self, sigma: f32) -> [f32; 3] {
            // Slope of a line fitted over ticks −5..5: Σ i pᵢ / Σ i², Σ i² = 110.
            let position_sigma = sigma * TICK_S * fmath::sqrt(110.0);
            self.ring[self.at] = self.noise.vec(position_sigma);
            self.at = (self.at + 1) % 11;
            let mut slope = [0.0; 3];
            for k in 0..11 {
                let i = k as f32 - 5.0;
                let p = self.ring[(self.at + k) % 11];
                for (s, x) in slope.iter_mut().zip(p) {
                    *s += i * x / (110.0 * TICK_S);
                }
            }
            slope
        }
    }

    fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
        [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
    }

    /// Feeds `seconds` of ticks with translation `v(t)` and rotation `w(t)`; returns how many
    /// ticks `translating` said moved (judged from rest), and the longest run of them.
    fn feed(
        f: &mut NoiseFloor,
        seconds: f32,
        mut v: impl FnMut(f32) -> [f32; 3],
        mut w: impl FnMut(f32) -> [f32; 3],
    ) -> (usize, usize) {
        let ticks = fmath::round(seconds / TICK_S) as usize;
        let (mut moved, mut run, mut longest) = (0, 0, 0);
        for i in 0..ticks {
            let t = i as f32 * TICK_S;
            let (a, b) = (v(t), w(t));
            let (an, bn) = (fmath::norm3(a), fmath::norm3(b));
            f.push(a, an, a, b, bn);
            if f.translating(a, an, false) != Motion::Still {
                moved += 1;
                run += 1;
                longest = longest.max(run);
            } else {
                run = 0;
            }
        }
        (moved, longest)
    }

    /// Ticks a token must last ([`crate::token::MIN_TOKEN_US`] on the 100 Hz grid).
    const TOKEN_TICKS: usize = 4;

    /// The rms of a white 3-D vector with per-component σ.
    fn rms(sigma: f32) -> f32 {
        fmath::sqrt(3.0) * sigma
    }

    #[test]
    fn nothing_moves_before_the_first_block_closes() {
        let mut f = NoiseFloor::new();
        let x = |s: f32| [s, 0.0, 0.0];
        assert!(
            !f.translating(x(10.0), 10.0, true).is_moving()
                && !f.rotating(x(10.0), 10.0, true).is_moving()
        );
        feed(&mut f, 0.25, |_| [0.0; 3], |_| [0.0; 3]);
        assert!(
            f.translating(x(10.0), 10.0, true).is_moving()
                && f.rotating(x(10.0), 10.0, true).is_moving()
        );
        // Nothing learnt from silence: the fixed floors decide.
        let (lo, hi) = (0.9 * V_FLOOR_M_S, 1.1 * V_FLOOR_M_S);
        assert!(!f.translating(x(lo), lo, true).is_moving());
        assert!(f.translating(x(hi), hi, true).is_moving());
    }

    #[test]
    fn a_noise_too_small_to_invert_leaves_the_fixed_floors_in_charge() {
        // A clean log at rest differentiates to rounding error, not to zero.
        let mut f = NoiseFloor::new();
        let mut n = Noise(3);
        let mut m = Noise(4);
        feed(&mut f, 1.0, |_| n.vec(3e-7), |_| m.vec(3e-7));
        let hi = 1.1 * V_FLOOR_M_S;
        assert!(f.translating([hi, 0.0, 0.0], hi, true).is_moving());
        assert!(f.rotating([0.0, 1.0, 0.0], 1.0, true).is_moving());
    }

    #[test]
    fn white_jitter_is_learnt_and_stays_below_the_motion_threshold() {
        for (seed, sigma) in [(1u64, 0.01f32), (2, 0.05), (3, 0.15)] {
            let mut f = NoiseFloor::new();
            let mut n = Jitter::new(seed);
            let mut m = Jitter::new(seed + 100);
            let (moved, longest) = feed(&mut f, 60.0, |_| n.vec(sigma), |_| m.vec(sigma));
            let (v, w) = f.rms();
            for learnt in [v, w] {
                assert!(
                    learnt > 0.6 * rms(sigma) && learnt < 1.05 * rms(sigma),
                    "σ {sigma}: learnt {learnt}, true rms {}",
                    rms(sigma)
                );
            }
            // Jitter goes to and fro: it seldom heads anywhere (under 1 % of 6,000 ticks), and
            // never for longer than a token's least duration.
            assert!(
                moved < 60 && longest <= TOKEN_TICKS,
                "σ {sigma}: {moved} ticks, {longest} in a row"
            );
        }
    }

    #[test]
    fn a_long_stroke_or_spin_is_never_learnt_as_noise() {
        let mut f = NoiseFloor::new();
        let mut n = Noise(7);
        let mut m = Noise(8);
        feed(&mut f, 3.0, |_| n.vec(0.01), |_| m.vec(0.05));
        let before = f.rms();
        // Five seconds of steady sliding while spinning, on the same jitter.
        let (moved, _) = feed(
            &mut f,
            5.0,
            |_| add([0.0, 0.0, 0.4], n.vec(0.01)),
            |_| add([0.0, 6.0, 0.0], m.vec(0.05)),
        );
        assert_eq!(f.rms(), before);
        assert!(moved >= 495, "{moved} of 500 ticks moved");
        assert!(f.rotating([0.0, 6.0, 0.0], 6.0, true).is_moving());
    }

    #[test]
    fn a_noisier_tracker_is_learnt_within_two_seconds() {
        let mut f = NoiseFloor::new();
        let mut n = Noise(11);
        let mut m = Noise(12);
        // On a table under a quiet tracker, then picked up under a tracker 15× noisier.
        feed(&mut f, 3.0, |_| n.vec(0.004), |_| m.vec(0.02));
        feed(&mut f, 2.0, |_| n.vec(0.06), |_| m.vec(0.3));
        let (v, w) = f.rms();
        assert!(v > 0.6 * rms(0.06), "{v}");
        assert!(w > 0.6 * rms(0.3), "{w}");
        // And back on the table, the quiet floor returns once quiet blocks are the majority.
        feed(&mut f, 1.0, |_| n.vec(0.004), |_| m.vec(0.02));
        assert!(f.rms().0 < 1.05 * rms(0.004), "{:?}", f.rms());
    }

    #[test]
    fn a_slide_too_slow_for_any_one_tick_is_found_by_its_slow_mean() {
        let mut f = NoiseFloor::new();
        let mut n = Jitter::new(21);
        let mut m = Jitter::new(22);
        feed(&mut f, 3.0, |_| n.vec(0.05), |_| m.vec(0.1));
        // 0.1 m/s: under half the tick-by-tick threshold (2.5 × 0.087 m/s rms).
        let slide = [0.0, -0.1, 0.0];
        let (moved, _) = feed(&mut f, 1.0, |_| add(slide, n.vec(0.05)), |_| m.vec(0.1));
        assert!(moved >= 50, "{moved} of 100 ticks moved");
        // Its direction is the slide's.
        let (slow, _) = f.slow();
        assert!(slow[1] < -0.07 && fmath::abs(slow[0]) < 0.03, "{slow:?}");
        // The same jitter alone moves nothing.
        let mut g = NoiseFloor::new();
        let (moved, _) = feed(&mut g, 4.0, |_| n.vec(0.05), |_| m.vec(0.1));
        assert!(moved < 4, "{moved} of 400 ticks moved");
    }

    #[test]
    fn a_stroke_does_not_linger_after_it_ends() {
        let mut f = NoiseFloor::new();
        let mut n = Noise(31);
        let mut m = Noise(32);
        feed(&mut f, 3.0, |_| n.vec(0.01), |_| m.vec(0.05));
        let (moved, _) = feed(
            &mut f,
            0.4,
            |_| add([0.8, 0.0, 0.0], n.vec(0.01)),
            |_| m.vec(0.05),
        );
        assert!(moved >= 38, "{moved}");
        // The slow mean still holds most of the stroke, but the figurine has stopped.
        let (after, _) = feed(&mut f, 0.5, |_| n.vec(0.01), |_| m.vec(0.05));
        assert!(after <= 1, "{after} ticks moved after the stroke");
    }

    #[test]
    fn tremor_does_not_start_motion_where_a_stroke_as_fast_does() {
        let tremor = |t: f32| {
            let s = 0.2 * libm::sinf(core::f32::consts::TAU * 10.0 * t);
            [s, 0.5 * s, 0.0]
        };
        let mut f = NoiseFloor::new();
        assert_eq!(feed(&mut f, 5.0, tremor, |_| [0.0; 3]).1, 0);
        let mut g = NoiseFloor::new();
        feed(&mut g, 1.0, |_| [0.0; 3], |_| [0.0; 3]);
        let (moved, _) = feed(&mut g, 0.3, |_| [0.2, 0.1, 0.0], |_| [0.0; 3]);
        assert!(moved >= 25, "{moved}");
    }
}
