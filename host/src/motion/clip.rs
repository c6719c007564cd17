//! Clips: a skeleton plus uniformly sampled local poses, and forward kinematics.
//!
//! A [`Pose`] holds, for every joint, its local rotation (relative to the parent) and its local
//! translation from the parent (the rest offset, or the animated value for joints with
//! position channels — BVH position channels *replace* the offset, as Blender reads them). The
//! root's translation is therefore the root motion, in the parent-less world frame.

use glam::{Quat, Vec3};

use super::skeleton::Skeleton;

/// Local transforms of every joint at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Local rotation of each joint relative to its parent (unit quaternions).
    pub rotations: Vec<Quat>,
    /// Local translation of each joint from its parent, in the skeleton's length unit.
    pub translations: Vec<Vec3>,
}

impl Pose {
    /// The rest pose of a skeleton: identity rotations, rest offsets.
    pub fn rest(skeleton: &Skeleton) -> Pose {
        Pose {
            rotations: vec![Quat::IDENTITY; skeleton.len()],
            translations: skeleton.joints.iter().map(|j| j.offset).collect(),
        }
    }

    /// Blends two poses of the same skeleton: slerp of rotations, lerp of translations,
    /// `w` = 0 gives `self`, 1 gives `other`.
    pub fn blend(&self, other: &Pose, w: f32) -> Pose {
        Pose {
            rotations: self
                .rotations
                .iter()
                .zip(&other.rotations)
                .map(|(a, b)| slerp_short(*a, *b, w))
                .collect(),
            translations: self
                .translations
                .iter()
                .zip(&other.translations)
                .map(|(a, b)| a.lerp(*b, w))
                .collect(),
        }
    }
}

/// Slerp along the shorter arc (q and −q are the same rotation).
pub fn slerp_short(a: Quat, b: Quat, w: f32) -> Quat {
    let b = if a.dot(b) < 0.0 { -b } else { b };
    a.slerp(b, w).normalize()
}

/// World transform of one joint: position and orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldJoint {
    /// Joint position in world units.
    pub position: Vec3,
    /// Joint orientation (local frame → world).
    pub rotation: Quat,
}

impl Skeleton {
    /// Forward kinematics: world transforms of every joint for a pose.
    ///
    /// Missing entries in a malformed pose count as identity / rest offset rather than panic.
    pub fn forward(&self, pose: &Pose) -> Vec<WorldJoint> {
        let mut out: Vec<WorldJoint> = Vec::with_capacity(self.len());
        for (j, joint) in self.joints.iter().enumerate() {
            let r = pose.rotations.get(j).copied().unwrap_or(Quat::IDENTITY);
            let t = pose.translations.get(j).copied().unwrap_or(joint.offset);
            let world = match joint.parent.and_then(|p| out.get(p)) {
                Some(p) => WorldJoint {
                    position: p.position + p.rotation * t,
                    rotation: (p.rotation * r).normalize(),
                },
                None => WorldJoint {
                    position: t,
                    rotation: r,
                },
            };
            out.push(world);
        }
        out
    }

    /// World positions of every joint for a pose.
    pub fn positions(&self, pose: &Pose) -> Vec<Vec3> {
        self.forward(pose).into_iter().map(|w| w.position).collect()
    }
}

/// An animation: a skeleton sampled at a uniform frame time.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    /// Clip name (file stem for imported clips).
    pub name: String,
    /// The joint hierarchy.
    pub skeleton: Skeleton,
    /// Seconds between frames (1/fps).
    pub frame_time: f32,
    /// The poses, one per frame.
    pub frames: Vec<Pose>,
}

impl Clip {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether the clip has no frames.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Frames per second.
    pub fn fps(&self) -> f32 {
        1.0 / self.frame_time
    }

    /// Duration in seconds from the first to the last frame.
    pub fn duration(&self) -> f32 {
        self.frames.len().saturating_sub(1) as f32 * self.frame_time
    }

