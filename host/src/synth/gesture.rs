//! Per-action motion models: how a child or an animator plays each action with a toy figurine.
//!
//! Each action is a short list of strokes (see [`Stroke`]) drawn afresh for every performance:
//! step counts, step lengths, hop heights, angles and timings vary between performances the way
//! they vary between two tries by the same person. Sizes are given for a doodle of scale 1 and
//! neutral effort (metres, seconds, degrees); the performance's scale and [`EffortShape`]
//! multiply them. Directions are in the heading frame: +Z forward, +Y up, +X the figurine's left.

use std::fmt;
use std::str::FromStr;

use glam::DVec3;

use super::effort::EffortShape;
use super::rng::SynthRng;
use super::trajectory::Stroke;

/// The actions the generator can play.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Action {
    /// Small forward hops along the heading, rocking side to side.
    Walk,
    /// Faster, flatter, longer hops, leaning forward.
    Run,
    /// A crouch, one big arc up and forward, a landing.
    Jump,
    /// A quick forward thrust and return.
    Punch,
    /// A back-swing (nose up), then a forward-up arc (nose down), then return.
    Throw,
    /// A forward-up flick while leaning back, then return.
    Kick,
    /// A yaw rotation in place of 90–180°, either way.
    Turn,
    /// Lateral hops to one side.
    Sidestep,
    /// Down, hold, up.
    Crouch,
    /// Pitch forward about the feet, hold, back up.
    Bow,
    /// Roll oscillation about the feet while standing still.
    Wave,
    /// A full turn (≈360° yaw), often with a hop.
    Spin,
}

impl Action {
    /// Every action, in a fixed order.
    pub const ALL: [Action; 12] = [
        Action::Walk,
        Action::Run,
        Action::Jump,
        Action::Punch,
        Action::Throw,
        Action::Kick,
        Action::Turn,
        Action::Sidestep,
        Action::Crouch,
        Action::Bow,
        Action::Wave,
        Action::Spin,
    ];

    /// Lower-case name as used on the command line and in labels.
    pub fn name(self) -> &'static str {
        match self {
            Action::Walk => "walk",
            Action::Run => "run",
            Action::Jump => "jump",
            Action::Punch => "punch",
            Action::Throw => "throw",
            Action::Kick => "kick",
            Action::Turn => "turn",
            Action::Sidestep => "sidestep",
            Action::Crouch => "crouch",
            Action::Bow => "bow",
            Action::Wave => "wave",
            Action::Spin => "spin",
        }
    }

    /// `true` for actions that, played again right after themselves, go on rather than
    /// start anew: each is a few like units already (strides, steps to the side, waves, a
    /// turn's twists), so more strides are a longer walk, more waving a longer wave. A second
    /// jump, punch or spin is another action.
    pub fn continues(self) -> bool {
        matches!(
            self,
            Action::Walk | Action::Run | Action::Sidestep | Action::Wave | Action::Turn
        )
    }

    /// `true` for actions that move the figurine across the floor.
    pub fn travels(self) -> bool {
        matches!(
            self,
            Action::Walk | Action::Run | Action::Jump | Action::Sidestep
        )
    }
}

impl fmt::Display for Action {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Action {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim().to_ascii_lowercase();
        Action::ALL
            .into_iter()
            .find(|a| a.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Action::ALL.iter().map(|a| a.name()).collect();
                format!("unknown action `{s}`; known: {}", names.join(", "))
            })
    }
}

/// How stroke durations grow with the doodle's scale: duration ∝ scale^0.4.
pub const DURATION_SCALE_EXPONENT: f64 = 0.4;

/// Draws sizes and timings for one performance.
struct Draw<'a> {
    rng: &'a mut SynthRng,
    shape: EffortShape,
    scale: f64,
}

