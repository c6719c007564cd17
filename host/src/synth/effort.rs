//! Laban effort shaping: how Time (sudden/sustained) and Weight (strong/light) change a stroke.
//!
//! Seed 000 §5 describes the two effort dimensions the recognizer must tell apart; the
//! generator renders them into the kinematics of each stroke (one continuous movement of a
//! gesture, e.g. one hop or one thrust):
//!
//! * **Time** sets the stroke's duration and its *onset*. Sudden strokes are short
//!   (×0.45–0.7 of the neutral duration) and start explosively (the velocity profile rises
//!   almost at once); sustained strokes are long (×1.5–2.4) and ease in gently.
//! * **Weight** sets the stroke's amplitude and its *ending*. Strong strokes are bigger
//!   (×1.15–1.45), arrive with speed and stop in an impact (a damped overshoot), so their
//!   accelerations are large and concentrated; light strokes are smaller (×0.6–0.85) and fade out
//!   delicately, with small, evenly spread accelerations. Following the Effort–Shape affinities
//!   of seed 000 §5.1, strong hops are also relatively flatter (sinking) and light ones higher
//!   (rising).
//!
//! The velocity profile of a stroke is a Beta-shaped bump `v(τ) ∝ τ^a (1−τ)^b` over normalised
//! time τ ∈ [0, 1]: `a` (onset, 1–1.4 sudden, 1.9–2.9 sustained) comes from Time, `b` (ending,
//! 1–1.5 strong, 2.2–3.4 light) and the impact cut (strong only) from Weight. Its integral, the
//! progress `s(τ)` from 0 to 1, drives every displacement and rotation of the stroke. The
//! classic combinations come out as Laban's drives: sudden+strong ≈ punch, sudden+light ≈ flick,
//! sustained+strong ≈ press, sustained+light ≈ glide/float.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::rng::SynthRng;

/// Laban Time class of a performance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TimeClass {
    /// Quick, impulsive (Lt > 0).
    Sudden,
    /// Slow, lingering (Lt < 0).
    Sustained,
    /// Neither (ordinary tempo); only used for unlabelled learning examples.
    Neutral,
}

/// Laban Weight class of a performance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WeightClass {
    /// Forceful, heavy (Lw > 0).
    Strong,
    /// Delicate, buoyant (Lw < 0).
    Light,
    /// Neither (ordinary force); only used for unlabelled learning examples.
    Neutral,
}

/// An effort combination (Time × Weight).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Effort {
    /// Time class.
    pub time: TimeClass,
    /// Weight class.
    pub weight: WeightClass,
}

impl Effort {
    /// The four labelled states, in the order of the `train-effort` folders.
    pub const STATES: [Effort; 4] = [
        Effort::new(TimeClass::Sudden, WeightClass::Strong),
        Effort::new(TimeClass::Sudden, WeightClass::Light),
        Effort::new(TimeClass::Sustained, WeightClass::Strong),
        Effort::new(TimeClass::Sustained, WeightClass::Light),
    ];

    /// Ordinary tempo and force.
    pub const NEUTRAL: Effort = Effort::new(TimeClass::Neutral, WeightClass::Neutral);

    /// An effort from its two classes.
    pub const fn new(time: TimeClass, weight: WeightClass) -> Self {
        Self { time, weight }
    }

    /// One of the four labelled states, uniformly at random.
    pub fn random_state(rng: &mut SynthRng) -> Self {
        Self::STATES[rng.index(Self::STATES.len())]
    }

    /// Folder / CLI name, e.g. `sudden-strong`, or `neutral`.
    pub fn name(self) -> String {
        match (self.time, self.weight) {
            (TimeClass::Neutral, WeightClass::Neutral) => "neutral".into(),
            (t, w) => format!("{}-{}", time_name(t), weight_name(w)),
        }
    }

