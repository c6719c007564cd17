//! Stage 7 — Laban features (seed 000 §5.2), accumulated in constant memory.
//!
//! Per tick, 27 quantities. The seed's 25: the magnitudes of the 6 object-frame components'
//! velocity, acceleration and jerk (18: |vx| |vy| |vz| |ωx| |ωy| |ωz|, then the same for
//! acceleration and jerk), and 7 world quantities: speed, |acceleration|, |jerk|, curvature,
//! |torsion|, equi-affine velocity `|det(ṙ, r̈, r⃛)|^(1/6)` and the magnitude of its time
//! derivative (equi-affine acceleration). Curvature and torsion are clamped to ±[`GEOM_CLAMP`]
//! where speed vanishes. Two of ours split the tangential acceleration `ṙ·r̈/|ṙ|` into its
//! speeding-up and slowing-down parts: how a stroke *starts* (an explosive or an easing onset:
//! Time) and how it *stops* (an impact or a fade: Weight) are what Laban observers look at,
//! and the seed's unsigned magnitudes mix the two. Two more split the angular acceleration
//! along the spin, `ω·ω̇/|ω|`, the same way: a bow, a turn or a wave is a twist, whose impact
//! or fade no translation quantity sees.
//!
//! [`Accum`] keeps count, Σx and Σx² per quantity (one per token run: any segment's statistics
//! are the sum of its runs' accumulators), and how far the figurine rose and how high it was
//! over the ticks, from which a span's [`Shape`] follows ([`ShapeSums`]).
//! [`segment_features`] turns an accumulator into the 58 features — the mean of each
//! quantity, then its *relative* spread (standard deviation over mean, the coefficient of
//! variation) — in the log domain `ln(FEATURE_EPS + x)`, where Gaussian naive Bayes fits much
//! better than on the raw, heavy-tailed values. Means carry the
//! tempo (they are rates per second once divided by the mean speed); the relative spread is
//! free of both size and duration and carries the shape of the effort: accelerations
//! concentrated in a short impact spread far more than evenly eased ones. The seed's plain
//! standard deviation is, in the log domain, the sum of the two and adds nothing a naive
//! Bayes classifier could use that they do not — but it confounds tempo and shape.

use crate::fmath;
use crate::frame::Kinematics;
use crate::intake::TICK_S;

/// Per-tick quantities.
pub const QUANTITIES: usize = 29;
/// Index of the world speed (m/s) among the quantities; 0, 1, 2 are |velocity| along the
/// object's left, up and front axes.
pub const SPEED: usize = 18;
/// Index of |angular velocity| about the object's x axis (rad/s) among the quantities; y and z
/// follow.
pub const ANGVEL: usize = 3;
/// Floor of a mean world speed (m/s) wherever one divides by it: 1 mm/s.
pub const SPEED_FLOOR: f32 = 1e-3;
/// Segment features: mean and relative spread of each quantity.
pub const FEATURES: usize = 2 * QUANTITIES;
/// Bound on |curvature| (1/m) and |torsion| (1/m).
pub const GEOM_CLAMP: f32 = 1000.0;
/// Offset inside the log transform of features.
pub const FEATURE_EPS: f32 = 1e-4;
/// Floor of a quantity's mean when dividing its standard deviation by it (a quantity that
/// stayed 0 throughout then has relative spread 0, not NaN).
pub const MEAN_FLOOR: f32 = 1e-6;

/// Short names of the quantities, in order (features `i` and `QUANTITIES + i` are their mean
/// and relative spread).
pub const QUANTITY_NAMES: [&str; QUANTITIES] = [
    "vel.left",
    "vel.up",
    "vel.front",
    "angvel.x",
    "angvel.y",
    "angvel.z",
    "acc.left",
    "acc.up",
    "acc.front",
    "angacc.x",
    "angacc.y",
    "angacc.z",
    "jerk.left",
    "jerk.up",
    "jerk.front",
    "angjerk.x",
    "angjerk.y",
    "angjerk.z",
    "world.speed",
    "world.acc",
    "world.jerk",
    "curvature",
    "torsion",
    "equiaffine.vel",
    "equiaffine.acc",
    "world.speedup",
    "world.slowdown",
    "ang.speedup",
    "ang.slowdown",
];