impl Draw<'_> {
    /// A stroke duration in seconds from a neutral range. Bigger doodles take somewhat longer
    /// (× scale^[`DURATION_SCALE_EXPONENT`]), as bigger arm movements do, so speed grows less
    /// than linearly with scale.
    fn dur(&mut self, lo: f64, hi: f64) -> f64 {
        self.rng.uniform(lo, hi)
            * self.shape.time_factor
            * self.scale.max(1e-3).powf(DURATION_SCALE_EXPONENT)
    }

    /// A hold duration: effort stretches holds less than strokes.
    fn hold(&mut self, lo: f64, hi: f64) -> Stroke {
        Stroke::hold(self.rng.uniform(lo, hi) * self.shape.time_factor.sqrt())
    }

    /// A length in metres from a neutral range.
    fn len(&mut self, lo: f64, hi: f64) -> f64 {
        self.rng.uniform(lo, hi) * self.scale * self.shape.amplitude
    }

    /// An expressive angle (radians) from a range in degrees; Weight enlarges it mildly.
    fn ang(&mut self, lo_deg: f64, hi_deg: f64) -> f64 {
        self.rng.uniform(lo_deg, hi_deg).to_radians() * self.shape.amplitude.sqrt()
    }

    /// A semantic angle (radians) from degrees, untouched by effort (e.g. how far to turn).
    fn exact_ang(&mut self, lo_deg: f64, hi_deg: f64) -> f64 {
        self.rng.uniform(lo_deg, hi_deg).to_radians()
    }

    /// A dimension of the toy itself (metres): the figurine does not grow when the child
    /// plays bigger, so neither the doodle's scale nor the effort's amplitude applies.
    fn body(&mut self, lo: f64, hi: f64) -> f64 {
        self.rng.uniform(lo, hi)
    }

    /// Where the fingers hold the toy when twisting it about the vertical: a horizontal offset
    /// of 0–3 cm from the tracked centre (a toy dimension), so turns and spins also swing the
    /// tracked point a little.
    fn grip(&mut self) -> DVec3 {
        let r = self.body(0.0, 0.03);
        let a = self.rng.uniform(0.0, std::f64::consts::TAU);
        DVec3::new(r * a.cos(), 0.0, r * a.sin())
    }

    /// A main stroke (with the effort's impact, if any).
    fn stroke(&mut self, lo: f64, hi: f64) -> Stroke {
        let d = self.dur(lo, hi);
        Stroke::moving(d, self.shape.profile)
    }

    /// A recovery stroke (wind-up, return): same onset, eased ending, no impact.
    fn recover(&mut self, lo: f64, hi: f64) -> Stroke {
        let d = self.dur(lo, hi);
        Stroke::moving(d, self.shape.profile.recovery())
    }
}

