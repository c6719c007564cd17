//! Handling: motion of the figurine that plays no action — the child moves the toy to another
//! spot, lifts it to look at it and sets it back down, or holds it while talking with it.
//!
//! These are the non-actions a recogniser must stay silent through (issue 26: "repositioning
//! the figurine, lifting and setting it down … give no event"). Unlike [`super::rest`] (a toy
//! held still, at most a fidget of millimetres), handling moves as far as an action does; what
//! sets it apart is its form: one unhurried stroke, or a rise, a hold and a fall back to where
//! it started, with none of an action's hops, thrusts or rhythm.
//!
//! | kind | motion (at doodle scale 1) |
//! |---|---|
//! | `reposition` | one smooth carry 10–30 cm in any direction, lifted 1–4 cm on the way, turned up to ±45°, 0.6–1.2 s |
//! | `lift` | raised 5–15 cm in 0.4–0.8 s, held 0.3–1.2 s while tipped up to 25° to look at it, set back down |
//! | `talk` | the hand that holds it beats along with speech: 4–12 strokes of 0.3–0.9 s between points within 3–12 cm of where it rests, turning up to ±15° (pitch, roll) and ±25° (yaw) about its resting attitude, with or without a breath (0.05–0.5 s) between |
//!
//! `talk` stands for the motion a real person's wrist makes while they stand and talk (the
//! Blender gesture take that `figurine eval real` holds: beats of 3–22 cm at 0.1–0.7 m/s): no
//! action, yet as fast and as far as a small gesture, and never still for long.
//!
//! Lengths scale with the doodle's scale and durations with scale^[`DURATION_SCALE_EXPONENT`],
//! as an action's do, so handling is drawn at the size the player plays at.

use std::fmt;
use std::str::FromStr;

use super::effort::Profile;
use super::gesture::DURATION_SCALE_EXPONENT;
use super::rng::SynthRng;
use super::trajectory::Stroke;

/// A kind of non-action handling.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Handling {
    /// Carried to another spot in one smooth stroke.
    Reposition,
    /// Lifted, looked at, and set back down where it was.
    Lift,
    /// Held in a hand that beats along with speech, about where it rests.
    Talk,
}

impl Handling {
    /// Every kind, in a fixed order.
    pub const ALL: [Handling; 3] = [Handling::Reposition, Handling::Lift, Handling::Talk];

    /// The kinds a generated sequence draws its one handling from, and `figurine eval`'s
    /// handling-silent share counts: a toy moved between plays. Talking with it is measured
    /// apart, as events per hour (`eval`'s talk line), the real-motion twin of `eval real`'s
    /// takes that play no action.
    pub const BETWEEN_PLAYS: [Handling; 2] = [Handling::Reposition, Handling::Lift];

    /// Lower-case name (`reposition`, `lift`, `talk`).
    pub fn name(self) -> &'static str {
        match self {
            Handling::Reposition => "reposition",
            Handling::Lift => "lift",
            Handling::Talk => "talk",
        }
    }
}

impl fmt::Display for Handling {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Handling {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim().to_ascii_lowercase();
        Handling::ALL
            .into_iter()
            .find(|h| h.name() == s)
            .ok_or_else(|| format!("unknown handling `{s}`; known: reposition, lift, talk"))
    }
}

/// The strokes of one handling of `kind` at doodle `scale` (dimensionless, 1 = a typical toy
/// doodle). Durations are at the player's normal tempo (the performer divides by its speed).
pub fn plan(kind: Handling, scale: f64, rng: &mut SynthRng) -> Vec<Stroke> {
    let scale = scale.max(1e-3);
    let tempo = scale.powf(DURATION_SCALE_EXPONENT);
    let smooth = Profile::smooth();
    let mut out = Vec::new();
    match kind {
        Handling::Reposition => {
            let dist = rng.uniform(0.1, 0.3) * scale;
            let dir = rng.uniform(0.0, std::f64::consts::TAU);
            let mut s = Stroke::moving(rng.uniform(0.6, 1.2) * tempo, smooth);
            s.translate.x = dist * dir.sin();
            s.translate.z = dist * dir.cos();
            s.arc.y = rng.uniform(0.01, 0.04) * scale;
            s.rotate.y = rng.uniform(-45.0, 45.0).to_radians();
            out.push(s);
        }
        Handling::Lift => {
            let h = rng.uniform(0.05, 0.15) * scale;
            // The hand does not come down exactly where it rose: up to a centimetre off.
            let off_x = rng.uniform(-0.01, 0.01) * scale;
            let off_z = rng.uniform(-0.01, 0.01) * scale;
            let mut up = Stroke::moving(rng.uniform(0.4, 0.8) * tempo, smooth);
            up.translate.y = h;
            out.push(up);
            // Tipped towards the face and back, the hand otherwise still.
            let mut look = Stroke::moving(rng.uniform(0.3, 1.2) * tempo, smooth);
            look.rot_arc.x = -rng.uniform(0.0, 25.0).to_radians();
            look.rot_arc.z = rng.uniform(-10.0, 10.0).to_radians();
            out.push(look);
            let mut down = Stroke::moving(rng.uniform(0.4, 0.8) * tempo, smooth);
            down.translate.y = -h;
            down.translate.x = off_x;
            down.translate.z = off_z;
            out.push(down);
        }
        Handling::Talk => talk(scale, tempo, rng, &mut out),
    }
    out
}