/// World displacement one unit of [`Accum::moved`] stands for, m (0.05 mm: a run of ±1.6 m).
pub const MOVED_UNIT_M: f32 = 5.0e-5;
/// Rotation one unit of [`Accum::turned`] stands for, rad (0.5 mrad: a run of ±16 rad).
pub const TURNED_UNIT_RAD: f32 = 5.0e-4;

/// 1.5 × 2²³: adding and then subtracting it leaves a float of magnitude under 2²² rounded to
/// the nearest integer (ties to even), in two plain additions.
const ROUNDER: f32 = 12_582_912.0;

/// `x` × `per_unit`, rounded to the nearest integer: the units of `x`, saturating at the ends
/// of `i16` (NaN is 0).
#[inline(always)]
fn units(x: f32, per_unit: f32) -> i16 {
    // Six times a tick, so cheap on the MCU: two additions rather than a call to `roundf`, a
    // cast to i32 (one saturating instruction) and a clamp (one more) rather than a cast to
    // i16 (three comparisons).
    let n = ((x * per_unit + ROUNDER) - ROUNDER) as i32;
    n.clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16
}

/// Sums over a set of ticks, in order. 256 bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accum {
    /// Number of ticks.
    pub n: u32,
    /// Σ x per quantity.
    pub sum: [f32; QUANTITIES],
    /// Σ x² per quantity.
    pub sum_sq: [f32; QUANTITIES],
    /// How far the figurine rose over the ticks (world up), m.
    pub rise: f32,
    /// Σ over the ticks of the height after each, above where the first began, m·ticks:
    /// whether the motion went up and came back (a jump) or down and came back (a crouch).
    pub lift: f32,
    /// World displacement over the ticks of motion ([`Accum::travel`]), [`MOVED_UNIT_M`]
    /// (each tick rounded, saturating): with [`Accum::turned`], how far a gesture went
    /// ([`crate::extent`]). Fixed point keeps the 40 runs of the history within the RAM
    /// budget.
    pub moved: [i16; 3],
    /// Rotation over the ticks of motion about the object's axes, [`TURNED_UNIT_RAD`] (each
    /// tick rounded, saturating).
    pub turned: [i16; 3],
}

impl Default for Accum {
    fn default() -> Self {
        Self::new()
    }
}

impl Accum {
    /// Empty sums.
    pub const fn new() -> Self {
        Accum {
            n: 0,
            sum: [0.0; QUANTITIES],
            sum_sq: [0.0; QUANTITIES],
            rise: 0.0,
            lift: 0.0,
            moved: [0; 3],
            turned: [0; 3],
        }
    }

    /// Adds one tick's quantities after the ticks already added; the figurine rose `rise` m
    /// (world up) during it.
    pub fn add(&mut self, q: &[f32; QUANTITIES], rise: f32) {
        self.rise += rise;
        self.lift += self.rise;
        self.n = self.n.saturating_add(1);
        for ((s, s2), &x) in self.sum.iter_mut().zip(self.sum_sq.iter_mut()).zip(q) {
            *s += x;
            *s2 += x * x;
        }
    }

    /// Adds how far a tick of motion carried the figurine: its world velocity `v` (m/s) and
    /// its angular velocity `w` about its own axes (rad/s), over one tick. The front end calls
    /// it for the ticks of moving runs only: a still run's drift is the tracker's and the
    /// hand's, not the gesture's (and it spares the MCU the work on most ticks).
    pub fn travel(&mut self, v: [f32; 3], w: [f32; 3]) {
        for k in 0..3 {
            let moved = units(v[k], TICK_S / MOVED_UNIT_M);
            let turned = units(w[k], TICK_S / TURNED_UNIT_RAD);
            self.moved[k] = self.moved[k].saturating_add(moved);
            self.turned[k] = self.turned[k].saturating_add(turned);
        }
    }

