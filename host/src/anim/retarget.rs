//! Retargeting a take onto the clip library's skeleton, so that a clip cut from another rig
//! (LAFAN1's 22-joint BVH rig, say) plays on the library's one (DeepMimic's humanoid) and
//! blends with its other clips joint by joint.
//!
//! Both rigs are read through their body landmarks ([`crate::graph::roles`]), so joint names
//! and counts may differ. Each landmark joint of the target is aimed, frame by frame, the way
//! its counterpart in the take points: its **bone** (towards its child landmark) along the
//! take's bone, and a **second direction** it carries (its forward, or the foot's up) as the
//! take's bone carries it. The second direction fixes the twist about the bone that positions
//! alone cannot (a straight leg says nothing of where its knee faces). In the target's rest
//! pose every joint frame is the world frame, so there its forward is the body's forward; in
//! the take it is measured once, in a calibration frame where the performer stands in a
//! T-pose facing forward (LAFAN1 takes open with one).
//!
//! | target joint | bone towards | second direction |
//! |---|---|---|
//! | hips | chest | left hip → right hip |
//! | chest | neck | left shoulder → right shoulder |
//! | neck | head | left shoulder → right shoulder |
//! | thigh, shin, upper arm, forearm | knee, ankle, elbow, wrist | the bone's forward |
//! | ankle | toe tip | the foot's up |
//!
//! Knees and elbows of the target keep only their bend about the body's left–right axis (the
//! hinge DeepMimic's humanoid has). The root follows the take's hips scaled by the ratio of the
//! rigs' leg lengths, so strides fit the target's legs, and is set at the height where the
//! feet stand on the ground (the lowest foot point's 5th percentile at y = 0). Joints without a
//! landmark keep their rest rotation.

use glam::{Mat3, Quat, Vec3};

use super::AnimError;
use crate::graph::roles::{Role, RoleMap, RoleOverrides};
use crate::motion::{Clip, Pose, Skeleton};

/// Which second direction a joint is aimed by (see the module table).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Second {
    /// The line from the left to the right joint of a pair of landmarks.
    Across(Role, Role),
    /// The joint's forward, as calibrated.
    Forward,
    /// The joint's up, as calibrated.
    Up,
}

/// One aimed joint: the target joint, the take's joint, the child landmarks that give the
/// bone in each rig, and how its twist is fixed.
#[derive(Debug, Clone, Copy)]
struct Aim {
    target: usize,
    source: usize,
    target_child: usize,
    source_child: usize,
    second: Second,
}

/// The tip of a foot: the descendant of the ankle farthest from it in the rest pose.
fn toe_tip(sk: &Skeleton, ankle: usize, rest: &[Vec3]) -> usize {
    let mut best = ankle;
    let mut stack = vec![ankle];
    while let Some(j) = stack.pop() {
        if (rest[j] - rest[ankle]).length() > (rest[best] - rest[ankle]).length() {
            best = j;
        }
        stack.extend(sk.children(j));
    }
    best
}

/// Orthonormal frame (columns) from a primary direction and a second one projected off it.
fn frame(primary: Vec3, second: Vec3) -> Option<Mat3> {
    let p = primary.try_normalize()?;
    let s = (second - p * second.dot(p)).try_normalize()?;
    Some(Mat3::from_cols(p, s, p.cross(s)))
}

/// The rotation carrying `from` (primary, second) onto `to` (primary, second).
fn align(from: (Vec3, Vec3), to: (Vec3, Vec3)) -> Option<Quat> {
    let a = frame(from.0, from.1)?;
    let b = frame(to.0, to.1)?;
    Some(Quat::from_mat3(&(b * a.transpose())).normalize())
}

/// The part of `q` that turns about `axis` (its twist), as a rotation about `axis`.
fn hinge(q: Quat, axis: Vec3) -> Quat {
    let v = Vec3::new(q.x, q.y, q.z);
    let angle = 2.0 * v.dot(axis).atan2(q.w);
    Quat::from_axis_angle(axis, angle)
}

