//! Joint limits: effort may amplify a limb's swing, but never bend a knee or an elbow
//! backwards.
//!
//! Eq. 7 rescales each joint's rotation away from a stage's reference pose by `c` (up to 2 for
//! a strong Weight). For a ball joint that widens a swing; for a hinge — a knee, an elbow — a
//! straightening amplified past straight is a joint bent backwards, which no person does. So
//! the hinges of each source clip are found (joints whose rotations in the clip all turn about
//! one axis, and bend one way on the whole), and after effort transfer each hinge's bend about
//! that axis is held between the straightest the source itself went (or straight, whichever
//! is straighter) and [`MAX_BEND_RAD`]. The rest of the rotation (its swing off the axis) is
//! kept.
//!
//! | hinge test | value |
//! |---|---|
//! | frames turning about the common axis (\|cos\| ≥ [`AXIS_AGREEMENT`]) | ≥ [`AXIS_SHARE`] of those that turn |
//! | mean bend | ≥ [`MIN_MEAN_BEND_RAD`] |
//!
//! Ball joints (hips, shoulders, the spine) have no single axis, but people still move them
//! within a range: amplifying a run's hip swing twofold about the cycle's first pose splits the
//! legs nearly 180°, which no runner does. [`JointRanges`] learns each joint's range from the
//! clip library's own takes — per joint, the box its local rotation (as a rotation vector,
//! axis × angle) stays in over every frame of every clip — and after effort transfer each
//! joint is held within it. Pooling the library's takes leaves effort room: a strong run may
//! lift a knee as high as the kick does, but no hip extends further back than any actor's did.

use glam::{Quat, Vec3};

use crate::motion::Clip;

/// Least |cos| between a frame's rotation axis and the joint's common axis.
pub const AXIS_AGREEMENT: f32 = 0.9;
/// Share of a joint's turning frames that must agree with the common axis for it to be a
/// hinge.
pub const AXIS_SHARE: f32 = 0.9;
/// Rotation (rad) under which a frame tells nothing about the axis.
pub const TURNING_RAD: f32 = 0.1;
/// Mean bend (rad) under which a joint is no hinge worth guarding (it barely bends).
pub const MIN_MEAN_BEND_RAD: f32 = 0.2;
/// The most a knee or an elbow folds, rad (150°).
pub const MAX_BEND_RAD: f32 = 2.6;

/// A hinge joint of a source clip and the range it may bend in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hinge {
    /// The joint.
    pub joint: usize,
    /// Its axis, in its parent's frame, oriented so that bending is a positive turn.
    pub axis: Vec3,
    /// The straightest bend allowed, rad (≤ 0: straight, or the source's own overextension).
    pub least: f32,
    /// The deepest bend allowed, rad.
    pub most: f32,
}

/// The signed turn (rad) of `q` about the unit `axis`: the twist of its swing–twist split.
fn twist_angle(q: Quat, axis: Vec3) -> f32 {
    let q = if q.w < 0.0 { -q } else { q };
    2.0 * Vec3::new(q.x, q.y, q.z).dot(axis).atan2(q.w)
}

/// The hinges of `clip` (see the module docs).
pub fn find_hinges(clip: &Clip) -> Vec<Hinge> {
    let mut out = Vec::new();
    for joint in 1..clip.skeleton.len() {
        let rotations: Vec<Quat> = clip
            .frames
            .iter()
            .filter_map(|p| p.rotations.get(joint).copied())
            .filter(|q| q.is_finite())
            .map(|q| if q.w < 0.0 { -q } else { q }.normalize())
            .collect();
        let axes: Vec<Vec3> = rotations
            .iter()
            .map(|q| q.to_axis_angle())
            .filter(|(a, angle)| *angle > TURNING_RAD && a.is_finite())
            .map(|(a, _)| a)
            .collect();
        let Some(&first) = axes.first() else { continue };
        let sum: Vec3 = axes
            .iter()
            .map(|a| if a.dot(first) < 0.0 { -*a } else { *a })
            .sum();
        let Some(axis) = sum.try_normalize() else {
            continue;
        };
        let agree = axes
            .iter()
            .filter(|a| a.dot(axis).abs() >= AXIS_AGREEMENT)
            .count();
        if (agree as f32) < AXIS_SHARE * axes.len() as f32 {
            continue;
        }
        let angles: Vec<f32> = rotations.iter().map(|q| twist_angle(*q, axis)).collect();
        let mean = angles.iter().sum::<f32>() / angles.len() as f32;
        if mean.abs() < MIN_MEAN_BEND_RAD {
            continue;
        }
        // Bending is a positive turn about the axis.
        let (axis, sign) = if mean < 0.0 {
            (-axis, -1.0)
        } else {
            (axis, 1.0)
        };
        let bends = angles.iter().map(|a| a * sign);
        let least = bends.clone().fold(f32::INFINITY, f32::min).min(0.0);
        let most = bends.fold(f32::NEG_INFINITY, f32::max).max(MAX_BEND_RAD);
        out.push(Hinge {
            joint,
            axis,
            least,
            most,
        });
    }
    out
}

