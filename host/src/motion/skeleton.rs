//! Skeletons: a joint tree with rest offsets, channel layouts and per-joint rotation orders.
//!
//! Joints are stored parent-before-child (`joints[j].parent < j`), which lets forward
//! kinematics run in one pass. End sites (BVH `End Site`, DeepMimic wrists/toes) are joints
//! with no channels and `end_site = true`: they carry no animation but give the renderer and
//! the foot-contact stage the tips of limbs.

use glam::{Quat, Vec3};

/// One rotation axis of an Euler decomposition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    /// The X axis.
    X,
    /// The Y axis.
    Y,
    /// The Z axis.
    Z,
}

impl Axis {
    /// Unit vector of the axis.
    pub fn unit(self) -> Vec3 {
        match self {
            Axis::X => Vec3::X,
            Axis::Y => Vec3::Y,
            Axis::Z => Vec3::Z,
        }
    }

    /// Upper-case letter of the axis (`'X'`, `'Y'`, `'Z'`).
    pub fn letter(self) -> char {
        match self {
            Axis::X => 'X',
            Axis::Y => 'Y',
            Axis::Z => 'Z',
        }
    }
}

/// One animated degree of freedom of a joint, as in a BVH `CHANNELS` line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// Translation along an axis, in the file's length unit.
    Position(Axis),
    /// Rotation about an axis, degrees in BVH.
    Rotation(Axis),
}

impl Channel {
    /// Parses a BVH channel name such as `Xposition` or `Zrotation` (case-insensitive).
    pub fn parse(name: &str) -> Option<Channel> {
        let lower = name.to_ascii_lowercase();
        let axis = match lower.as_bytes().first()? {
            b'x' => Axis::X,
            b'y' => Axis::Y,
            b'z' => Axis::Z,
            _ => return None,
        };
        match &lower[1..] {
            "position" => Some(Channel::Position(axis)),
            "rotation" => Some(Channel::Rotation(axis)),
            _ => None,
        }
    }

    /// The BVH name of the channel (`Xposition`, `Zrotation`, …).
    pub fn bvh_name(self) -> String {
        match self {
            Channel::Position(a) => format!("{}position", a.letter()),
            Channel::Rotation(a) => format!("{}rotation", a.letter()),
        }
    }
}

/// The order in which a joint's three Euler rotations compose, as listed in its channels.
///
/// `[Z, Y, X]` (BVH `Zrotation Yrotation Xrotation`) means the local rotation is
/// `Rz(z) · Ry(y) · Rx(x)` acting on column vectors, the BVH convention.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RotationOrder(pub [Axis; 3]);

impl RotationOrder {
    /// `Rz · Ry · Rx`, the most common BVH order.
    pub const ZYX: RotationOrder = RotationOrder([Axis::Z, Axis::Y, Axis::X]);
    /// `Rx · Ry · Rz`.
    pub const XYZ: RotationOrder = RotationOrder([Axis::X, Axis::Y, Axis::Z]);

    /// Whether the three axes are distinct (a Tait–Bryan order).
    pub fn is_valid(self) -> bool {
        let [a, b, c] = self.0;
        a != b && b != c && a != c
    }

    /// Builds a rotation from angles in radians given in this order's axis sequence.
    pub fn to_quat(self, angles_rad: [f32; 3]) -> Quat {
        let mut q = Quat::IDENTITY;
        for (axis, angle) in self.0.iter().zip(angles_rad) {
            q *= Quat::from_axis_angle(axis.unit(), angle);
        }
        q
    }

    /// Decomposes a rotation into angles in radians, in this order's axis sequence, such that
    /// `self.to_quat(self.from_quat(q)) ≈ q`.
    pub fn from_quat(self, q: Quat) -> [f32; 3] {
        let rot = glam::EulerRot::from_axes(self.0);
        let (a, b, c) = q.normalize().to_euler(rot);
        [a, b, c]
    }
}

/// Maps our axis triple onto glam's intrinsic Euler orders.
trait FromAxes {
    fn from_axes(axes: [Axis; 3]) -> Self;
}

impl FromAxes for glam::EulerRot {
    fn from_axes(axes: [Axis; 3]) -> Self {
        use glam::EulerRot as E;
        use Axis::{X, Y, Z};
        match axes {
            [X, Y, Z] => E::XYZ,
            [X, Z, Y] => E::XZY,
            [Y, X, Z] => E::YXZ,
            [Y, Z, X] => E::YZX,
            [Z, X, Y] => E::ZXY,
            // Any invalid triple is rejected by the importers; ZYX is the safe fallback.
            _ => E::ZYX,
        }
    }
}

/// One joint of a skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Joint name, unique within the skeleton.
    pub name: String,
    /// Index of the parent joint (always smaller than this joint's index); `None` for a root.
    pub parent: Option<usize>,
    /// Rest translation from the parent joint, in the skeleton's length unit.
    pub offset: Vec3,
    /// Animated channels in file order (empty for end sites and fixed joints).
    pub channels: Vec<Channel>,
    /// Order in which the joint's rotations compose (taken from its channels).
    pub rotation_order: RotationOrder,
    /// Whether the joint is a BVH `End Site` (a limb tip without channels).
    pub end_site: bool,
}