    /// World joint positions at frame `f` (empty if out of range).
    pub fn joint_positions(&self, f: usize) -> Vec<Vec3> {
        self.frames
            .get(f)
            .map(|p| self.skeleton.positions(p))
            .unwrap_or_default()
    }

    /// World joint positions for every frame (frames × joints).
    pub fn all_positions(&self) -> Vec<Vec<Vec3>> {
        self.frames
            .iter()
            .map(|p| self.skeleton.positions(p))
            .collect()
    }

    /// Root translation per frame (joint 0), in world units.
    pub fn root_path(&self) -> Vec<Vec3> {
        self.frames
            .iter()
            .map(|p| p.translations.first().copied().unwrap_or(Vec3::ZERO))
            .collect()
    }

    /// Pose at a fractional frame index, interpolated between neighbours, clamped to the clip.
    pub fn sample_frame(&self, f: f32) -> Pose {
        let n = self.frames.len();
        if n == 0 {
            return Pose::rest(&self.skeleton);
        }
        let f = if f.is_finite() {
            f.clamp(0.0, (n - 1) as f32)
        } else {
            0.0
        };
        let i = f.floor() as usize;
        let w = f - i as f32;
        match (self.frames.get(i), self.frames.get(i + 1)) {
            (Some(a), Some(b)) if w > 0.0 => a.blend(b, w),
            (Some(a), _) => a.clone(),
            _ => Pose::rest(&self.skeleton),
        }
    }

    /// Pose at time `t` seconds from the clip start, clamped to the clip.
    pub fn sample(&self, t: f32) -> Pose {
        self.sample_frame(t / self.frame_time)
    }

    /// Scales every length (offsets and translations) by `factor`, e.g. 0.01 for cm → m.
    pub fn scale_lengths(&mut self, factor: f32) {
        for j in &mut self.skeleton.joints {
            j.offset *= factor;
        }
        for p in &mut self.frames {
            for t in &mut p.translations {
                *t *= factor;
            }
        }
    }

    /// Lowest world Y over all joints and frames (where the feet touch the floor).
    pub fn min_height(&self) -> f32 {
        self.frames
            .iter()
            .flat_map(|p| self.skeleton.positions(p))
            .map(|v| v.y)
            .fold(f32::INFINITY, f32::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::skeleton::Joint;

    fn arm() -> Skeleton {
        let j = Joint::bare;
        Skeleton {
            joints: vec![
                j("root", None, Vec3::ZERO),
                j("upper", Some(0), Vec3::new(0.0, 1.0, 0.0)),
                j("lower", Some(1), Vec3::new(1.0, 0.0, 0.0)),
            ],
        }
    }

    #[test]
    fn fk_composes_parent_rotations() {
        let s = arm();
        let mut p = Pose::rest(&s);
        p.translations[0] = Vec3::new(5.0, 0.0, 0.0);
        p.rotations[1] = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let w = s.positions(&p);
        assert!((w[1] - Vec3::new(5.0, 1.0, 0.0)).length() < 1e-6);
        assert!(
            (w[2] - Vec3::new(5.0, 2.0, 0.0)).length() < 1e-6,
            "{}",
            w[2]
        );
    }

    #[test]
    fn sampling_interpolates_and_clamps() {
        let s = arm();
        let a = Pose::rest(&s);
        let mut b = Pose::rest(&s);
        b.translations[0] = Vec3::new(2.0, 0.0, 0.0);
        let c = Clip {
            name: "t".into(),
            skeleton: s,
            frame_time: 0.5,
            frames: vec![a, b],
        };
        assert!((c.sample(0.25).translations[0].x - 1.0).abs() < 1e-6);
        assert!((c.sample(9.0).translations[0].x - 2.0).abs() < 1e-6);
        assert!((c.sample(f32::NAN).translations[0].x).abs() < 1e-6);
        assert!((c.duration() - 0.5).abs() < 1e-6);
    }
}