/// Holds every hinge of `hinges` within its range in `clip`, keeping the swing off its axis.
/// Returns how many joint rotations it changed.
pub fn limit_hinges(hinges: &[Hinge], clip: &mut Clip) -> usize {
    let mut changed = 0;
    for pose in &mut clip.frames {
        for h in hinges {
            let Some(q) = pose.rotations.get_mut(h.joint) else {
                continue;
            };
            let bend = twist_angle(*q, h.axis);
            let held = bend.clamp(h.least, h.most);
            if held == bend || !bend.is_finite() {
                continue;
            }
            let twist = Quat::from_axis_angle(h.axis, bend);
            let swing = *q * twist.inverse();
            *q = (swing * Quat::from_axis_angle(h.axis, held)).normalize();
            changed += 1;
        }
    }
    changed
}

/// Per joint, the range its local rotation stays in over a set of takes: the box (per
/// component, radians) of its rotation vector (axis × angle, on the shorter arc). The root's
/// entry is unused: its rotation is the body's facing.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointRanges {
    /// Per joint: (least, greatest) rotation-vector components, radians.
    pub boxes: Vec<(Vec3, Vec3)>,
}

/// Rotation vector (axis × angle, radians) of `q` on the shorter arc.
fn rotation_vector(q: Quat) -> Vec3 {
    let q = if q.w < 0.0 { -q } else { q };
    q.normalize().to_scaled_axis()
}

