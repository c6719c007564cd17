//! Stage 1b — a hand's tremor notched out of the motion.
//!
//! A hand holding a toy trembles at 8–12 Hz (physiological tremor: a fraction of a
//! millimetre, 1–3 mm in a tired or young hand; the validation set's rest logs show a line of
//! 0.3–1.7 mm there), while a played stroke lasts 0.2–0.5 s and its content lies below 5 Hz.
//! The Savitzky–Golay derivative ([`crate::filter`]) passes 10 Hz at 0.82 of its amplitude,
//! so 1 mm of tremor reads as 5 cm/s of motion: the noise floor ([`crate::noise`]) learns it,
//! and a slow or small stroke hides under it. A second-order notch at [`NOTCH_HZ`] on the
//! filter's velocity of every channel (position and the sign-continuous quaternion) takes the
//! tremor band out before the tokens, the noise floor and the sweep count read it:
//!
//! | frequency | gain |
//! |---|---|
//! | ≤ 3 Hz (a stroke's bulk) | ≥ 0.98 |
//! | 5 Hz | 0.92 |
//! | 8 / 10 / 12 Hz | 0.58 / 0 / 0.51 |
//! | 20 Hz | 0.94 |
//!
//! The notch costs something everywhere — 11–13 ms of delay below 3 Hz, and a tenth of a
//! second of ringing after a stroke that stops dead — and pays only where the tremor would
//! have set the floor, so it is used only then:
//!
//! | the stream | velocity read |
//! |---|---|
//! | a tracker under [`MIN_RATE_HZ`] | as played: the band is half of all it can tell, and notching it takes out the tracker's own jitter (a 30 Hz webcam at rest then fires six times as often) |
//! | at rest, the band's rms under [`ENGAGE_RMS`] | as played: the motion threshold stays on its floor anyway (a clean tracker, a toy on a table) |
//! | at rest, the band's rms over it (let go under half) | notched |
//!
//! Effort is read from the velocity as played ([`crate::frontend`]): how sudden or strong a
//! stroke was lives in its fast content too. Each channel is a biquad in transposed direct
//! form II, in f32 multiplies and adds only (host and MCU compute the same bits), started at
//! rest on the first tick after a restart. RAM: [`CHANNELS`] × 2 f32 of state and two words.

/// Centre of the notch, Hz: the middle of the physiological tremor band (8–12 Hz).
pub const NOTCH_HZ: f64 = 10.0;
/// Quality factor: the −3 dB band is 7.2–13.9 Hz, the tremor band and a margin either side.
/// A wider notch delays every stop more; a narrower one rings longer after a sudden stroke.
pub const NOTCH_Q: f64 = 1.5;

/// Slowest tracker (samples per second) whose velocity is notched: four times the top of the
/// tremor band, so that the band is at most half of what the tracker resolves.
pub const MIN_RATE_HZ: u32 = 48;

/// Channels notched: the velocity of x, y, z and the derivatives of qw, qx, qy, qz.
pub const CHANNELS: usize = 7;

/// Biquad coefficients (b0, b1, b2, a1, a2) of the notch on the 100 Hz grid (RBJ cookbook),
/// with cos and sin of the centre's angle by their series (const fns have no libm).
const COEFFS: [f32; 5] = coefficients();

const fn coefficients() -> [f32; 5] {
    let w = 2.0 * core::f64::consts::PI * NOTCH_HZ * crate::intake::TICK_S as f64;
    // Taylor series to 20 terms: exact to f64 for |w| < 1.
    let (mut c, mut s) = (0.0f64, 0.0f64);
    let (mut tc, mut ts) = (1.0f64, w);
    let mut k = 0;
    while k < 20 {
        c += tc;
        s += ts;
        let n = (2 * k + 1) as f64;
        tc *= -w * w / (n * (n + 1.0));
        ts *= -w * w / ((n + 1.0) * (n + 2.0));
        k += 1;
    }
    let alpha = s / (2.0 * NOTCH_Q);
    let a0 = 1.0 + alpha;
    [
        (1.0 / a0) as f32,
        (-2.0 * c / a0) as f32,
        (1.0 / a0) as f32,
        (-2.0 * c / a0) as f32,
        ((1.0 - alpha) / a0) as f32,
    ]
}

