//! Mirror images of clips: a step to the right becomes a step to the left.
//!
//! The clip is reflected through the body's sagittal plane — the plane through the rest pose's
//! up and forward axes, whose normal is the rest pose's left → right hip direction — and each
//! left joint takes its right twin's motion and the other way round. Twins are found by name
//! (`left`/`right`, `Left`/`Right`, `l_`/`r_`, `.L`/`.R` …); a joint without a twin keeps its
//! own motion, reflected. A reflection keeps rotation angles but turns each rotation's axis
//! `a` into `−M a` (`M` the reflection), so a quaternion (w, v) becomes (w, −M v).
//!
//! This is only a mirror image when the rest pose is itself symmetric (each twin's offset the
//! reflection of the other's), as DeepMimic's humanoid is; [`mirror`] refuses other rigs.

use glam::{Quat, Vec2, Vec3};

use super::trajectory::{ground, yaw_between, Polyline};
use super::AnimError;
use crate::graph::roles::{Role, RoleMap, RoleOverrides};
use crate::motion::{Clip, Skeleton};

/// Appended to a variant's name for its mirror image.
pub const MIRRORED_SUFFIX: &str = "~mirrored";

/// Largest gap between a twin's rest offset and the reflection of the other's, in the
/// skeleton's unit relative to its height, under which a rig counts as symmetric.
pub const SYMMETRY_TOLERANCE: f32 = 0.01;

/// The name of a joint's twin on the other side, if the name has a side marker.
fn twin_name(name: &str) -> Option<String> {
    for (a, b) in [
        ("left", "right"),
        ("Left", "Right"),
        ("LEFT", "RIGHT"),
        ("right", "left"),
        ("Right", "Left"),
        ("RIGHT", "LEFT"),
    ] {
        if name.contains(a) {
            return Some(name.replacen(a, b, 1));
        }
    }
    for (a, b) in [("l_", "r_"), ("r_", "l_"), ("L_", "R_"), ("R_", "L_")] {
        if let Some(rest) = name.strip_prefix(a) {
            return Some(format!("{b}{rest}"));
        }
    }
    for (a, b) in [(".L", ".R"), (".R", ".L"), ("_l", "_r"), ("_r", "_l")] {
        if let Some(rest) = name.strip_suffix(a) {
            return Some(format!("{rest}{b}"));
        }
    }
    None
}

/// Each joint's twin (itself when it has none).
fn twins(sk: &Skeleton) -> Vec<usize> {
    (0..sk.len())
        .map(|j| {
            twin_name(&sk.joints[j].name)
                .and_then(|n| sk.find(&n))
                .unwrap_or(j)
        })
        .collect()
}

/// The mirror image of `clip` (see the module doc); an error if its rig is not symmetric.
pub fn mirror(clip: &Clip) -> Result<Clip, AnimError> {
    let sk = &clip.skeleton;
    let roles = RoleMap::detect(sk, &RoleOverrides::new(), &clip.name)
        .map_err(|e| AnimError::Data(e.to_string()))?;
    let rest = sk.rest_positions();
    let across = rest[roles.joint(Role::RightHip)] - rest[roles.joint(Role::LeftHip)];
    let n = Vec3::new(across.x, 0.0, across.z).normalize_or(Vec3::Z);
    let reflect = |v: Vec3| v - 2.0 * v.dot(n) * n;
    let turn = |q: Quat| {
        let v = -reflect(Vec3::new(q.x, q.y, q.z));
        Quat::from_xyzw(v.x, v.y, v.z, q.w)
    };
    let twin = twins(sk);
    let height = rest.iter().map(|p| p.y).fold(f32::NEG_INFINITY, f32::max)
        - rest.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
    for (j, &t) in twin.iter().enumerate() {
        let gap = (sk.joints[t].offset - reflect(sk.joints[j].offset)).length();
        if gap > SYMMETRY_TOLERANCE * height.max(1e-6) {
            return Err(AnimError::Data(format!(
                "{}: cannot mirror: joint {} is {gap:.3} from the mirror image of {} in the \
                 rest pose (the rig is not symmetric)",
                clip.name, sk.joints[t].name, sk.joints[j].name
            )));
        }
    }
    let mut out = clip.clone();
    for (p, src) in out.frames.iter_mut().zip(&clip.frames) {
        for (j, &t) in twin.iter().enumerate() {
            p.rotations[j] = turn(src.rotations[t]);
            p.translations[j] = reflect(src.translations[t]);
        }
    }
    Ok(out)
}

