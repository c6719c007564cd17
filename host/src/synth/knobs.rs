//! Variation knobs: the ranges every doodle's nuisance parameters are drawn from.
//!
//! A recognizer must not care where the figurine stands, which way it faces, how big or how
//! fast the child plays, how the toy is held, or how the tracker samples; the generator varies
//! all of these widely. Each knob is a [`Range`] (a fixed value is a range with `lo == hi`);
//! [`Knobs::draw`] picks one [`Variation`] per doodle. Values are always drawn in the same order
//! and number whatever the ranges, so pinning one knob (e.g. `--rate 60`) leaves every other
//! drawn value — and the path itself — unchanged for the same seed.

use std::fmt;
use std::str::FromStr;

use glam::{DQuat, DVec3};

use super::rng::SynthRng;
use super::sampling::SignMode;

/// A closed interval of values to draw from uniformly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Lower end.
    pub lo: f64,
    /// Upper end (≥ `lo`).
    pub hi: f64,
}

impl Range {
    /// The interval [lo, hi] (swapped if given backwards).
    pub const fn new(lo: f64, hi: f64) -> Self {
        if hi < lo {
            Self { lo: hi, hi: lo }
        } else {
            Self { lo, hi }
        }
    }

    /// A single value.
    pub const fn fixed(v: f64) -> Self {
        Self { lo: v, hi: v }
    }

    /// Draws a value (one RNG draw, always).
    pub fn draw(&self, rng: &mut SynthRng) -> f64 {
        rng.uniform(self.lo, self.hi)
    }
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.lo == self.hi {
            write!(f, "{}", self.lo)
        } else {
            write!(f, "{}..{}", self.lo, self.hi)
        }
    }
}

impl FromStr for Range {
    type Err = String;
    /// Parses `V` or `LO..HI` (finite numbers).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let num = |x: &str| -> Result<f64, String> {
            let v: f64 = x
                .trim()
                .parse()
                .map_err(|_| format!("`{}` is not a number", x.trim()))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("`{}` is not finite", x.trim()))
            }
        };
        match s.split_once("..") {
            Some((a, b)) => Ok(Range::new(num(a)?, num(b)?)),
            None => Ok(Range::fixed(num(s)?)),
        }
    }
}

/// Ranges of all nuisance parameters. `Default` gives the wide ranges of `figurine synth`.
#[derive(Debug, Clone, PartialEq)]
pub struct Knobs {
    /// Nominal sample rate, Hz (default 30..240).
    pub rate_hz: Range,
    /// Timestamp jitter, fraction of a sample period (default 0..0.25, at most 0.45).
    pub jitter: Range,
    /// Probability that a sample is dropped (default 0..0.01).
    pub drop: Range,
    /// Spatial scale of the doodle, dimensionless (default 0.5..2).
    pub scale: Range,
    /// Tempo multiplier: durations are divided by it (default 0.8..1.25).
    pub speed: Range,
    /// Heading of the whole doodle, degrees about +Y (default −180..180).
    pub heading_deg: Range,
    /// How crooked the toy is held: tilt angle in degrees, random direction (default 0..10).
    pub tilt_deg: Range,
    /// Start position across the room (x and z), metres (default −2..2).
    pub room_m: Range,
    /// Start height, metres (default 0.4..1.5).
    pub height_m: Range,
    /// Multiplier of sensor noise, tremor and drift (0 = clean; default 0.5..1.5).
    pub noise: Range,
    /// Log clock at the first sample, seconds (default 0..10).
    pub t0: Range,
    /// Still time before the first action, seconds (default 0.4..1.2).
    pub lead_s: Range,
    /// Still time between actions and after the last, seconds (default 0.3..1.5).
    pub pause_s: Range,
    /// Quaternion sign convention; `None` draws one per doodle.
    pub sign: Option<SignMode>,
    /// Probability per sample of a tracker glitch (spike, NaN row, zero quaternion, repeated or
    /// backward timestamp); default 0 (see [`super::noise::Glitcher`]).
    pub glitch: Range,
    /// Probability that a sequence also holds one handling of the toy that plays no action
    /// (carried elsewhere, lifted and set down: [`super::Handling`]); default 1/3.
    pub handling: f64,
}