    /// Adds another accumulator, whose ticks came after these.
    // Out of line: merges happen at run joins and commits, not per tick, and each inlined
    // copy costs flash.
    #[inline(never)]
    pub fn merge(&mut self, o: &Accum) {
        append_height(&mut self.rise, &mut self.lift, o);
        self.n = self.n.saturating_add(o.n);
        for k in 0..3 {
            self.moved[k] = self.moved[k].saturating_add(o.moved[k]);
            self.turned[k] = self.turned[k].saturating_add(o.turned[k]);
        }
        for i in 0..QUANTITIES {
            if let (Some(s), Some(s2), Some(x), Some(x2)) = (
                self.sum.get_mut(i),
                self.sum_sq.get_mut(i),
                o.sum.get(i),
                o.sum_sq.get(i),
            ) {
                *s += x;
                *s2 += x2;
            }
        }
    }
}

/// Appends the ticks of `o` to a rise (m) and lift (m·ticks) summed over earlier ticks: every
/// height `o` measured from its own start lies `rise` higher for the whole.
#[inline(always)]
fn append_height(rise: &mut f32, lift: &mut f32, o: &Accum) {
    *lift += o.lift + *rise * o.n as f32;
    *rise += o.rise;
}

/// Scale exponent of each quantity: its value is divided by `mean speed` (linear rates) or
/// multiplied by the path length (curvature, torsion), or divided by √path (equi-affine), so
/// the features do not change when the same gesture is made larger or smaller. The mean world
/// speed itself (feature 18) stays absolute: the one feature that knows the size.
const SCALE_KIND: [u8; QUANTITIES] = [
    1, 1, 1, 0, 0, 0, 1, 1, 1, 0, 0, 0, 1, 1, 1, 0, 0, 0, 1, 1, 1, 2, 2, 3, 3, 1, 1, 0, 0,
];

/// The log-domain, scale-free features of a segment: means (each divided or multiplied by its
/// scale, so that size does not matter; the mean world speed stays absolute), then
/// coefficients of variation.
pub fn segment_features(a: &Accum) -> [f32; FEATURES] {
    let mut out = [fmath::ln(FEATURE_EPS); FEATURES];
    if a.n == 0 {
        return out;
    }
    let n = a.n as f32;
    let speed = fmath::max(a.sum[SPEED] / n, SPEED_FLOOR);
    let path = fmath::max(speed * n * TICK_S, 1e-3);
    for i in 0..QUANTITIES {
        let mean = a.sum[i] / n;
        let var = fmath::max(a.sum_sq[i] / n - mean * mean, 0.0);
        // The mean world speed itself stays absolute: the one feature that knows the size.
        let k = match SCALE_KIND[i] {
            _ if i == SPEED => 1.0,
            1 => 1.0 / speed,
            2 => path,
            3 => 1.0 / fmath::sqrt(path),
            _ => 1.0,
        };
        out[i] = fmath::ln(FEATURE_EPS + fmath::max(mean, 0.0) * k);
        out[QUANTITIES + i] =
            fmath::ln(FEATURE_EPS + fmath::sqrt(var) / fmath::max(mean, MEAN_FLOOR));
    }
    out
}

/// The motion shape of `n` ticks whose |velocity| along the object's left, up and front axes
/// sums to `sums` and whose world speed sums to `speed`: each as a share of the speed
/// (floored at [`SPEED_FLOOR`]). What an action's examples and a match are compared by
/// (`shape::shape_penalty`).
pub fn motion_shape(sums: [f32; 3], speed: f32, n: u32) -> [f32; 3] {
    let speed = fmath::max(speed, SPEED_FLOOR * n as f32);
    sums.map(|s| s / speed)
}