/// Weight of one quiet tick in the band's energy (1 s at 100 Hz).
const ENERGY_WEIGHT: f32 = 0.01;
/// The translation velocity's rms in the band at rest (m/s) above which the notch is used:
/// where the tremor alone would lift the motion threshold off its floor
/// ([`crate::noise::ON_FACTOR`] × rms against [`crate::noise::V_FLOOR_M_S`]); let go at half
/// of it.
pub const ENGAGE_RMS: f32 = crate::noise::V_FLOOR_M_S / crate::noise::ON_FACTOR;

/// The notch over the [`CHANNELS`] of a tick stream.
#[derive(Debug, Clone, Default)]
pub struct TremorNotch {
    /// Per channel the two state words of the transposed direct form; `None` until the
    /// first tick after a restart.
    state: Option<[[f32; 2]; CHANNELS]>,
    /// Energy of the translation velocity in the band while quiet, (m/s)².
    band: f32,
    /// Whether the notched velocity is used.
    engaged: bool,
}

impl TremorNotch {
    /// A notch at rest, started by the next tick.
    pub const fn new() -> Self {
        TremorNotch {
            state: None,
            band: 0.0,
            engaged: false,
        }
    }

    /// The filter's velocities `x` as the recognizer reads them (module docs): notched while
    /// a hand's tremor at rest would lift the motion threshold off its floor, as played
    /// otherwise. `quiet`: the figurine was at rest at the last tick (only then is the band's
    /// energy learnt); `fast_tracker`: samples come at [`MIN_RATE_HZ`] or more.
    pub fn filter(
        &mut self,
        x: [f32; CHANNELS],
        quiet: bool,
        fast_tracker: bool,
    ) -> [f32; CHANNELS] {
        let y = self.notch(x);
        if !fast_tracker {
            self.engaged = false;
            return x;
        }
        if quiet {
            let band: f32 = x
                .iter()
                .zip(&y)
                .take(3)
                .map(|(a, b)| (a - b) * (a - b))
                .sum();
            self.band += ENERGY_WEIGHT * (band - self.band);
            let at = if self.engaged { 0.25 } else { 1.0 } * ENGAGE_RMS * ENGAGE_RMS;
            self.engaged = self.band > at;
        }
        if self.engaged {
            y
        } else {
            x
        }
    }

    /// Forgets the stream (after a gap): the next tick starts it again at rest.
    pub fn reset(&mut self) {
        *self = Self::new();
    }