/// Retargets `take` (metres, +Y up) onto `target`: `tpose` is a frame of the take where its
/// performer stands in a T-pose facing forward (it may lie outside `frames`), `frames` the
/// inclusive range of the take to retarget. The result has `target`'s joints and the take's
/// frame time.
pub fn retarget(
    take: &Clip,
    tpose: usize,
    frames: [usize; 2],
    target: &Skeleton,
) -> Result<Clip, AnimError> {
    let n = take.frames.len();
    if tpose >= n || frames[0] > frames[1] || frames[1] >= n {
        return Err(AnimError::Data(format!(
            "{}: retargeting frames {}-{} with the T-pose at {tpose}: the take has {n} frames",
            take.name, frames[0], frames[1]
        )));
    }
    let no_role = |e: crate::graph::GraphError| AnimError::Data(e.to_string());
    let src_roles =
        RoleMap::detect(&take.skeleton, &RoleOverrides::new(), &take.name).map_err(no_role)?;
    let dst_roles = RoleMap::detect(target, &RoleOverrides::new(), "the library's skeleton")
        .map_err(no_role)?;
    let src_rest = take.skeleton.positions(&take.frames[tpose]);
    let dst_rest = target.rest_positions();
    let (s, d) = (|r: Role| src_roles.joint(r), |r: Role| dst_roles.joint(r));
    let across_sh = Second::Across(Role::LeftShoulder, Role::RightShoulder);
    let mut aims = vec![
        (
            Role::Hips,
            Role::Chest,
            Second::Across(Role::LeftHip, Role::RightHip),
        ),
        (Role::Chest, Role::Neck, across_sh),
        (Role::Neck, Role::Head, across_sh),
    ]
    .into_iter()
    .map(|(j, c, second)| Aim {
        target: d(j),
        source: s(j),
        target_child: d(c),
        source_child: s(c),
        second,
    })
    .collect::<Vec<_>>();
    for chain in [
        [Role::LeftHip, Role::LeftKnee, Role::LeftFoot],
        [Role::RightHip, Role::RightKnee, Role::RightFoot],
        [Role::LeftShoulder, Role::LeftElbow, Role::LeftHand],
        [Role::RightShoulder, Role::RightElbow, Role::RightHand],
    ] {
        for w in chain.windows(2) {
            aims.push(Aim {
                target: d(w[0]),
                source: s(w[0]),
                target_child: d(w[1]),
                source_child: s(w[1]),
                second: Second::Forward,
            });
        }
    }
    for foot in [Role::LeftFoot, Role::RightFoot] {
        aims.push(Aim {
            target: d(foot),
            source: s(foot),
            target_child: toe_tip(target, d(foot), &dst_rest),
            source_child: toe_tip(&take.skeleton, s(foot), &src_rest),
            second: Second::Up,
        });
    }
    // Parents before children, so a joint's parent is aimed before it.
    aims.sort_by_key(|a| target.depth(a.target));

    // The body's right and forward in each rig's reference pose.
    let right_of = |p: &[Vec3], r: &RoleMap| {
        let v = p[r.joint(Role::RightHip)] - p[r.joint(Role::LeftHip)];
        Vec3::new(v.x, 0.0, v.z).normalize_or(Vec3::Z)
    };
    let dst_right = right_of(&dst_rest, &dst_roles);
    let src_right = right_of(&src_rest, &src_roles);
    let (dst_fwd, src_fwd) = (Vec3::Y.cross(dst_right), Vec3::Y.cross(src_right));
    let src_world0 = take.skeleton.forward(&take.frames[tpose]);
    // The take's forward and up in each source joint's own frame.
    let calibrated = |j: usize, v: Vec3| src_world0[j].rotation.inverse() * v;

    let leg = |p: &[Vec3], r: &RoleMap| {
        let (h, k, a) = (
            r.joint(Role::LeftHip),
            r.joint(Role::LeftKnee),
            r.joint(Role::LeftFoot),
        );
        (p[k] - p[h]).length() + (p[a] - p[k]).length()
    };
    let ratio = leg(&dst_rest, &dst_roles) / leg(&src_rest, &src_roles).max(1e-6);
    let hinges = [
        Role::LeftKnee,
        Role::RightKnee,
        Role::LeftElbow,
        Role::RightElbow,
    ]
    .map(d);

    let mut out = Vec::with_capacity(frames[1] - frames[0] + 1);
    for f in frames[0]..=frames[1] {
        let world = take.skeleton.forward(&take.frames[f]);
        let at = |j: usize| world[j].position;
        let mut pose = Pose::rest(target);
        for a in &aims {
            let bone_src = at(a.source_child) - at(a.source);
            let bone_dst = dst_rest[a.target_child] - dst_rest[a.target];
            let (second_src, second_dst) = match a.second {
                Second::Across(l, r) => (at(s(r)) - at(s(l)), dst_rest[d(r)] - dst_rest[d(l)]),
                Second::Forward => (
                    world[a.source].rotation * calibrated(a.source, src_fwd),
                    dst_fwd,
                ),
                Second::Up => (
                    world[a.source].rotation * calibrated(a.source, Vec3::Y),
                    Vec3::Y,
                ),
            };
            // Ancestors are aimed first (by depth), so their rotations are final here.
            let parent = target.joints[a.target].parent.map_or(Quat::IDENTITY, |p| {
                target
                    .chain_to(p)
                    .iter()
                    .fold(Quat::IDENTITY, |w, &k| w * pose.rotations[k])
            });
            let want = align((bone_dst, second_dst), (bone_src, second_src)).unwrap_or(parent);
            let local = (parent.inverse() * want).normalize();
            pose.rotations[a.target] = if hinges.contains(&a.target) {
                hinge(local, dst_right)
            } else {
                local
            };
        }
        pose.translations[0] = at(s(Role::Hips)) * ratio;
        out.push(pose);
    }
    let mut clip = Clip {
        name: take.name.clone(),
        skeleton: target.clone(),
        frame_time: take.frame_time,
        frames: out,
    };
    stand_on_ground(&mut clip, &dst_roles);
    Ok(clip)
}