/// Dimensions of a [`Shape`].
pub const SHAPE_DIMS: usize = 6;

/// How a span of motion moved, whatever its size, speed and place: mean |velocity| along the
/// object's left, up and front axes, each as a share of the mean speed ([`motion_shape`]);
/// `ln(1 + angle turned)` (rad, the three axes' turning combined: a kick's lean, a throw's
/// swing and a punch's twist differ in it where their strokes do not); and the share of its
/// time spent still (a crouch is held low, a jump is not); and how high it was on average
/// (world up, above where it began, over its duration) as a share of its path length —
/// positive for a jump, negative for a crouch, whose strokes alone may read alike.
pub type Shape = [f32; SHAPE_DIMS];

/// Sums over a span of token runs from which its [`Shape`] follows.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ShapeSums {
    lin: [f32; 3],
    turn: [f32; 3],
    speed: f32,
    ticks: u32,
    still: u32,
    height: f32,
    lift: f32,
}

impl ShapeSums {
    /// Nothing summed.
    pub const fn new() -> Self {
        ShapeSums {
            lin: [0.0; 3],
            turn: [0.0; 3],
            speed: 0.0,
            ticks: 0,
            still: 0,
            height: 0.0,
            lift: 0.0,
        }
    }

    /// Adds a run's sums (the run after those added); `still`: the run is STILL.
    pub fn add(&mut self, acc: &Accum, still: bool) {
        append_height(&mut self.height, &mut self.lift, acc);
        for k in 0..3 {
            self.lin[k] += acc.sum[k];
            self.turn[k] += acc.sum[ANGVEL + k];
        }
        self.speed += acc.sum[SPEED];
        self.ticks = self.ticks.saturating_add(acc.n);
        if still {
            self.still = self.still.saturating_add(acc.n);
        }
    }

    /// The shape of what was added.
    pub fn shape(&self) -> Shape {
        let [l, u, f] = motion_shape(self.lin, self.speed, self.ticks);
        let angle = TICK_S * fmath::norm3(self.turn);
        let ticks = fmath::max(self.ticks as f32, 1.0);
        let still = self.still as f32 / ticks;
        // Mean height / path: lift (m·ticks) / (Σ speed (m/s·ticks) · TICK_S · ticks).
        let path = fmath::max(self.speed, SPEED_FLOOR * ticks) * TICK_S;
        let height = self.lift / (path * ticks);
        [l, u, f, fmath::ln(1.0 + angle), still, height]
    }
}

impl Accum {
    /// Σ over the ticks of |ω| about the three object axes, rad/s (× [`TICK_S`]: the angle
    /// turned, rad, counting each axis).
    pub fn turn_sum(&self) -> f32 {
        self.sum[ANGVEL] + self.sum[ANGVEL + 1] + self.sum[ANGVEL + 2]
    }
}

/// Computes per-tick quantities; remembers the previous equi-affine velocity.
#[derive(Debug, Clone, Default)]
pub struct FeatureExtractor {
    prev_va: Option<f32>,
}

fn abs3(v: [f32; 3]) -> [f32; 3] {
    [fmath::abs(v[0]), fmath::abs(v[1]), fmath::abs(v[2])]
}

impl FeatureExtractor {
    /// A fresh extractor.
    pub const fn new() -> Self {
        FeatureExtractor { prev_va: None }
    }

    /// Forgets the previous tick (after a gap).
    pub fn reset(&mut self) {
        self.prev_va = None;
    }