impl Default for Knobs {
    fn default() -> Self {
        Self {
            rate_hz: Range::new(30.0, 240.0),
            jitter: Range::new(0.0, 0.25),
            drop: Range::new(0.0, 0.01),
            scale: Range::new(0.5, 2.0),
            speed: Range::new(0.8, 1.25),
            heading_deg: Range::new(-180.0, 180.0),
            tilt_deg: Range::new(0.0, 10.0),
            room_m: Range::new(-2.0, 2.0),
            height_m: Range::new(0.4, 1.5),
            noise: Range::new(0.5, 1.5),
            t0: Range::new(0.0, 10.0),
            lead_s: Range::new(0.4, 1.2),
            pause_s: Range::new(0.3, 1.5),
            sign: None,
            glitch: Range::fixed(0.0),
            handling: 1.0 / 3.0,
        }
    }
}

impl Knobs {
    /// Knobs with no sensor imperfections, fixed rate, no jitter or drops, unit scale and speed,
    /// heading 0, no tilt, start at (0, 1, 0), clock from 0, no handling: the canonical doodle,
    /// for tests.
    pub fn canonical() -> Self {
        Self {
            rate_hz: Range::fixed(120.0),
            jitter: Range::fixed(0.0),
            drop: Range::fixed(0.0),
            scale: Range::fixed(1.0),
            speed: Range::fixed(1.0),
            heading_deg: Range::fixed(0.0),
            tilt_deg: Range::fixed(0.0),
            room_m: Range::fixed(0.0),
            height_m: Range::fixed(1.0),
            noise: Range::fixed(0.0),
            t0: Range::fixed(0.0),
            lead_s: Range::fixed(0.5),
            pause_s: Range::fixed(0.5),
            sign: Some(SignMode::Continuous),
            glitch: Range::fixed(0.0),
            handling: 0.0,
        }
    }

    /// Draws one doodle's nuisance parameters.
    pub fn draw(&self, rng: &mut SynthRng) -> Variation {
        let rate_hz = self.rate_hz.draw(rng);
        let jitter = self.jitter.draw(rng);
        let drop = self.drop.draw(rng);
        let scale = self.scale.draw(rng);
        let speed = self.speed.draw(rng);
        let heading = self.heading_deg.draw(rng).to_radians();
        let tilt_angle = self.tilt_deg.draw(rng).to_radians();
        let tilt_dir = rng.uniform(0.0, std::f64::consts::TAU);
        let x = self.room_m.draw(rng);
        let z = self.room_m.draw(rng);
        let y = self.height_m.draw(rng);
        let noise = self.noise.draw(rng);
        let t0 = self.t0.draw(rng);
        let sign_pick = rng.index(SignMode::ALL.len());
        let glitch = self.glitch.draw(rng);
        // Tilt about a horizontal axis of the object (a mix of pitch and roll).
        let axis = DVec3::new(tilt_dir.cos(), 0.0, tilt_dir.sin());
        Variation {
            rate_hz,
            jitter,
            drop,
            scale,
            speed: if speed > 0.0 { speed } else { 1.0 },
            heading,
            tilt: DQuat::from_axis_angle(axis, tilt_angle),
            start: DVec3::new(x, y, z),
            noise,
            t0,
            sign: self.sign.unwrap_or(SignMode::ALL[sign_pick]),
            glitch,
        }
    }