impl Joint {
    /// A joint built in code (no file channels, ZYX order): for programmatic rigs and tests.
    pub fn bare(name: &str, parent: Option<usize>, offset: Vec3) -> Joint {
        Joint {
            name: name.into(),
            parent,
            offset,
            channels: Vec::new(),
            rotation_order: RotationOrder::ZYX,
            end_site: false,
        }
    }

    /// Whether the joint has any position channel (its local translation is animated).
    pub fn has_position(&self) -> bool {
        self.channels
            .iter()
            .any(|c| matches!(c, Channel::Position(_)))
    }
}

/// A joint hierarchy, parent-before-child.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Skeleton {
    /// The joints; `joints[j].parent < Some(j)` always holds.
    pub joints: Vec<Joint>,
}

impl Skeleton {
    /// Number of joints (including end sites).
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// Whether the skeleton has no joints.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Index of the joint with this name (exact match).
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Indices of the children of joint `j`.
    pub fn children(&self, j: usize) -> Vec<usize> {
        (0..self.joints.len())
            .filter(|&k| self.joints[k].parent == Some(j))
            .collect()
    }

    /// Depth of joint `j` (roots have depth 0).
    pub fn depth(&self, j: usize) -> usize {
        let mut d = 0;
        let mut cur = self.joints.get(j).and_then(|x| x.parent);
        while let Some(p) = cur {
            d += 1;
            cur = self.joints.get(p).and_then(|x| x.parent);
        }
        d
    }

    /// Chain of joint indices from the root down to `j`, inclusive.
    pub fn chain_to(&self, j: usize) -> Vec<usize> {
        let mut out = Vec::new();
        let mut cur = Some(j);
        while let Some(k) = cur {
            out.push(k);
            cur = self.joints.get(k).and_then(|x| x.parent);
        }
        out.reverse();
        out
    }

    /// Joint indices in depth-first order (the order a BVH file lists them), roots in order.
    pub fn dfs_order(&self) -> Vec<usize> {
        fn visit(sk: &Skeleton, j: usize, out: &mut Vec<usize>) {
            out.push(j);
            for k in sk.children(j) {
                visit(sk, k, out);
            }
        }
        let mut out = Vec::with_capacity(self.joints.len());
        for (j, joint) in self.joints.iter().enumerate() {
            if joint.parent.is_none() {
                visit(self, j, &mut out);
            }
        }
        out
    }

    /// Rest-pose world positions of all joints (identity rotations, offsets only).
    pub fn rest_positions(&self) -> Vec<Vec3> {
        let mut out: Vec<Vec3> = Vec::with_capacity(self.joints.len());
        for j in &self.joints {
            let base = j
                .parent
                .and_then(|p| out.get(p).copied())
                .unwrap_or(Vec3::ZERO);
            out.push(base + j.offset);
        }
        out
    }

    /// Checks the parent-before-child invariant and name uniqueness; returns a reason if broken.
    pub fn validate(&self) -> Result<(), String> {
        for (i, j) in self.joints.iter().enumerate() {
            if let Some(p) = j.parent {
                if p >= i {
                    return Err(format!("joint {} has parent {} not before it", j.name, p));
                }
            }
            if !j.rotation_order.is_valid() {
                return Err(format!("joint {} has a repeated rotation axis", j.name));
            }
            if !j.offset.is_finite() {
                return Err(format!("joint {} has a non-finite offset", j.name));
            }
        }
        let mut names: Vec<&str> = self.joints.iter().map(|j| j.name.as_str()).collect();
        names.sort_unstable();
        if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
            return Err(format!("joint name {} appears twice", w[0]));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_names_parse_and_print() {
        for n in [
            "Xposition",
            "Yposition",
            "Zposition",
            "Xrotation",
            "Yrotation",
            "Zrotation",
        ] {
            let c = Channel::parse(n).unwrap();
            assert_eq!(c.bvh_name(), n);
        }
        assert_eq!(
            Channel::parse("zROTATION"),
            Some(Channel::Rotation(Axis::Z))
        );
        assert_eq!(Channel::parse("Wrotation"), None);
        assert_eq!(Channel::parse(""), None);
    }

    #[test]
    fn euler_round_trips_in_every_order() {
        use Axis::{X, Y, Z};
        let orders = [
            [X, Y, Z],
            [X, Z, Y],
            [Y, X, Z],
            [Y, Z, X],
            [Z, X, Y],
            [Z, Y, X],
        ];
        let angles = [0.3f32, -1.1, 2.5];
        for o in orders {
            let ro = RotationOrder(o);
            let q = ro.to_quat(angles);
            let back = ro.to_quat(ro.from_quat(q));
            assert!(q.dot(back).abs() > 1.0 - 1e-6, "{o:?}: {q} vs {back}");
        }
    }

    #[test]
    fn zyx_matches_matrix_product() {
        let ro = RotationOrder::ZYX;
        let q = ro.to_quat([0.5, 0.0, 0.0]);
        let v = q * Vec3::X;
        assert!((v - Vec3::new(0.5f32.cos(), 0.5f32.sin(), 0.0)).length() < 1e-6);
        // Rz·Rx: rotating Y by x first then by z.
        let q = ro.to_quat([
            std::f32::consts::FRAC_PI_2,
            0.0,
            std::f32::consts::FRAC_PI_2,
        ]);
        let v = q * Vec3::Y; // Rx(90) Y = Z, Rz(90) Z = Z
        assert!((v - Vec3::Z).length() < 1e-6, "{v}");
    }
}