    /// One tick's channels with their tremor band notched out (units as given).
    fn notch(&mut self, x: [f32; CHANNELS]) -> [f32; CHANNELS] {
        let [b0, b1, b2, a1, a2] = COEFFS;
        // Started as if the first value had always been there: the notch passes it whole.
        let state = self
            .state
            .get_or_insert_with(|| x.map(|v| [v * (b1 + b2 - a1 - a2), v * (b2 - a2)]));
        let mut y = [0.0f32; CHANNELS];
        for ((yi, &xi), s) in y.iter_mut().zip(&x).zip(state.iter_mut()) {
            let out = b0 * xi + s[0];
            s[0] = b1 * xi - a1 * out + s[1];
            s[1] = b2 * xi - a2 * out;
            *yi = out;
        }
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intake::TICK_S;

    /// The steady amplitude of a sine of `hz` through the notch (after 2 s of settling).
    fn gain(hz: f32) -> f32 {
        let mut n = TremorNotch::new();
        let mut peak = 0.0f32;
        for i in 0..400u32 {
            let x = libm::sinf(2.0 * core::f32::consts::PI * hz * i as f32 * TICK_S);
            let y = n.notch([x; CHANNELS]);
            if i >= 200 {
                peak = peak.max(y[0].abs());
                assert_eq!(y[0], y[6], "every channel alike");
            }
        }
        peak
    }

    #[test]
    fn the_tremor_band_is_cut_and_a_strokes_band_passes() {
        assert!(gain(10.0) < 0.02, "{}", gain(10.0));
        assert!(
            gain(8.0) < 0.6 && gain(12.0) < 0.6,
            "{} {}",
            gain(8.0),
            gain(12.0)
        );
        assert!(
            gain(2.0) > 0.98 && gain(3.0) > 0.97,
            "{} {}",
            gain(2.0),
            gain(3.0)
        );
        assert!(gain(20.0) > 0.9, "{}", gain(20.0));
    }

    #[test]
    fn a_steady_stream_passes_unchanged_from_its_first_tick() {
        let mut n = TremorNotch::new();
        for _ in 0..50 {
            let y = n.notch([0.3, -0.1, 0.0, 1.0, 0.0, 0.2, 0.0]);
            assert!(
                (y[0] - 0.3).abs() < 1e-6 && (y[1] + 0.1).abs() < 1e-6,
                "{y:?}"
            );
            assert!(
                (y[3] - 1.0).abs() < 1e-6 && (y[5] - 0.2).abs() < 1e-6,
                "{y:?}"
            );
        }
        n.reset();
        let y = n.notch([-2.0; CHANNELS]);
        assert!((y[0] + 2.0).abs() < 1e-6, "{y:?}");
    }

    #[test]
    fn a_slow_stroke_comes_through_whole_and_a_little_late() {
        // A 0.4 s minimum-jerk push's velocity: its peak survives, about one tick late.
        let v = |i: u32| {
            let s = i as f32 * TICK_S / 0.4;
            if (0.0..=1.0).contains(&s) {
                30.0 * s * s * (1.0 - s) * (1.0 - s)
            } else {
                0.0
            }
        };
        let mut n = TremorNotch::new();
        let out: [f32; 60] = core::array::from_fn(|i| n.notch([v(i as u32); CHANNELS])[0]);
        let (at, peak) = out
            .iter()
            .enumerate()
            .fold((0, 0.0f32), |b, (i, &y)| if y > b.1 { (i, y) } else { b });
        assert!(
            (peak / v(20) - 1.0).abs() < 0.03,
            "{peak} against {}",
            v(20)
        );
        assert!((20..=22).contains(&at), "peak at tick {at}");
    }

    /// What `filter` makes of 3 s of quiet ticks whose velocity trembles at 10 Hz with an
    /// amplitude of `amp` m/s, at the last tick: (played, read).
    fn held(amp: f32, fast_tracker: bool) -> (f32, f32) {
        let mut n = TremorNotch::new();
        let mut last = (0.0, 0.0);
        for i in 0..300u32 {
            let v = amp * libm::sinf(2.0 * core::f32::consts::PI * 10.0 * i as f32 * TICK_S);
            let x = [v, 0.5 * v, 0.0, 0.0, 0.0, 0.0, 0.0];
            last = (v, n.filter(x, true, fast_tracker)[0]);
        }
        last
    }

    #[test]
    fn the_notch_is_used_only_where_the_tremor_would_set_the_floor() {
        // 10 cm/s of tremor (about 1.6 mm at 10 Hz) is notched out …
        let (played, read) = held(0.1, true);
        assert!(played.abs() > 0.05 && read.abs() < 0.01, "{played} {read}");
        // … 2 cm/s would stay under the floor anyway: read as played …
        let (played, read) = held(0.02, true);
        assert_eq!(played, read);
        // … and so is a slow tracker, however it trembles.
        let (played, read) = held(0.1, false);
        assert_eq!(played, read);
    }

    #[test]
    fn the_coefficients_are_the_cookbooks() {
        let w = 2.0 * core::f64::consts::PI * NOTCH_HZ * TICK_S as f64;
        let alpha = libm::sin(w) / (2.0 * NOTCH_Q);
        let a1 = (-2.0 * libm::cos(w) / (1.0 + alpha)) as f32;
        assert_eq!(COEFFS[1], a1);
        assert_eq!(COEFFS[4], ((1.0 - alpha) / (1.0 + alpha)) as f32);
    }
}
