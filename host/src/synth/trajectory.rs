//! The clean (noise-free) 6-DoF trajectory of a doodle: a timeline of strokes.
//!
//! A *stroke* is one continuous movement of the figurine — one hop, one thrust, one tilt — given
//! relative to the figurine's pose when the stroke starts: a translation in the *heading frame*
//! (the figurine's facing direction projected on the floor: +X left, +Y up, +Z forward, metres),
//! a bump (arc) added at mid-stroke (e.g. the height of a hop), rotation deltas about the
//! figurine's axes, and a velocity profile ([`Profile`]) that says how progress unfolds in time.
//! A stroke with no motion is a hold (the figurine kept still).
//!
//! Orientation is kept as yaw (about world +Y, positive turns toward the figurine's left),
//! pitch (about the figurine's +X, positive tips the front down) and roll (about its +Z,
//! positive tips the top toward its right); the quaternion is `Ry(yaw)·Rx(pitch)·Rz(roll)·tilt`,
//! where `tilt` is the small constant offset of how the toy is held.

use glam::{DQuat, DVec3};

use super::effort::Profile;

/// One continuous movement, relative to the pose at its start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stroke {
    /// Duration, seconds (> 0).
    pub duration: f64,
    /// Net displacement in the heading frame, metres.
    pub translate: DVec3,
    /// Displacement bump `arc·sin(π s)` in the heading frame, metres (0 at both ends).
    pub arc: DVec3,
    /// Net (pitch, yaw, roll) change, radians.
    pub rotate: DVec3,
    /// Rotation bump `rot_arc·sin(π s)` as (pitch, yaw, roll), radians.
    pub rot_arc: DVec3,
    /// Centre of the stroke's rotation relative to the tracked point, in the figurine's own
    /// frame at the stroke's start, metres (zero: rotate about the tracked point). A bow pivots
    /// about the feet below; a child spinning the toy in the fingers swings it about the grip.
    pub pivot: DVec3,
    /// Progress over time.
    pub profile: Profile,
}

impl Stroke {
    /// A still hold of `duration` seconds.
    pub fn hold(duration: f64) -> Self {
        Self::moving(duration, Profile::smooth())
    }

    /// A stroke of `duration` seconds with no motion yet; set the motion fields after.
    pub fn moving(duration: f64, profile: Profile) -> Self {
        Self {
            duration,
            translate: DVec3::ZERO,
            arc: DVec3::ZERO,
            rotate: DVec3::ZERO,
            rot_arc: DVec3::ZERO,
            pivot: DVec3::ZERO,
            profile,
        }
    }

    /// `true` when the stroke moves nothing.
    pub fn is_hold(&self) -> bool {
        // The pivot alone moves nothing: it only matters when something rotates.
        self.translate == DVec3::ZERO
            && self.arc == DVec3::ZERO
            && self.rotate == DVec3::ZERO
            && self.rot_arc == DVec3::ZERO
    }
}

/// Pose of the figurine in the generator's own terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyState {
    /// World position, metres.
    pub pos: DVec3,
    /// Heading, radians about world +Y.
    pub yaw: f64,
    /// Pitch about the figurine's +X, radians (positive: front down).
    pub pitch: f64,
    /// Roll about the figurine's +Z, radians.
    pub roll: f64,
}

impl BodyState {
    /// Orientation object→world, with the constant hold `tilt` applied in the object frame.
    pub fn quat(&self, tilt: DQuat) -> DQuat {
        DQuat::from_rotation_y(self.yaw)
            * DQuat::from_rotation_x(self.pitch)
            * DQuat::from_rotation_z(self.roll)
            * tilt
    }

    /// The state a fraction `s` (progress) through `stroke`.
    fn advance(&self, stroke: &Stroke, s: f64) -> Self {
        let bump = (std::f64::consts::PI * s.clamp(-0.3, 1.3)).sin();
        let local = stroke.translate * s + stroke.arc * bump;
        let rot = stroke.rotate * s + stroke.rot_arc * bump;
        let mut next = Self {
            pos: self.pos + DQuat::from_rotation_y(self.yaw) * local,
            pitch: self.pitch + rot.x,
            yaw: self.yaw + rot.y,
            roll: self.roll + rot.z,
        };
        if stroke.pivot != DVec3::ZERO {
            // Rotating about c = p + q0·pivot moves the tracked point by
            // q0·pivot − (q1·q0⁻¹)·(q0·pivot).
            let q0 = self.quat(DQuat::IDENTITY);
            let q1 = next.quat(DQuat::IDENTITY);
            let arm = q0 * stroke.pivot;
            next.pos += arm - (q1 * q0.inverse()) * arm;
        }
        next
    }
}

#[derive(Debug, Clone)]
struct Placed {
    start: f64,
    state: BodyState,
    stroke: Stroke,
}

/// A timeline of strokes starting at a given time and state; evaluable at any time.
#[derive(Debug, Clone)]
pub struct Trajectory {
    start: f64,
    initial: BodyState,
    placed: Vec<Placed>,
    end: f64,
    last: BodyState,
}