/// Whether a clip that steps to one side should play as its mirror image `mirrored` along
/// `path` (a moving action's ground path, relative to its start): whichever leaves the
/// character facing nearest `heading` once its travel is turned onto the path — a step to the
/// right when the path runs to the right of the heading, to the left otherwise. `forward` is
/// the rig's facing in its clips. Without a mirror image, or a path to read, it plays as it is.
pub fn plays_mirrored(
    clip: &Clip,
    mirrored: Option<&Clip>,
    path: &Polyline,
    heading: Vec2,
    forward: Vec3,
) -> bool {
    let (Some(m), Some(along)) = (mirrored, path.tangent_at(0.0, 0.3)) else {
        return false;
    };
    let facing_along = |c: &Clip| {
        let root = c.root_path();
        let (Some(a), Some(b)) = (root.first(), root.last()) else {
            return f32::NEG_INFINITY;
        };
        let q0 = c.frames.first().map_or(Quat::IDENTITY, |p| p.rotations[0]);
        let travel = ground(*b - *a).normalize_or(Vec2::X);
        let facing = ground(q0 * forward).normalize_or(Vec2::X);
        let world = ground(yaw_between(travel, along) * Vec3::new(facing.x, 0.0, facing.y));
        world.dot(heading)
    };
    facing_along(m) > facing_along(clip)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::motion::{Joint, Pose};

    fn rig() -> Skeleton {
        stick_figure("root")
    }

    /// A symmetric stick figure facing +X (its right towards +Z) rooted at `root`.
    pub(crate) fn stick_figure(root: &str) -> Skeleton {
        let j = |name: &str, parent: Option<usize>, offset: Vec3| Joint::bare(name, parent, offset);
        Skeleton {
            joints: vec![
                j(root, None, Vec3::ZERO),
                j("left_hip", Some(0), Vec3::new(0.0, -0.1, -0.1)),
                j("left_knee", Some(1), Vec3::new(0.0, -0.4, 0.0)),
                j("left_ankle", Some(2), Vec3::new(0.0, -0.4, 0.0)),
                j("right_hip", Some(0), Vec3::new(0.0, -0.1, 0.1)),
                j("right_knee", Some(4), Vec3::new(0.0, -0.4, 0.0)),
                j("right_ankle", Some(5), Vec3::new(0.0, -0.4, 0.0)),
                j("chest", Some(0), Vec3::new(0.0, 0.3, 0.0)),
                j("neck", Some(7), Vec3::new(0.0, 0.2, 0.0)),
                j("head", Some(8), Vec3::new(0.0, 0.1, 0.0)),
                j("left_shoulder", Some(7), Vec3::new(0.0, 0.1, -0.2)),
                j("left_elbow", Some(10), Vec3::new(0.0, -0.3, 0.0)),
                j("left_wrist", Some(11), Vec3::new(0.0, -0.25, 0.0)),
                j("right_shoulder", Some(7), Vec3::new(0.0, 0.1, 0.2)),
                j("right_elbow", Some(13), Vec3::new(0.0, -0.3, 0.0)),
                j("right_wrist", Some(14), Vec3::new(0.0, -0.25, 0.0)),
            ],
        }
    }

    #[test]
    fn a_mirrored_pose_is_the_reflection_of_the_original() {
        let sk = rig();
        let mut pose = Pose::rest(&sk);
        pose.translations[0] = Vec3::new(0.3, 0.9, 0.5);
        pose.rotations[0] = Quat::from_rotation_y(0.4) * Quat::from_rotation_x(0.2);
        pose.rotations[1] = Quat::from_rotation_z(0.7) * Quat::from_rotation_x(-0.3);
        pose.rotations[5] = Quat::from_rotation_z(-0.9);
        pose.rotations[13] = Quat::from_rotation_x(1.1);
        let clip = Clip {
            name: "t".into(),
            skeleton: sk.clone(),
            frame_time: 1.0 / 30.0,
            frames: vec![pose],
        };
        let m = mirror(&clip).unwrap();
        let (a, b) = (clip.joint_positions(0), m.joint_positions(0));
        let flip = |v: Vec3| Vec3::new(v.x, v.y, -v.z);
        for (j, t) in twins(&sk).into_iter().enumerate() {
            assert!(
                (b[t] - flip(a[j])).length() < 1e-5,
                "joint {j}: {} vs {}",
                b[t],
                a[j]
            );
        }
        // Mirroring twice gives the clip back.
        let back = mirror(&m).unwrap();
        for (p, q) in back.frames[0]
            .rotations
            .iter()
            .zip(&clip.frames[0].rotations)
        {
            assert!(p.angle_between(*q) < 1e-4);
        }
    }

    #[test]
    fn an_asymmetric_rig_is_refused() {
        let mut sk = rig();
        sk.joints[4].offset.z = 0.3;
        let clip = Clip {
            name: "lopsided".into(),
            frames: vec![Pose::rest(&sk)],
            skeleton: sk,
            frame_time: 1.0 / 30.0,
        };
        let err = mirror(&clip).unwrap_err().to_string();
        assert!(err.contains("not symmetric"), "{err}");
    }
}