    /// Draws the stroke-shaping parameters for one performance with this effort.
    pub fn shape(self, rng: &mut SynthRng) -> EffortShape {
        // Draw every value whatever the class, so the stream position never depends on it.
        let tf = rng.unit();
        let onset = rng.unit();
        let amp = rng.unit();
        let ending = rng.unit();
        let ring = rng.unit();
        let lift = rng.unit();
        let lerp = |lo: f64, hi: f64, u: f64| lo + (hi - lo) * u;
        let (time_factor, a) = match self.time {
            TimeClass::Sudden => (lerp(0.45, 0.7, tf), lerp(1.0, 1.4, onset)),
            TimeClass::Sustained => (lerp(1.5, 2.4, tf), lerp(1.9, 2.9, onset)),
            TimeClass::Neutral => (lerp(0.85, 1.2, tf), lerp(1.4, 1.9, onset)),
        };
        let (amplitude, b, impact, lift) = match self.weight {
            WeightClass::Strong => (
                lerp(1.15, 1.45, amp),
                lerp(1.0, 1.5, ending),
                // A sudden strong stroke hits (arrives at full speed); a sustained one presses
                // on and stops firmly.
                if self.time == TimeClass::Sustained {
                    lerp(0.1, 0.2, ring)
                } else {
                    lerp(0.25, 0.4, ring)
                },
                lerp(0.8, 0.95, lift),
            ),
            WeightClass::Light => (
                lerp(0.6, 0.85, amp),
                lerp(2.2, 3.4, ending),
                0.0,
                lerp(1.1, 1.3, lift),
            ),
            WeightClass::Neutral => (lerp(0.9, 1.1, amp), lerp(1.4, 1.9, ending), 0.0, 1.0),
        };
        EffortShape {
            time_factor,
            amplitude,
            lift,
            profile: Profile::new(a, b, impact),
        }
    }
}

fn time_name(t: TimeClass) -> &'static str {
    match t {
        TimeClass::Sudden => "sudden",
        TimeClass::Sustained => "sustained",
        TimeClass::Neutral => "neutral",
    }
}

fn weight_name(w: WeightClass) -> &'static str {
    match w {
        WeightClass::Strong => "strong",
        WeightClass::Light => "light",
        WeightClass::Neutral => "neutral",
    }
}

impl fmt::Display for Effort {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

impl FromStr for Effort {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim().to_ascii_lowercase();
        if s == "neutral" {
            return Ok(Self::NEUTRAL);
        }
        let (t, w) = s.split_once('-').ok_or_else(|| {
            format!("unknown effort `{s}`: expected sudden|sustained-strong|light, or neutral")
        })?;
        let time = match t {
            "sudden" => TimeClass::Sudden,
            "sustained" => TimeClass::Sustained,
            _ => {
                return Err(format!(
                    "unknown Time class `{t}`: expected sudden or sustained"
                ))
            }
        };
        let weight = match w {
            "strong" => WeightClass::Strong,
            "light" => WeightClass::Light,
            _ => {
                return Err(format!(
                    "unknown Weight class `{w}`: expected strong or light"
                ))
            }
        };
        Ok(Self::new(time, weight))
    }
}

/// Per-performance stroke shaping drawn from an [`Effort`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EffortShape {
    /// Multiplier of every stroke's neutral duration (dimensionless).
    pub time_factor: f64,
    /// Multiplier of every stroke's translation amplitude (dimensionless).
    pub amplitude: f64,
    /// Extra multiplier of upward arcs (hop heights): strong sinks (0.8–0.95), light rises
    /// (1.1–1.3), after Bishko's Effort–Shape affinities cited in seed 000 §5.1.
    pub lift: f64,
    /// Velocity profile of each stroke.
    pub profile: Profile,
}

/// Added to the ending exponent of recovery strokes.
pub const RECOVERY_EASE: f64 = 0.8;

/// Number of points of the tabulated progress curve of a [`Profile`].
const PROFILE_TABLE: usize = 257;

/// Time an impact takes to settle, seconds: a hand stopping a toy hard decelerates within
/// ~20 ms (the first quarter cycle) and the bounce dies out in ~0.1 s, however long the stroke.
pub const IMPACT_SETTLE_S: f64 = 0.1;
/// Bounds of the settle's share of a stroke (very short or very long strokes).
const SETTLE_FRACTION_RANGE: (f64, f64) = (0.05, 0.5);