impl Trajectory {
    /// An empty timeline beginning at `start` seconds in `state`.
    pub fn new(start: f64, state: BodyState) -> Self {
        Self {
            start,
            initial: state,
            placed: Vec::new(),
            end: start,
            last: state,
        }
    }

    /// Appends a stroke after the current end; non-positive or non-finite durations are
    /// skipped.
    pub fn push(&mut self, stroke: Stroke) {
        if !(stroke.duration.is_finite() && stroke.duration > 0.0) {
            return;
        }
        let state = self.last;
        self.last = state.advance(&stroke, 1.0);
        self.placed.push(Placed {
            start: self.end,
            state,
            stroke,
        });
        self.end += stroke.duration;
    }

    /// Appends all strokes in order.
    pub fn extend(&mut self, strokes: impl IntoIterator<Item = Stroke>) {
        for s in strokes {
            self.push(s);
        }
    }

    /// Start time, seconds.
    pub fn start(&self) -> f64 {
        self.start
    }

    /// End time (after the last stroke), seconds.
    pub fn end(&self) -> f64 {
        self.end
    }

    /// The state after the last stroke.
    pub fn last_state(&self) -> BodyState {
        self.last
    }

    /// The state at time `t` (clamped to the timeline).
    pub fn state_at(&self, t: f64) -> BodyState {
        if self.placed.is_empty() || t <= self.start || !t.is_finite() {
            return if t.is_finite() && t >= self.end {
                self.last
            } else {
                self.initial
            };
        }
        if t >= self.end {
            return self.last;
        }
        // Last stroke starting at or before t.
        let i = self
            .placed
            .partition_point(|p| p.start <= t)
            .saturating_sub(1);
        let p = &self.placed[i];
        let tau = (t - p.start) / p.stroke.duration;
        if p.stroke.is_hold() {
            return p.state;
        }
        p.state
            .advance(&p.stroke, p.stroke.profile.progress(tau, p.stroke.duration))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn origin() -> BodyState {
        BodyState {
            pos: DVec3::new(1.0, 1.0, 1.0),
            yaw: 0.0,
            pitch: 0.0,
            roll: 0.0,
        }
    }

    #[test]
    fn forward_follows_heading_and_hops_return_to_ground() {
        let mut tr = Trajectory::new(2.0, origin());
        let mut turn = Stroke::moving(0.5, Profile::smooth());
        turn.rotate.y = std::f64::consts::FRAC_PI_2;
        tr.push(turn);
        let mut hop = Stroke::moving(0.4, Profile::smooth());
        hop.translate.z = 0.1;
        hop.arc.y = 0.05;
        tr.push(hop);
        tr.push(Stroke::hold(0.3));
        assert!((tr.end() - 3.2).abs() < 1e-12);
        let end = tr.state_at(10.0);
        // Facing +X (left of the original +Z) after a +90° yaw.
        assert!(
            (end.pos - DVec3::new(1.1, 1.0, 1.0)).length() < 1e-9,
            "{:?}",
            end.pos
        );
        let mid = tr.state_at(2.5 + 0.2);
        assert!(mid.pos.y > 1.04);
        let q = end.quat(DQuat::IDENTITY);
        assert!((q * DVec3::Z - DVec3::X).length() < 1e-9);
        assert_eq!(tr.state_at(0.0), origin());
        assert_eq!(tr.state_at(f64::NAN), origin());
    }

    #[test]
    fn a_bow_pivots_about_the_feet() {
        let r = 0.05;
        let theta = 0.6_f64;
        let mut tr = Trajectory::new(0.0, origin());
        let mut down = Stroke::moving(1.0, Profile::smooth());
        down.rotate.x = theta;
        down.pivot = DVec3::new(0.0, -r, 0.0);
        tr.push(down);
        let mut up = down;
        up.rotate.x = -theta;
        tr.push(up);
        let mid = tr.state_at(1.0);
        let expect = origin().pos + DVec3::new(0.0, r * theta.cos() - r, r * theta.sin());
        assert!((mid.pos - expect).length() < 1e-12, "{:?}", mid.pos);
        assert!((tr.state_at(2.0).pos - origin().pos).length() < 1e-12);
        // Feet stay put throughout.
        for i in 0..=20 {
            let st = tr.state_at(i as f64 * 0.1);
            let feet = st.pos + st.quat(DQuat::IDENTITY) * DVec3::new(0.0, -r, 0.0);
            assert!((feet - DVec3::new(1.0, 1.0 - r, 1.0)).length() < 1e-12);
        }
    }

    #[test]
    fn bad_durations_are_skipped() {
        let mut tr = Trajectory::new(0.0, origin());
        tr.push(Stroke::hold(f64::NAN));
        tr.push(Stroke::hold(-1.0));
        tr.push(Stroke::hold(0.0));
        assert_eq!(tr.end(), 0.0);
        assert_eq!(tr.state_at(0.5), origin());
    }
}