/// The strokes of one performance of `action` at `scale` (dimensionless, 1 = a typical toy
/// doodle) with effort `shape`. The figurine ends upright and level, where the action leaves it.
pub fn plan(action: Action, shape: &EffortShape, scale: f64, rng: &mut SynthRng) -> Vec<Stroke> {
    let mut d = Draw {
        rng,
        shape: *shape,
        scale,
    };
    let mut out = Vec::new();
    match action {
        Action::Walk => {
            let n = d.rng.int(2, 5);
            let rock = d.ang(6.0, 14.0);
            let side = d.rng.sign();
            for i in 0..n {
                let mut s = d.stroke(0.3, 0.45);
                s.translate.z = d.len(0.06, 0.12);
                s.arc.y = d.len(0.025, 0.05);
                let alt = if i % 2 == 0 { 1.0 } else { -1.0 };
                s.rot_arc.z = rock * side * alt * d.rng.uniform(0.8, 1.2);
                out.push(s);
                if i + 1 < n {
                    out.push(d.hold(0.0, 0.06));
                }
            }
        }
        Action::Run => {
            let n = d.rng.int(3, 6);
            let lean = d.ang(8.0, 15.0);
            let rock = d.ang(3.0, 6.0);
            let side = d.rng.sign();
            for i in 0..n {
                let mut s = d.stroke(0.2, 0.28);
                s.translate.z = d.len(0.12, 0.2);
                s.arc.y = d.len(0.012, 0.025);
                let alt = if i % 2 == 0 { 1.0 } else { -1.0 };
                s.rot_arc.z = rock * side * alt;
                if i == 0 {
                    s.rotate.x += lean;
                }
                if i + 1 == n {
                    s.rotate.x -= lean;
                }
                out.push(s);
            }
        }
        Action::Jump => {
            let dip = d.len(0.015, 0.035);
            let crouch_pitch = d.ang(3.0, 8.0);
            let mut s = d.recover(0.18, 0.28);
            s.translate.y = -dip;
            s.rotate.x = crouch_pitch;
            out.push(s);
            let mut flight = d.stroke(0.45, 0.75);
            flight.translate = DVec3::new(0.0, dip, d.len(0.1, 0.35));
            flight.arc.y = d.len(0.15, 0.3);
            flight.rotate.x = -crouch_pitch;
            flight.rot_arc.x = -d.ang(5.0, 12.0);
            out.push(flight);
            let absorb = d.len(0.01, 0.025);
            let mut land = d.recover(0.12, 0.2);
            land.translate.y = -absorb;
            out.push(land);
            let mut up = d.recover(0.2, 0.3);
            up.translate.y = absorb;
            out.push(up);
        }
        Action::Punch => {
            let windup = if d.rng.chance(0.7) {
                d.len(0.015, 0.035)
            } else {
                0.0
            };
            if windup > 0.0 {
                let mut s = d.recover(0.12, 0.2);
                s.translate.z = -windup;
                out.push(s);
            }
            let reach = d.len(0.1, 0.2);
            let twist = d.ang(0.0, 15.0) * d.rng.sign();
            let mut thrust = d.stroke(0.22, 0.34);
            thrust.translate.z = windup + reach;
            thrust.rotate.z = twist;
            out.push(thrust);
            out.push(d.hold(0.03, 0.12));
            let mut back = d.recover(0.28, 0.42);
            back.translate.z = -reach;
            back.rotate.z = -twist;
            out.push(back);
        }
        Action::Throw => {
            let bz = d.len(0.05, 0.1);
            let by = d.len(0.03, 0.07);
            let pb = d.ang(20.0, 35.0);
            let mut swing = d.recover(0.3, 0.45);
            swing.translate = DVec3::new(0.0, by, -bz);
            swing.rotate.x = -pb;
            out.push(swing);
            let fz = d.len(0.15, 0.25);
            let fy = d.len(0.0, 0.04);
            let pf = d.ang(15.0, 30.0);
            let mut release = d.stroke(0.28, 0.4);
            release.translate = DVec3::new(0.0, fy, bz + fz);
            release.arc.y = d.len(0.03, 0.06);
            release.rotate.x = pb + pf;
            out.push(release);
            out.push(d.hold(0.02, 0.1));
            let mut back = d.recover(0.4, 0.6);
            back.translate = DVec3::new(0.0, -(by + fy), -fz);
            back.rotate.x = -pf;
            out.push(back);
        }
        Action::Kick => {
            let prep = if d.rng.chance(0.6) {
                d.len(0.01, 0.025)
            } else {
                0.0
            };
            if prep > 0.0 {
                let mut s = d.recover(0.12, 0.2);
                s.translate.z = -prep;
                out.push(s);
            }
            let fz = d.len(0.05, 0.1);
            let fy = d.len(0.03, 0.07);
            let lean = d.ang(15.0, 30.0);
            let mut flick = d.stroke(0.22, 0.34);
            flick.translate = DVec3::new(0.0, fy, prep + fz);
            flick.rotate.x = -lean;
            out.push(flick);
            out.push(d.hold(0.02, 0.1));
            let mut back = d.recover(0.3, 0.45);
            back.translate = DVec3::new(0.0, -fy, -fz);
            back.rotate.x = lean;
            out.push(back);
        }
        Action::Turn => {
            let angle = d.exact_ang(90.0, 180.0) * d.rng.sign();
            let pieces = if d.rng.chance(0.7) { 1 } else { 2 };
            let grip = d.grip();
            for i in 0..pieces {
                let mut s = d.stroke(0.45, 0.8);
                s.duration *= if pieces == 2 { 0.6 } else { 1.0 };
                s.rotate.y = angle / f64::from(pieces);
                s.arc.y = d.len(0.008, 0.025);
                s.pivot = grip;
                out.push(s);
                if i + 1 < pieces {
                    out.push(d.hold(0.03, 0.1));
                }
            }
        }
        Action::Sidestep => {
            let n = d.rng.int(2, 4);
            let dir = d.rng.sign();
            let lean = d.ang(4.0, 10.0);
            for i in 0..n {
                let mut s = d.stroke(0.28, 0.4);
                s.translate.x = dir * d.len(0.05, 0.1);
                s.arc.y = d.len(0.02, 0.04);
                // Moving left (+X) tips the top left, which is negative roll.
                s.rot_arc.z = -dir * lean;
                out.push(s);
                if i + 1 < n {
                    out.push(d.hold(0.0, 0.06));
                }
            }
        }
        Action::Crouch => {
            let depth = d.len(0.05, 0.12);
            let pitch = d.ang(3.0, 12.0);
            let mut down = d.stroke(0.35, 0.6);
            down.translate.y = -depth;
            down.rotate.x = pitch;
            out.push(down);
            out.push(d.hold(0.3, 0.8));
            let mut up = d.recover(0.4, 0.6);
            up.translate.y = depth;
            up.rotate.x = -pitch;
            out.push(up);
        }
        Action::Bow => {
            // The toy pivots about its feet, `r` below the tracked centre.
            let feet = DVec3::new(0.0, -d.body(0.03, 0.07), 0.0);
            let theta = d.ang(30.0, 70.0);
            let mut down = d.stroke(0.5, 0.8);
            down.rotate.x = theta;
            down.pivot = feet;
            out.push(down);
            out.push(d.hold(0.1, 0.5));
            let mut up = d.recover(0.5, 0.8);
            up.rotate.x = -theta;
            up.pivot = feet;
            out.push(up);
        }
        Action::Wave => {
            let amp = d.ang(15.0, 30.0);
            let cycles = d.rng.int(2, 4);
            let first = d.rng.sign();
            let feet = DVec3::new(0.0, -d.body(0.02, 0.05), 0.0);
            // Roll targets: +A, −A, +A, … then back to 0, rocking about the feet.
            let mut targets: Vec<f64> = (0..2 * cycles)
                .map(|k| if k % 2 == 0 { amp } else { -amp } * first)
                .collect();
            targets.push(0.0);
            let mut roll = 0.0_f64;
            for target in targets {
                let target = target * d.rng.uniform(0.85, 1.15);
                let mut s = d.stroke(0.18, 0.3);
                s.rotate.z = target - roll;
                s.pivot = feet;
                out.push(s);
                roll = target;
            }
        }
        Action::Spin => {
            let angle = d.exact_ang(320.0, 400.0) * d.rng.sign();
            let hop = if d.rng.chance(0.6) {
                d.len(0.03, 0.08)
            } else {
                d.len(0.005, 0.015)
            };
            let grip = d.grip();
            let mut s = d.stroke(0.6, 1.1);
            s.rotate.y = angle;
            s.arc.y = hop;
            s.pivot = grip;
            out.push(s);
        }
    }
    sloppiness(action, &mut out, d.shape.lift, d.rng);
    out
}