/// Share of a stroke of `duration_s` seconds spent settling after an impact.
fn settle_fraction(duration_s: f64) -> f64 {
    if duration_s.is_finite() && duration_s > 0.0 {
        (IMPACT_SETTLE_S / duration_s).clamp(SETTLE_FRACTION_RANGE.0, SETTLE_FRACTION_RANGE.1)
    } else {
        SETTLE_FRACTION_RANGE.1
    }
}
/// Damped cycles of the settle (per settle phase).
const SETTLE_CYCLES: f64 = 1.25;
/// Exponential decay of the settle over its phase (e^-5 ≈ 0.7 % left).
const SETTLE_DECAY: f64 = 5.0;

/// A stroke's velocity profile: a Beta bump `τ^a (1−τ)^b`, optionally cut short by an impact.
///
/// With `impact` > 0 the bump is cut at `1 − impact` of its course and stretched to reach the
/// end point there, so the figurine arrives with speed and stops in a short damped bounce about
/// the end point lasting [`IMPACT_SETTLE_S`] whatever the stroke's length (position and velocity continuous; the deceleration is large but finite, so
/// sampled accelerations do not grow without bound with the sample rate).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    /// Onset exponent (near 1 = the velocity rises at once; larger = gentle start).
    pub a: f64,
    /// Ending exponent (near 1 = brisk stop; larger = delicate fade).
    pub b: f64,
    /// Fraction of the bump cut off by an impact, in [0, 0.6] (0 = none).
    pub impact: f64,
    table: [f64; PROFILE_TABLE],
    /// ∫₀¹ τ^a (1−τ)^b dτ (numerical).
    norm: f64,
}

impl Profile {
    /// A profile with onset `a`, ending `b` (both clamped to [1, 6]: no infinite
    /// accelerations) and `impact` (clamped to [0, 0.6]).
    pub fn new(a: f64, b: f64, impact: f64) -> Self {
        let a = if a.is_finite() {
            a.clamp(1.0, 6.0)
        } else {
            2.0
        };
        let b = if b.is_finite() {
            b.clamp(1.0, 6.0)
        } else {
            2.0
        };
        let impact = if impact.is_finite() {
            impact.clamp(0.0, 0.6)
        } else {
            0.0
        };
        let mut table = [0.0; PROFILE_TABLE];
        // Cumulative midpoint integration of the Beta kernel, normalised to end at 1.
        let n = PROFILE_TABLE - 1;
        let mut acc = 0.0;
        for (i, slot) in table.iter_mut().enumerate().skip(1) {
            let tau = (i as f64 - 0.5) / n as f64;
            acc += kernel(a, b, tau);
            *slot = acc;
        }
        for v in &mut table {
            *v /= acc;
        }
        Self {
            a,
            b,
            impact,
            table,
            norm: acc / n as f64,
        }
    }

    /// Minimum-jerk-like symmetric profile (a = b = 2), no impact.
    pub fn smooth() -> Self {
        Self::new(2.0, 2.0, 0.0)
    }

    /// The same onset and ending without the impact.
    pub fn without_impact(&self) -> Self {
        Self::new(self.a, self.b, 0.0)
    }

    /// The profile of a recovery stroke (wind-up, return): same onset, no impact, and an
    /// ending eased by [`RECOVERY_EASE`] — the emphasis of a gesture is in its main strokes.
    pub fn recovery(&self) -> Self {
        Self::new(self.a, self.b + RECOVERY_EASE, 0.0)
    }

    /// Normalised integral of the kernel from 0 to `x`: cubic Hermite interpolation of the
    /// table with the exact kernel as slope, so velocity is continuous between table points
    /// (linear interpolation would put acceleration spikes at every table point).
    fn cumulative(&self, x: f64) -> f64 {
        let n = (PROFILE_TABLE - 1) as f64;
        let x = x.clamp(0.0, 1.0) * n;
        let i = (x.floor() as usize).min(PROFILE_TABLE - 2);
        let f = x - i as f64;
        let slope = |k: usize| kernel(self.a, self.b, k as f64 / n) / self.norm / n;
        let (p0, p1) = (self.table[i], self.table[i + 1]);
        let (m0, m1) = (slope(i), slope(i + 1));
        let (f2, f3) = (f * f, f * f * f);
        (2.0 * f3 - 3.0 * f2 + 1.0) * p0
            + (f3 - 2.0 * f2 + f) * m0
            + (-2.0 * f3 + 3.0 * f2) * p1
            + (f3 - f2) * m1
    }

