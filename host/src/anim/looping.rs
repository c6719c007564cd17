//! Looping clips: repeating a clip seamlessly when an action outlasts it.
//!
//! Two things make a repeat seamless:
//! - **the root carries on**: cycle k starts where cycle k − 1 ended — the clip turned by k ×
//!   its own yaw per cycle and shifted by the earlier cycles' ground displacements (none for
//!   anchored clips) — so the character never snaps back to where the clip began
//!   ([`cycle_frames`]);
//! - **the joints close**: motion-capture loops rarely end exactly on their first pose
//!   (DeepMimic's walk ends 28° away at the right shoulder). Per joint, the rotation
//!   `first · last⁻¹` is spread over the cycle, a growing share of it applied as the cycle
//!   plays ([`loop_closure`], [`close_loop`]), so a cycle's end meets the next one's start.

use glam::{Quat, Vec2, Vec3};

use super::trajectory::{ground, yaw};
use crate::motion::{Clip, Pose};

/// Per cycle k of `cycles`: (ground offset, turn about +Y) placing the clip's cycle k in the
/// frame of cycle 0. `forward` is the rig's facing in its root frame; `anchor` drops the
/// ground displacement (the clip's drift is removed elsewhere).
pub fn cycle_frames(clip: &Clip, forward: Vec3, anchor: bool, cycles: usize) -> Vec<(Vec2, Quat)> {
    let (Some(first), Some(last)) = (clip.frames.first(), clip.frames.last()) else {
        return vec![(Vec2::ZERO, Quat::IDENTITY)];
    };
    let (Some(&q0), Some(&ql)) = (first.rotations.first(), last.rotations.first()) else {
        return vec![(Vec2::ZERO, Quat::IDENTITY)];
    };
    let (Some(&r0), Some(&rl)) = (first.translations.first(), last.translations.first()) else {
        return vec![(Vec2::ZERO, Quat::IDENTITY)];
    };
    let a = ground(q0 * forward).normalize_or(Vec2::X);
    let b = ground(ql * forward).normalize_or(Vec2::X);
    let turn_per_cycle = Quat::from_rotation_y(yaw(b) - yaw(a));
    let step = if anchor { Vec2::ZERO } else { ground(rl - r0) };
    let mut out = Vec::with_capacity(cycles.max(1));
    let (mut off, mut turn) = (Vec2::ZERO, Quat::IDENTITY);
    for _ in 0..cycles.max(1) {
        out.push((off, turn));
        off += ground(turn * Vec3::new(step.x, 0.0, step.y));
        turn = (turn_per_cycle * turn).normalize();
    }
    out
}

/// Per joint (the root's entry unused): the local rotation taking the clip's last pose onto
/// its first, `first · last⁻¹`, on the shorter arc.
pub fn loop_closure(clip: &Clip) -> Vec<Quat> {
    let (Some(first), Some(last)) = (clip.frames.first(), clip.frames.last()) else {
        return Vec::new();
    };
    first
        .rotations
        .iter()
        .zip(&last.rotations)
        .map(|(a, b)| {
            let d = (*a * b.inverse()).normalize();
            if d.w < 0.0 {
                -d
            } else {
                d
            }
        })
        .collect()
}

/// Applies the share `u` ∈ [0, 1] (source time / clip duration) of the loop closure to a
/// pose's non-root joints (the root's turn is the cycle's own, kept).
pub fn close_loop(pose: &mut Pose, closure: &[Quat], u: f32) {
    let u = if u.is_finite() {
        u.clamp(0.0, 1.0)
    } else {
        0.0
    };
    for (r, d) in pose.rotations.iter_mut().zip(closure).skip(1) {
        *r = (Quat::IDENTITY.slerp(*d, u) * *r).normalize();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::{Joint, Skeleton};

    fn clip(last_root: Vec3, last_yaw: f32, last_spine: f32) -> Clip {
        let j = Joint::bare;
        let sk = Skeleton {
            joints: vec![j("root", None, Vec3::ZERO), j("spine", Some(0), Vec3::Y)],
        };
        let mut a = Pose::rest(&sk);
        let mut b = Pose::rest(&sk);
        b.translations[0] = last_root;
        b.rotations[0] = Quat::from_rotation_y(last_yaw);
        b.rotations[1] = Quat::from_rotation_z(last_spine);
        a.translations[0] = Vec3::ZERO;
        Clip {
            name: "c".into(),
            skeleton: sk,
            frame_time: 0.1,
            frames: vec![a, b],
        }
    }

    #[test]
    fn cycles_chain_displacement_and_turn() {
        let c = clip(Vec3::new(1.0, 0.0, 0.0), std::f32::consts::FRAC_PI_2, 0.0);
        let f = cycle_frames(&c, Vec3::X, false, 3);
        assert_eq!(f.len(), 3);
        assert!(f[0].0.length() < 1e-6);
        assert!((f[1].0 - Vec2::new(1.0, 0.0)).length() < 1e-5, "{:?}", f[1]);
        // After a quarter turn the second step goes sideways: cycle 2 starts at (1, ±1).
        assert!((f[2].0.x - 1.0).abs() < 1e-5 && (f[2].0.y.abs() - 1.0).abs() < 1e-5);
        // Cycle k's start equals cycle k − 1's end.
        let end_of = |k: usize| {
            let (off, turn) = f[k];
            off + ground(turn * Vec3::new(1.0, 0.0, 0.0))
        };
        assert!((end_of(1) - f[2].0).length() < 1e-5);
        let anchored = cycle_frames(&c, Vec3::X, true, 3);
        assert!(anchored.iter().all(|(o, _)| o.length() < 1e-6));
        assert_eq!(cycle_frames(&c, Vec3::X, false, 0).len(), 1);
    }

    #[test]
    fn closure_takes_the_last_pose_onto_the_first() {
        let c = clip(Vec3::ZERO, 0.0, 0.4);
        let d = loop_closure(&c);
        let mut last = c.frames[1].clone();
        close_loop(&mut last, &d, 1.0);
        assert!(last.rotations[1].angle_between(c.frames[0].rotations[1]) < 1e-4);
        let mut first = c.frames[0].clone();
        close_loop(&mut first, &d, 0.0);
        assert_eq!(first, c.frames[0]);
        close_loop(&mut first, &d, f32::NAN);
        assert_eq!(first, c.frames[0]);
    }
}
