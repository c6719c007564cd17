//! Torso tilt: the angle of the hips → neck line from vertical, per frame, in degrees; a
//! stretch of motion is summed up by its 95th percentile and its maximum ([`TiltFigures`]).
//! `figurine check` prints it, and judges it per kind of action
//! ([`super::tilt_reference`]). Effort transfer bends the spine (eq. 7's rescale, the
//! reshape's sinking and rising); [`hold_torso_tilt`] keeps each frame's tilt within
//! [`HOLD_DEG`] of its source frame's: half of [`super::envelope::TILT_MARGIN_DEG`], how far
//! real takes of one kind differ at different vigour.

use anyhow::{Context, Result};
use glam::Vec3;

use crate::graph::roles::{Role, RoleMap, RoleOverrides};
use crate::motion::{slerp_short, Clip, Pose};

/// Bisection steps finding how far a frame's spine is drawn back towards the source (1/256).
const HOLD_BISECTIONS: usize = 8;

/// How far effort transfer may turn a frame's torso tilt from its source frame's, °: half the
/// margin an action's tilt figures are judged with ([`super::envelope::TILT_MARGIN_DEG`]).
/// The other half is left for what the action's timing does to its figures: a retimed clip
/// is sampled at other instants than its source's frames, and a peak one frame wide is
/// passed between two (a light bow held 11 of 11.6° shallower at its deepest frame showed a
/// deepest frame 2° shallower still), and it spends other shares of its time in each pose
/// (the 95th percentile).
pub const HOLD_DEG: f32 = 0.5 * super::envelope::TILT_MARGIN_DEG;

/// The torso's tilt from vertical (°) with the hips at `hips` and the neck at `neck` (+Y up):
/// 0 upright, 90 lying, 180 upside down; 0 for coincident points.
pub fn tilt_deg(hips: Vec3, neck: Vec3) -> f32 {
    (neck - hips)
        .try_normalize()
        .map_or(0.0, |u| u.dot(Vec3::Y).clamp(-1.0, 1.0).acos().to_degrees())
}

/// The torso's tilt (°) in every frame of `clip` (`name` names it in errors).
pub fn tilt_series(clip: &Clip, name: &str) -> Result<Vec<f32>> {
    let sk = &clip.skeleton;
    let roles = RoleMap::detect(sk, &RoleOverrides::new(), name)
        .with_context(|| format!("{name}: could not find the hips and neck"))?;
    let (hips, neck) = (roles.joint(Role::Hips), roles.joint(Role::Neck));
    Ok(clip
        .frames
        .iter()
        .map(|p| {
            let w = sk.forward(p);
            let at = |j: usize| w.get(j).map_or(Vec3::ZERO, |w| w.position);
            tilt_deg(at(hips), at(neck))
        })
        .collect())
}

/// A stretch of motion's torso tilt, °.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TiltFigures {
    /// 95th percentile over frames.
    pub p95: f32,
    /// Largest.
    pub max: f32,
}

impl TiltFigures {
    /// The figures of a per-frame tilt series (0 for an empty one; non-finite frames skipped).
    pub fn of(series: &[f32]) -> TiltFigures {
        let mut v: Vec<f32> = series.iter().copied().filter(|x| x.is_finite()).collect();
        v.sort_by(f32::total_cmp);
        let at = |q: f32| {
            let i = ((v.len().saturating_sub(1)) as f32 * q).round() as usize;
            v.get(i.min(v.len().saturating_sub(1)))
                .copied()
                .unwrap_or(0.0)
        };
        TiltFigures {
            p95: at(0.95),
            max: at(1.0),
        }
    }
}

/// The joints whose rotations turn the hips → neck line besides the root's: the neck's
/// ancestors below the root (a DeepMimic humanoid's chest; a BVH rig's spine bones).
fn spine_between(clip: &Clip, neck: usize) -> Vec<usize> {
    let sk = &clip.skeleton;
    sk.chain_to(neck)
        .into_iter()
        .filter(|&j| j != neck && sk.joints.get(j).is_some_and(|x| x.parent.is_some()))
        .collect()
}