    /// Progress in [0, 1] (beyond 1 during an impact's overshoot) at normalised time `tau` of
    /// a stroke lasting `duration_s` seconds (which sets how much of it the impact's settle
    /// takes).
    pub fn progress(&self, tau: f64, duration_s: f64) -> f64 {
        let tau = if tau.is_finite() {
            tau.clamp(0.0, 1.0)
        } else {
            0.0
        };
        if self.impact <= 0.0 {
            return self.cumulative(tau);
        }
        let settle = settle_fraction(duration_s);
        let main = 1.0 - settle;
        let cut = 1.0 - self.impact;
        let reach = self.cumulative(cut).max(1e-9);
        if tau < main {
            return self.cumulative(tau / main * cut) / reach;
        }
        // Arrive at the end point with speed v0, then a damped bounce about it, in settle
        // time u ∈ [0, 1] (x(0) = 1, x'(0) = v0).
        let v0 = kernel(self.a, self.b, cut) / self.norm * cut / main / reach * settle;
        let u = (tau - main) / settle;
        let w = std::f64::consts::TAU * SETTLE_CYCLES;
        let spring = |u: f64| (-SETTLE_DECAY * u).exp() * (v0 / w) * (w * u).sin();
        // Remove the tiny residual at u = 1 with a blend that keeps the start untouched.
        1.0 + spring(u) - spring(1.0) * u * u * (3.0 - 2.0 * u)
    }
}

fn kernel(a: f64, b: f64, tau: f64) -> f64 {
    tau.powf(a) * (1.0 - tau).powf(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::rng::Stream;

    #[test]
    fn names_round_trip() {
        for e in Effort::STATES.into_iter().chain([Effort::NEUTRAL]) {
            assert_eq!(e.name().parse::<Effort>().unwrap(), e);
        }
        assert!("sudden".parse::<Effort>().is_err());
        assert!("fast-strong".parse::<Effort>().is_err());
    }

    #[test]
    fn profile_is_monotone_from_0_to_1() {
        for (a, b) in [(0.5, 0.6), (2.0, 2.0), (0.6, 3.0), (2.5, 0.7)] {
            let p = Profile::new(a, b, 0.0);
            let mut last = -1.0;
            for i in 0..=100 {
                let s = p.progress(i as f64 / 100.0, 0.5);
                assert!(s >= last - 1e-12);
                last = s;
            }
            assert!(p.progress(0.0, 0.5).abs() < 1e-12);
            assert!((p.progress(1.0, 0.5) - 1.0).abs() < 1e-12);
        }
        let hit = Profile::new(1.2, 1.2, 0.25);
        let pts: Vec<f64> = (0..=1000)
            .map(|i| hit.progress(i as f64 / 1000.0, 0.5))
            .collect();
        let peak = pts.iter().cloned().fold(0.0, f64::max);
        assert!(peak > 1.001 && peak < 1.05, "{peak}");
        assert!((hit.progress(1.0, 0.5) - 1.0).abs() < 1e-12);
        // Continuous: no step larger than the fastest motion allows.
        let worst = pts
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.01, "{worst}");
        // Velocity continuous across the impact (within the discretisation).
        let m = 1.0 - settle_fraction(0.5);
        let h = 1e-5;
        let before = (hit.progress(m - h, 0.5) - hit.progress(m - 2.0 * h, 0.5)) / h;
        let after = (hit.progress(m + 2.0 * h, 0.5) - hit.progress(m + h, 0.5)) / h;
        assert!(
            (before - after).abs() < 0.05 * before.abs(),
            "{before} vs {after}"
        );
    }

    #[test]
    fn sudden_onset_is_earlier_than_sustained() {
        let mut rng = SynthRng::new(3, Stream::Plan);
        let sudden = Effort::STATES[0].shape(&mut rng);
        let sustained = Effort::STATES[2].shape(&mut rng);
        assert!(sudden.time_factor < sustained.time_factor);
        assert!(sudden.profile.progress(0.2, 0.3) > sustained.profile.progress(0.2, 1.0));
    }
}