/// Shifts the root so the lowest foot point's 5th percentile over the clip is at y = 0.
fn stand_on_ground(clip: &mut Clip, roles: &RoleMap) {
    let feet = super::sideways::foot_joints(clip, roles);
    let mut lows: Vec<f32> = clip
        .all_positions()
        .iter()
        .map(|p| {
            feet.iter()
                .flatten()
                .map(|&j| p[j].y)
                .fold(f32::INFINITY, f32::min)
        })
        .collect();
    lows.sort_by(f32::total_cmp);
    let ground = lows.get(lows.len() / 20).copied().unwrap_or(0.0);
    if ground.is_finite() {
        for p in &mut clip.frames {
            p.translations[0].y -= ground;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::deepmimic::humanoid_skeleton;
    use crate::motion::urdf::read_urdf_path;

    /// The LAFAN1 test take in metres and DeepMimic's humanoid, if fetched.
    fn data() -> Option<(Clip, Skeleton)> {
        let take = crate::data::data_file("bvh", "lafan_test.bvh")?;
        let urdf = crate::data::data_file("deepmimic", "humanoid.urdf")?;
        let mut clip = crate::motion::read_bvh_path(&take).ok()?.clip;
        clip.scale_lengths(0.01);
        let u = read_urdf_path(&urdf).ok()?;
        Some((clip, humanoid_skeleton(&u, &urdf).ok()?))
    }

    #[test]
    fn retargeted_bones_point_where_the_takes_do() {
        let Some((take, target)) = data() else {
            eprintln!("skipping: LAFAN or DeepMimic data missing — run `cargo xtask setup`");
            return;
        };
        let range = [4873, 4914];
        let out = retarget(&take, 0, range, &target).unwrap();
        assert_eq!(out.len(), range[1] - range[0] + 1);
        let sr = RoleMap::detect(&take.skeleton, &RoleOverrides::new(), "take").unwrap();
        let dr = RoleMap::detect(&target, &RoleOverrides::new(), "target").unwrap();
        let bones = [
            (Role::Hips, Role::Neck),
            (Role::LeftHip, Role::LeftKnee),
            (Role::LeftKnee, Role::LeftFoot),
            (Role::RightHip, Role::RightKnee),
            (Role::RightKnee, Role::RightFoot),
            (Role::LeftShoulder, Role::LeftElbow),
            (Role::LeftElbow, Role::LeftHand),
            (Role::RightShoulder, Role::RightElbow),
            (Role::RightElbow, Role::RightHand),
            (Role::Neck, Role::Head),
        ];
        for (k, f) in (range[0]..=range[1]).enumerate() {
            let (s, d) = (take.joint_positions(f), out.joint_positions(k));
            for (a, b) in bones {
                let u = s[sr.joint(b)] - s[sr.joint(a)];
                let v = d[dr.joint(b)] - d[dr.joint(a)];
                let angle = u.angle_between(v).to_degrees();
                // Hinges keep only their bend, and rigs differ in where the neck and shoulders
                // sit: a few degrees off, not more.
                assert!(angle < 25.0, "frame {f}: {a:?} → {b:?} {angle:.1}° off");
            }
        }
    }
}