    /// Checks that the ranges make sense; the message names the offending knob.
    pub fn validate(&self) -> Result<(), String> {
        use super::sampling::{MAX_JITTER, MAX_RATE_HZ, MIN_RATE_HZ};
        let check = |name: &str, r: Range, lo: f64, hi: f64| {
            if r.lo < lo || r.hi > hi {
                Err(format!("--{name} {r}: must lie within {lo}..{hi}"))
            } else {
                Ok(())
            }
        };
        check("rate", self.rate_hz, MIN_RATE_HZ, MAX_RATE_HZ)?;
        check("jitter", self.jitter, 0.0, MAX_JITTER)?;
        check("drop", self.drop, 0.0, 0.5)?;
        check("scale", self.scale, 0.01, 100.0)?;
        check("speed", self.speed, 0.05, 20.0)?;
        check("heading", self.heading_deg, -3600.0, 3600.0)?;
        check("tilt", self.tilt_deg, 0.0, 60.0)?;
        check("room", self.room_m, -1000.0, 1000.0)?;
        check("height", self.height_m, -1000.0, 1000.0)?;
        check("noise", self.noise, 0.0, 100.0)?;
        check("t0", self.t0, -1e6, 1e6)?;
        check("lead", self.lead_s, 0.0, 60.0)?;
        check("pause", self.pause_s, 0.0, 60.0)?;
        check("glitch", self.glitch, 0.0, 0.5)?;
        check("handling", Range::fixed(self.handling), 0.0, 1.0)?;
        Ok(())
    }
}

/// One doodle's drawn nuisance parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variation {
    /// Nominal sample rate, Hz.
    pub rate_hz: f64,
    /// Timestamp jitter, fraction of a period.
    pub jitter: f64,
    /// Dropout probability per sample.
    pub drop: f64,
    /// Spatial scale (dimensionless).
    pub scale: f64,
    /// Tempo multiplier (dimensionless, > 0).
    pub speed: f64,
    /// Heading of the doodle, radians about +Y.
    pub heading: f64,
    /// Constant hold tilt, object frame.
    pub tilt: DQuat,
    /// Start position, metres.
    pub start: DVec3,
    /// Sensor imperfection multiplier.
    pub noise: f64,
    /// Log clock of the first sample, seconds.
    pub t0: f64,
    /// Quaternion sign convention.
    pub sign: SignMode,
    /// Glitch probability per sample.
    pub glitch: f64,
}

impl fmt::Display for Variation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (axis, angle) = self.tilt.to_axis_angle();
        let _ = axis;
        write!(
            f,
            "rate={:.1}Hz jitter={:.3} drop={:.4} scale={:.3} speed={:.3} heading={:.1}deg \
             tilt={:.1}deg start=({:.3},{:.3},{:.3}) noise={:.3} t0={:.3}s sign={} glitch={:.4}",
            self.rate_hz,
            self.jitter,
            self.drop,
            self.scale,
            self.speed,
            self.heading.to_degrees(),
            angle.to_degrees(),
            self.start.x,
            self.start.y,
            self.start.z,
            self.noise,
            self.t0,
            self.sign,
            self.glitch
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::rng::Stream;

    #[test]
    fn ranges_parse() {
        assert_eq!("60".parse::<Range>().unwrap(), Range::fixed(60.0));
        assert_eq!("2..0.5".parse::<Range>().unwrap(), Range::new(0.5, 2.0));
        assert_eq!(
            "-180..180".parse::<Range>().unwrap(),
            Range::new(-180.0, 180.0)
        );
        assert!("fast".parse::<Range>().is_err());
        assert!("1..nan".parse::<Range>().is_err());
    }

    #[test]
    fn pinning_one_knob_keeps_the_others() {
        let wide = Knobs::default();
        let pinned = Knobs {
            rate_hz: Range::fixed(60.0),
            ..Knobs::default()
        };
        let a = wide.draw(&mut SynthRng::new(9, Stream::Knobs));
        let b = pinned.draw(&mut SynthRng::new(9, Stream::Knobs));
        assert_eq!(b.rate_hz, 60.0);
        assert_eq!(a.scale, b.scale);
        assert_eq!(a.start, b.start);
        assert!(Knobs::default().validate().is_ok());
        let bad = Knobs {
            rate_hz: Range::fixed(1e6),
            ..Knobs::default()
        };
        assert!(bad.validate().unwrap_err().contains("--rate"));
    }
}