/// Holds every frame of `out` (the same frames as `src`, after effort transfer) within
/// `margin_deg` of the torso tilt its source frame had: where it leaves, its spine joints
/// between the hips and the neck are drawn back towards the source's by the least share that
/// brings it within. Returns how many frames it changed (0 for a rig without hips and neck).
/// The root's rotation, the body's facing and balance, is effort's to leave alone.
pub fn hold_torso_tilt(src: &Clip, out: &mut Clip, margin_deg: f32) -> usize {
    let Ok(roles) = RoleMap::detect(&src.skeleton, &RoleOverrides::new(), &src.name) else {
        return 0;
    };
    let (hips, neck) = (roles.joint(Role::Hips), roles.joint(Role::Neck));
    let spine = spine_between(src, neck);
    let sk = &src.skeleton;
    let tilt = |p: &Pose| {
        let w = sk.forward(p);
        let at = |j: usize| w.get(j).map_or(Vec3::ZERO, |w| w.position);
        tilt_deg(at(hips), at(neck))
    };
    let mut changed = 0;
    for (s, o) in src.frames.iter().zip(out.frames.iter_mut()) {
        let want = tilt(s);
        if (tilt(o) - want).abs() <= margin_deg {
            continue;
        }
        let drawn = |share: f32| {
            let mut p = o.clone();
            for &j in &spine {
                if let (Some(q), Some(&qs)) = (p.rotations.get_mut(j), s.rotations.get(j)) {
                    *q = slerp_short(*q, qs, share);
                }
            }
            p
        };
        // At share 1 the spine is the source's: the tilt differs by the root's alone, which
        // effort leaves as it was.
        let (mut outside, mut inside) = (0.0f32, 1.0f32);
        for _ in 0..HOLD_BISECTIONS {
            let mid = 0.5 * (outside + inside);
            if (tilt(&drawn(mid)) - want).abs() <= margin_deg {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        *o = drawn(inside);
        changed += 1;
    }
    changed
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn tilt_is_the_angle_from_vertical() {
        assert_eq!(tilt_deg(Vec3::ZERO, Vec3::Y), 0.0);
        assert!((tilt_deg(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0)) - 45.0).abs() < 1e-4);
        assert!((tilt_deg(Vec3::ZERO, Vec3::NEG_Y) - 180.0).abs() < 1e-4);
        assert_eq!(tilt_deg(Vec3::ONE, Vec3::ONE), 0.0);
    }

    #[test]
    fn figures_are_the_95th_percentile_and_the_maximum() {
        let series: Vec<f32> = (0..=100).map(|i| i as f32).collect();
        let f = TiltFigures::of(&series);
        assert_eq!((f.p95, f.max), (95.0, 100.0));
        assert_eq!(TiltFigures::of(&[]), TiltFigures { p95: 0.0, max: 0.0 });
    }

    /// `check`'s stick figure with its spine bent forward by `bends[f]` rad about +X in
    /// frame `f`.
    fn torso(bends: &[f32]) -> Clip {
        crate::anim::check::tests::figure(bends.len(), |f, p| {
            p.rotations[crate::anim::check::tests::SPINE] = Quat::from_rotation_x(bends[f]);
        })
    }

    #[test]
    fn a_spine_bent_beyond_the_margin_is_drawn_back_to_it_and_no_further() {
        let d = |deg: f32| deg.to_radians();
        let src = torso(&[d(10.0), d(40.0), d(60.0)]);
        // Effort bent the first frame 5° further (within 12°), the second 30° further and
        // straightened the third by 25°.
        let mut out = torso(&[d(15.0), d(70.0), d(35.0)]);
        let want = tilt_series(&src, "source").unwrap();
        let before = tilt_series(&out, "bent").unwrap();
        assert!((before[0] - want[0]).abs() < 12.0, "{before:?} {want:?}");
        assert!(before[1] > want[1] + 12.0 && before[2] < want[2] - 12.0);
        assert_eq!(hold_torso_tilt(&src, &mut out, 12.0), 2);
        let after = tilt_series(&out, "held").unwrap();
        assert_eq!(after[0], before[0], "a frame within stays as it was");
        // Drawn back to the margin's edge, within the bisection's resolution.
        let off = |f: usize| (after[f] - want[f]).abs();
        assert!(off(1) <= 12.0 && off(1) > 11.5, "{after:?} {want:?}");
        assert!(off(2) <= 12.0 && off(2) > 11.5, "{after:?} {want:?}");
        assert!(
            after[1] > want[1] && after[2] < want[2],
            "on the side effort bent it"
        );
        let mut same = src.clone();
        assert_eq!(hold_torso_tilt(&src, &mut same, 12.0), 0);
    }
}