    /// The quantities of one tick (all finite and ≥ 0).
    pub fn quantities(&mut self, k: &Kinematics) -> [f32; QUANTITIES] {
        let mut q = [0.0f32; QUANTITIES];
        let groups = [k.v, k.w, k.a, k.wa, k.j, k.wj];
        for (g, v) in groups.iter().enumerate() {
            let a = abs3(*v);
            q[3 * g..3 * g + 3].copy_from_slice(&a);
        }
        let (v, a, j) = (k.world_v, k.world_a, k.world_j);
        let speed = fmath::norm3(v);
        let va_cross = fmath::cross3(v, a);
        let cross_n = fmath::norm3(va_cross);
        let det = fmath::dot3(va_cross, j);
        let curvature = if speed > 1e-4 {
            cross_n / (speed * speed * speed)
        } else {
            0.0
        };
        let torsion = if cross_n > 1e-6 {
            det / (cross_n * cross_n)
        } else {
            0.0
        };
        let eq_v = fmath::sqrt(fmath::cbrt(fmath::abs(det)));
        let eq_a = match self.prev_va {
            Some(p) => fmath::abs(eq_v - p) / TICK_S,
            None => 0.0,
        };
        self.prev_va = Some(eq_v);
        q[SPEED] = speed;
        q[19] = fmath::norm3(a);
        q[20] = fmath::norm3(j);
        q[21] = fmath::clamp(curvature, 0.0, GEOM_CLAMP);
        q[22] = fmath::clamp(fmath::abs(torsion), 0.0, GEOM_CLAMP);
        q[23] = eq_v;
        q[24] = eq_a;
        // Along the path: > 0 speeding up, < 0 slowing down.
        let tangential = if speed > 1e-4 {
            fmath::dot3(v, a) / speed
        } else {
            0.0
        };
        q[25] = fmath::max(tangential, 0.0);
        q[26] = fmath::max(-tangential, 0.0);
        // The same split for the twist: how a turn or a bow starts and stops.
        let spin = fmath::norm3(k.w);
        let angular = if spin > 1e-3 {
            fmath::dot3(k.w, k.wa) / spin
        } else {
            0.0
        };
        q[27] = fmath::max(angular, 0.0);
        q[28] = fmath::max(-angular, 0.0);
        for x in &mut q {
            if !fmath::is_finite(*x) {
                *x = 0.0;
            }
        }
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intake::Tick;

    #[test]
    fn a_shape_has_the_shares_the_turn_and_the_time_held() {
        // 30 ticks moving up-and-forward at 0.6 / 0.8 m/s while pitching at 2 rad/s (rising
        // 0.6 m/s in the world too), then 10 ticks held still up there.
        let mut moving = Accum::new();
        let mut q = [0.0; QUANTITIES];
        q[1] = 0.6;
        q[2] = 0.8;
        q[ANGVEL] = 2.0;
        q[SPEED] = 1.0;
        for _ in 0..30 {
            moving.add(&q, 0.6 * TICK_S);
        }
        let mut held = Accum::new();
        for _ in 0..10 {
            held.add(&[0.0; QUANTITIES], 0.0);
        }
        let mut sums = ShapeSums::new();
        sums.add(&moving, false);
        sums.add(&held, true);
        let s = sums.shape();
        // Height: Σ 0.006·i over the 30 rising ticks (2.79 m·ticks) and 10 ticks at 0.18 m
        // (1.8), over 40 ticks — 0.11475 m on average — as a share of the 0.3 m path.
        let want = [
            0.0,
            0.6,
            0.8,
            libm::logf(1.0 + 30.0 * TICK_S * 2.0),
            0.25,
            0.11475 / 0.3,
        ];
        for (got, want) in s.iter().zip(want) {
            assert!((got - want).abs() < 1e-5, "{s:?}");
        }
        // Nothing added: no shares of a speed that is not there (NaN: no evidence, which
        // `shape::shape_penalty` charges nothing for), no turn, nothing held, no height.
        let empty = ShapeSums::new().shape();
        assert!(empty[..3].iter().all(|x| x.is_nan()), "{empty:?}");
        assert_eq!(empty[3..], [0.0, 0.0, 0.0]);
    }

    /// The ticks of a vertical stroke of `ticks` ticks that moves `dy` m (up if positive) at
    /// an even speed, added one by one to `acc`.
    fn stroke(acc: &mut Accum, ticks: u32, dy: f32) {
        let mut q = [0.0; QUANTITIES];
        let v = dy / (ticks as f32 * TICK_S);
        q[1] = libm::fabsf(v);
        q[SPEED] = libm::fabsf(v);
        for _ in 0..ticks {
            acc.add(&q, v * TICK_S);
        }
    }

    /// Height of runs (strokes of (ticks, dy, held)) one after the other.
    fn height(runs: &[(u32, f32, bool)]) -> f32 {
        let mut sums = ShapeSums::new();
        for &(ticks, dy, held) in runs {
            let mut acc = Accum::new();
            if held {
                for _ in 0..ticks {
                    acc.add(&[0.0; QUANTITIES], 0.0);
                }
            } else {
                stroke(&mut acc, ticks, dy);
            }
            sums.add(&acc, held);
        }
        sums.shape()[5]
    }

    #[test]
    fn a_jump_is_high_and_a_crouch_low_whatever_their_size() {
        // A jump: a small dip, a flight up and back down, a small rise after landing.
        let jump = |k: f32| {
            height(&[
                (20, -0.02 * k, false),
                (30, 0.25 * k, false),
                (30, -0.25 * k, false),
                (20, 0.02 * k, false),
            ])
        };
        // A crouch: down, held low, up.
        let crouch =
            |k: f32| height(&[(40, -0.1 * k, false), (50, 0.0, true), (50, 0.1 * k, false)]);
        assert!(jump(1.0) > 0.1, "{}", jump(1.0));
        assert!(crouch(1.0) < -0.2, "{}", crouch(1.0));
        for k in [0.5, 2.0] {
            assert!((jump(k) - jump(1.0)).abs() < 1e-5);
            assert!((crouch(k) - crouch(1.0)).abs() < 1e-5);
        }
    }

    #[test]
    fn merging_accumulators_in_order_is_adding_their_ticks() {
        // Height sums depend on the order of the ticks: a merge appends.
        let mut whole = Accum::new();
        stroke(&mut whole, 7, 0.3);
        stroke(&mut whole, 5, -0.1);
        let mut a = Accum::new();
        stroke(&mut a, 7, 0.3);
        let mut b = Accum::new();
        stroke(&mut b, 5, -0.1);
        a.merge(&b);
        assert_eq!(a.n, whole.n);
        assert!((a.rise - whole.rise).abs() < 1e-6);
        assert!(
            (a.lift - whole.lift).abs() < 1e-5,
            "{} vs {}",
            a.lift,
            whole.lift
        );
    }

    fn kin(v: [f32; 3], a: [f32; 3], j: [f32; 3]) -> Kinematics {
        Kinematics {
            tick: Tick {
                t_us: 0,
                pos: [0.0; 3],
                quat: [1.0, 0.0, 0.0, 0.0],
                seq: 0,
                sample_t_us: 0,
            },
            v,
            a,
            j,
            w: [0.0; 3],
            wa: [0.0; 3],
            wj: [0.0; 3],
            world_v: v,
            world_a: a,
            world_j: j,
        }
    }

    #[test]
    fn circle_has_curvature_one_over_radius() {
        // Uniform circle radius 0.5 m at 2 m/s: a = v²/r towards the centre.
        let mut fx = FeatureExtractor::new();
        let q = fx.quantities(&kin([2.0, 0.0, 0.0], [0.0, 8.0, 0.0], [-32.0, 0.0, 0.0]));
        assert!((q[21] - 2.0).abs() < 1e-4, "{}", q[21]);
        assert!(q[22].abs() < 1e-4);
        assert!((q[18] - 2.0).abs() < 1e-6);
    }

    #[test]
    fn helix_has_torsion_and_equiaffine_velocity() {
        let mut fx = FeatureExtractor::new();
        let q = fx.quantities(&kin([0.0, 1.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]));
        assert!(q[22] > 0.1);
        assert!(q[23] > 0.0);
        let q2 = fx.quantities(&kin([0.0; 3], [0.0; 3], [0.0; 3]));
        assert_eq!(q2[21], 0.0);
        assert!(q2[24] > 0.0, "equi-affine acceleration from the drop");
    }

    #[test]
    fn tangential_acceleration_splits_into_speeding_up_and_slowing_down() {
        let mut fx = FeatureExtractor::new();
        // Moving along +x at 1 m/s, accelerating 3 m/s² forwards and 4 m/s² sideways.
        let q = fx.quantities(&kin([1.0, 0.0, 0.0], [3.0, 4.0, 0.0], [0.0; 3]));
        assert!((q[25] - 3.0).abs() < 1e-5 && q[26] == 0.0, "{q:?}");
        let q = fx.quantities(&kin([1.0, 0.0, 0.0], [-2.0, 4.0, 0.0], [0.0; 3]));
        assert!(q[25] == 0.0 && (q[26] - 2.0).abs() < 1e-5, "{q:?}");
        // At rest there is no path to be along.
        let q = fx.quantities(&kin([0.0; 3], [5.0, 0.0, 0.0], [0.0; 3]));
        assert!(q[25] == 0.0 && q[26] == 0.0);
    }

    #[test]
    fn angular_acceleration_splits_along_the_spin() {
        let mut fx = FeatureExtractor::new();
        let mut k = kin([0.0; 3], [0.0; 3], [0.0; 3]);
        // Spinning at 2 rad/s about the object's y axis, slowing by 5 rad/s² while also
        // tilting the spin axis (3 rad/s² about x, which neither starts nor stops the spin).
        k.w = [0.0, 2.0, 0.0];
        k.wa = [3.0, -5.0, 0.0];
        let q = fx.quantities(&k);
        assert!(q[27] == 0.0 && (q[28] - 5.0).abs() < 1e-5, "{q:?}");
        k.w = [0.0, -2.0, 0.0];
        let q = fx.quantities(&k);
        assert!((q[27] - 5.0).abs() < 1e-5 && q[28] == 0.0, "{q:?}");
        // No spin, no axis to be along; linear quantities are untouched by the twist.
        k.w = [0.0; 3];
        let q = fx.quantities(&k);
        assert!(q[27] == 0.0 && q[28] == 0.0 && q[25] == 0.0 && q[26] == 0.0);
    }

    #[test]
    fn an_impact_spreads_its_slowing_down_more_than_a_fade() {
        // Same stroke, same total slowing down (1 m/s over the segment): once over 2 ticks
        // (an impact) or evenly over 20 (a fade).
        let seg = |ticks: usize| {
            let mut a = Accum::new();
            let mut q = [0.0; QUANTITIES];
            q[18] = 1.0;
            for i in 0..20 {
                q[26] = if i < ticks {
                    1.0 / (ticks as f32 * TICK_S)
                } else {
                    0.0
                };
                a.add(&q, 0.0);
            }
            segment_features(&a)[QUANTITIES + 26]
        };
        assert!(seg(2) > seg(20) + 1.0, "{} vs {}", seg(2), seg(20));
    }

    #[test]
    fn accumulated_mean_and_std() {
        let mut a = Accum::new();
        let mut q = [0.0; QUANTITIES];
        for x in [1.0f32, 3.0] {
            q[0] = x;
            a.add(&q, 0.0);
        }
        let f = segment_features(&a);
        // Mean relative to the (floored) mean speed of 1e-3 m/s; spread relative to the mean.
        assert!((f[0] - libm::logf(FEATURE_EPS + 2.0e3)).abs() < 1e-4);
        assert!((f[QUANTITIES] - libm::logf(FEATURE_EPS + 0.5)).abs() < 1e-4);
        // A quantity that never moved: spread 0, not NaN.
        assert_eq!(f[QUANTITIES + 1], libm::logf(FEATURE_EPS));
        assert_eq!(segment_features(&Accum::new())[3], libm::logf(FEATURE_EPS));
    }
}