/// Human imprecision: hop heights follow the effort's lift, every translation strays a little
/// sideways (σ 6 % of its length, perpendicular to it), and hops along the floor wander in
/// heading (σ 2°), so returns are not exact and paths are not ruler-straight.
fn sloppiness(action: Action, strokes: &mut [Stroke], lift: f64, rng: &mut SynthRng) {
    for s in strokes.iter_mut() {
        if s.arc.y > 0.0 {
            s.arc.y *= lift;
        }
        let len = s.translate.length();
        let dev = DVec3::new(rng.normal(), 0.5 * rng.normal(), rng.normal()) * (0.06 * len);
        let wander = rng.normal() * 2f64.to_radians();
        if len > 0.0 {
            let along = s.translate / len;
            s.translate += dev - along * dev.dot(along);
            if action.travels() {
                s.rotate.y += wander;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::effort::Effort;
    use crate::synth::rng::Stream;

    #[test]
    fn names_parse() {
        for a in Action::ALL {
            assert_eq!(a.name().parse::<Action>().unwrap(), a);
        }
        assert!("moonwalk".parse::<Action>().is_err());
    }

    #[test]
    fn every_action_moves_and_ends_level() {
        for (k, a) in Action::ALL.into_iter().enumerate() {
            let mut rng = SynthRng::new(k as u64, Stream::Plan);
            let shape = Effort::NEUTRAL.shape(&mut rng);
            let strokes = plan(a, &shape, 1.0, &mut rng);
            assert!(strokes.iter().any(|s| !s.is_hold()), "{a}");
            let pitch: f64 = strokes.iter().map(|s| s.rotate.x).sum();
            let roll: f64 = strokes.iter().map(|s| s.rotate.z).sum();
            assert!(
                pitch.abs() < 1e-9 && roll.abs() < 1e-9,
                "{a}: {pitch} {roll}"
            );
            let total: f64 = strokes.iter().map(|s| s.duration).sum();
            assert!((0.3..6.0).contains(&total), "{a}: {total}");
        }
    }
}