/// The beats of a hand that holds the toy while its owner talks: each a stroke from where the
/// hand is to a new point within `reach` of where it rests (uniform in a ball), its attitude to
/// a new one within the table's bounds of the resting one, so the hand wanders about home and
/// never away (a person who talks stays where they stand).
fn talk(scale: f64, tempo: f64, rng: &mut SynthRng, out: &mut Vec<Stroke>) {
    let reach = rng.uniform(0.03, 0.12) * scale;
    let beats = rng.int(4, 12);
    let (mut at, mut attitude) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
    for i in 0..beats {
        if i > 0 && rng.chance(0.5) {
            out.push(Stroke::hold(rng.uniform(0.05, 0.5) * tempo));
        }
        let target = loop {
            let p = glam::DVec3::new(
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            );
            if p.length_squared() <= 1.0 {
                break p * reach;
            }
        };
        let turned = glam::DVec3::new(
            rng.uniform(-15.0, 15.0),
            rng.uniform(-25.0, 25.0),
            rng.uniform(-15.0, 15.0),
        ) * std::f64::consts::PI
            / 180.0;
        // A beat is brisk at its start more often than not; its path bends a little.
        let profile = Profile::new(rng.uniform(1.5, 3.0), rng.uniform(1.5, 4.0), 0.0);
        let mut s = Stroke::moving(rng.uniform(0.3, 0.9) * tempo, profile);
        s.translate = target - at;
        let len = s.translate.length();
        s.arc = glam::DVec3::new(rng.normal(), rng.normal(), rng.normal()) * (0.15 * len);
        s.rotate = turned - attitude;
        out.push(s);
        at = target;
        attitude = turned;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path(strokes: &[Stroke]) -> (f64, f64) {
        let net = strokes
            .iter()
            .fold(glam::DVec3::ZERO, |a, s| a + s.translate);
        let horizontal = net.x.hypot(net.z);
        (horizontal, net.y)
    }

    #[test]
    fn a_reposition_carries_the_toy_elsewhere_and_a_lift_returns_it() {
        for seed in 0..50 {
            let mut rng = SynthRng::from_u64(seed);
            let r = plan(Handling::Reposition, 1.0, &mut rng);
            let (moved, rose) = path(&r);
            assert!((0.1..=0.3 + 1e-9).contains(&moved), "reposition {moved}");
            assert!(rose.abs() < 1e-12);
            let l = plan(Handling::Lift, 1.0, &mut rng);
            let (moved, rose) = path(&l);
            assert!(moved <= 0.015, "lift lands {moved} m off");
            assert!(rose.abs() < 1e-12);
            let top = l[0].translate.y;
            assert!((0.05..=0.15).contains(&top), "lift height {top}");
        }
    }

    #[test]
    fn a_talking_hand_beats_about_where_it_rests() {
        for seed in 0..50 {
            let mut rng = SynthRng::from_u64(seed);
            let t = plan(Handling::Talk, 1.0, &mut rng);
            let moving: Vec<&Stroke> = t.iter().filter(|s| !s.is_hold()).collect();
            assert!((4..=12).contains(&moving.len()), "{} beats", moving.len());
            // Every point it passes through lies within reach of home (arcs aside).
            let mut at = glam::DVec3::ZERO;
            for s in &t {
                at += s.translate;
                assert!(at.length() <= 0.12 + 1e-9, "wandered {} m", at.length());
            }
            let turned = t.iter().fold(glam::DVec3::ZERO, |a, s| a + s.rotate);
            assert!(turned.y.abs() <= 25f64.to_radians() + 1e-9);
            assert!(moving.iter().all(|s| (0.3..=0.9).contains(&s.duration)));
        }
    }

    #[test]
    fn handling_is_drawn_at_the_players_scale() {
        let mut a = SynthRng::from_u64(3);
        let mut b = SynthRng::from_u64(3);
        let small = plan(Handling::Lift, 0.5, &mut a);
        let big = plan(Handling::Lift, 2.0, &mut b);
        assert!((big[0].translate.y / small[0].translate.y - 4.0).abs() < 1e-9);
        assert!(big[0].duration > small[0].duration);
    }

    #[test]
    fn names_round_trip() {
        for h in Handling::ALL {
            assert_eq!(h.name().parse::<Handling>(), Ok(h));
        }
        assert!("wave".parse::<Handling>().is_err());
    }
}