impl JointRanges {
    /// The ranges of every joint over all frames of `clips` (which share one skeleton; a clip
    /// with another joint count is skipped). Empty without clips.
    pub fn learn<'a>(clips: impl IntoIterator<Item = &'a Clip>) -> JointRanges {
        let mut boxes: Vec<(Vec3, Vec3)> = Vec::new();
        for clip in clips {
            let n = clip.skeleton.len();
            if boxes.is_empty() {
                boxes = vec![(Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)); n];
            }
            if boxes.len() != n {
                continue;
            }
            for pose in &clip.frames {
                for (b, q) in boxes.iter_mut().zip(&pose.rotations) {
                    let v = rotation_vector(*q);
                    if v.is_finite() {
                        *b = (b.0.min(v), b.1.max(v));
                    }
                }
            }
        }
        JointRanges { boxes }
    }

    /// Whether joint `joint`'s local rotation `q` lies within its range (true for a joint
    /// without one).
    pub fn contains(&self, joint: usize, q: Quat) -> bool {
        let Some(&(lo, hi)) = self.boxes.get(joint) else {
            return true;
        };
        if !(lo.is_finite() && hi.is_finite()) {
            return true;
        }
        let v = rotation_vector(q);
        v.cmpge(lo).all() && v.cmple(hi).all()
    }

    /// Holds every non-root joint of every frame of `clip` within its range; joints without
    /// a learnt range (none of the takes had frames) are left alone. Returns how many joint
    /// rotations it changed.
    pub fn limit(&self, clip: &mut Clip) -> usize {
        let mut changed = 0;
        for pose in &mut clip.frames {
            for (q, &(lo, hi)) in pose.rotations.iter_mut().zip(&self.boxes).skip(1) {
                if !(lo.is_finite() && hi.is_finite()) {
                    continue;
                }
                let v = rotation_vector(*q);
                let held = v.clamp(lo, hi);
                if v.is_finite() && held != v {
                    *q = Quat::from_scaled_axis(held).normalize();
                    changed += 1;
                }
            }
        }
        changed
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::{Joint, Pose, Skeleton};

    /// A leg (hip → knee → ankle) whose knee bends `bends[f]` rad about +X in frame `f`.
    fn leg(bends: &[f32]) -> Clip {
        let skeleton = Skeleton {
            joints: vec![
                Joint::bare("hip", None, Vec3::ZERO),
                Joint::bare("knee", Some(0), Vec3::new(0.0, -0.4, 0.0)),
                Joint::bare("ankle", Some(1), Vec3::new(0.0, -0.4, 0.0)),
            ],
        };
        let frames = bends
            .iter()
            .map(|&b| {
                let mut p = Pose::rest(&skeleton);
                p.rotations[1] = Quat::from_rotation_x(b);
                p
            })
            .collect();
        Clip {
            name: "leg".into(),
            skeleton,
            frame_time: 1.0 / 30.0,
            frames,
        }
    }

    #[test]
    fn a_knee_amplified_past_straight_is_held_straight_and_its_fold_is_kept() {
        let src = leg(&[0.1, 0.6, 1.2, 0.4]);
        let hinges = find_hinges(&src);
        assert_eq!(hinges.len(), 1, "{hinges:?}");
        assert_eq!(hinges[0].joint, 1);
        // Rescaled by 2 about the deepest bend: 1.2 − 2·(1.2 − b): −0.8 is backwards.
        let mut out = leg(&[-0.8, 0.2, 1.2, -0.4]);
        assert_eq!(limit_hinges(&hinges, &mut out), 2);
        let bend = |c: &Clip, f: usize| twist_angle(c.frames[f].rotations[1], Vec3::X);
        for (f, want) in [(0, 0.0), (1, 0.2), (2, 1.2), (3, 0.0)] {
            assert!(
                (bend(&out, f) - want).abs() < 1e-5,
                "frame {f}: {}",
                bend(&out, f)
            );
        }
        // Folded past 150°: held at it.
        let mut deep = leg(&[2.9]);
        limit_hinges(&hinges, &mut deep);
        assert!((bend(&deep, 0) - MAX_BEND_RAD).abs() < 1e-5);
    }

    #[test]
    fn a_ball_joint_is_held_within_the_range_the_takes_moved_it_in() {
        // Two takes swing the "knee" 0.1–1.2 rad about +X; a rescaled copy swings it to 2.0
        // rad and −0.8 rad, and 0.5 rad about +Z, which no take did.
        let takes = [leg(&[0.1, 0.6]), leg(&[1.2, 0.4])];
        let ranges = JointRanges::learn(&takes);
        let mut out = leg(&[2.0, -0.8, 0.7]);
        out.frames[2].rotations[1] = Quat::from_rotation_x(0.7) * Quat::from_rotation_z(0.5);
        assert_eq!(ranges.limit(&mut out), 3);
        let v = |f: usize| rotation_vector(out.frames[f].rotations[1]);
        assert!(
            (v(0) - Vec3::new(1.2, 0.0, 0.0)).length() < 1e-5,
            "{}",
            v(0)
        );
        assert!(
            (v(1) - Vec3::new(0.1, 0.0, 0.0)).length() < 1e-5,
            "{}",
            v(1)
        );
        assert!(v(2).z.abs() < 1e-5 && v(2).x > 0.6, "{}", v(2));
        // Within range: untouched.
        let mut inside = leg(&[0.5]);
        assert_eq!(ranges.limit(&mut inside), 0);
        assert!(ranges.contains(1, Quat::from_rotation_x(1.0)));
        assert!(!ranges.contains(1, Quat::from_rotation_x(1.3)));
        assert!(JointRanges::learn(std::iter::empty()).boxes.is_empty());
    }

    #[test]
    fn a_joint_that_turns_about_many_axes_or_barely_is_no_hinge() {
        let mut ball = leg(&[0.5, 0.6, 0.7, 0.8]);
        ball.frames[1].rotations[1] = Quat::from_rotation_y(0.6);
        ball.frames[3].rotations[1] = Quat::from_rotation_z(0.8);
        assert!(find_hinges(&ball).is_empty());
        assert!(find_hinges(&leg(&[0.0, 0.05, 0.12, 0.0])).is_empty());
    }
}
