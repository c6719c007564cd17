//! Joint roles: which joint of a rig plays the hips, head, hands, feet …
//!
//! LMA features and posture distances are computed on [`Role::COUNT`] role points, so clips of
//! rigs with different joint names and counts (LAFAN, Mixamo, Blender's `thigh.L`, DeepMimic,
//! mocapbank …) are compared on the same body landmarks. Roles are found from joint names
//! (case-insensitive, namespace prefixes such as `mixamorig:` dropped, side markers `Left`,
//! `L_`, `.L`, `_l` recognised) and from the hierarchy (the upper arm is the elbow's parent, the
//! thigh the knee's parent, the hand may be the elbow's end site). A JSON override file
//! `{"left_hand": "forearm.L_end", …}` names joints explicitly; it wins over the guesses.

use std::collections::BTreeMap;
use std::path::Path;

use crate::motion::Skeleton;

use super::GraphError;

/// A body landmark the graph's features are computed on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Role {
    /// The pelvis / root of the body.
    Hips,
    /// Upper spine (chest).
    Chest,
    /// Base of the neck.
    Neck,
    /// The head.
    Head,
    /// Left upper arm's root (the shoulder joint).
    LeftShoulder,
    /// Left elbow.
    LeftElbow,
    /// Left hand (wrist or hand joint).
    LeftHand,
    /// Right shoulder joint.
    RightShoulder,
    /// Right elbow.
    RightElbow,
    /// Right hand.
    RightHand,
    /// Left hip joint (thigh root).
    LeftHip,
    /// Left knee.
    LeftKnee,
    /// Left foot (ankle).
    LeftFoot,
    /// Right hip joint.
    RightHip,
    /// Right knee.
    RightKnee,
    /// Right foot.
    RightFoot,
}

impl Role {
    /// Number of roles.
    pub const COUNT: usize = 16;
    /// All roles, in index order.
    pub const ALL: [Role; Role::COUNT] = [
        Role::Hips,
        Role::Chest,
        Role::Neck,
        Role::Head,
        Role::LeftShoulder,
        Role::LeftElbow,
        Role::LeftHand,
        Role::RightShoulder,
        Role::RightElbow,
        Role::RightHand,
        Role::LeftHip,
        Role::LeftKnee,
        Role::LeftFoot,
        Role::RightHip,
        Role::RightKnee,
        Role::RightFoot,
    ];

    /// Index of the role in [`Role::ALL`] (and in role-point arrays).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The snake_case name used in override files (`left_hand`).
    pub fn name(self) -> &'static str {
        match self {
            Role::Hips => "hips",
            Role::Chest => "chest",
            Role::Neck => "neck",
            Role::Head => "head",
            Role::LeftShoulder => "left_shoulder",
            Role::LeftElbow => "left_elbow",
            Role::LeftHand => "left_hand",
            Role::RightShoulder => "right_shoulder",
            Role::RightElbow => "right_elbow",
            Role::RightHand => "right_hand",
            Role::LeftHip => "left_hip",
            Role::LeftKnee => "left_knee",
            Role::LeftFoot => "left_foot",
            Role::RightHip => "right_hip",
            Role::RightKnee => "right_knee",
            Role::RightFoot => "right_foot",
        }
    }

    /// The role with this override-file name.
    pub fn from_name(name: &str) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.name() == name)
    }
}

/// Role → joint index for one skeleton.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RoleMap {
    /// Joint index per role, indexed by [`Role::index`].
    pub joints: [usize; Role::COUNT],
}

/// Explicit role → joint-name assignments read from an override file.
pub type RoleOverrides = BTreeMap<String, String>;

/// Reads a role override file: a JSON object mapping role names to joint names.
pub fn read_overrides(path: &Path) -> Result<RoleOverrides, GraphError> {
    let text = std::fs::read_to_string(path).map_err(|source| GraphError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let map: RoleOverrides = serde_json::from_str(&text)
        .map_err(|e| GraphError::format(path, format!("role override file: {e}")))?;
    for key in map.keys() {
        if Role::from_name(key).is_none() {
            let known: Vec<&str> = Role::ALL.iter().map(|r| r.name()).collect();
            return Err(GraphError::format(
                path,
                format!("unknown role `{key}` (known: {})", known.join(", ")),
            ));
        }
    }
    Ok(map)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    Left,
    Right,
    Centre,
}

/// Splits a joint name into its side and its base name (lower case, separators removed).
fn classify(name: &str) -> (Side, String) {
    let after_ns = name.rsplit(':').next().unwrap_or(name);
    let lower = after_ns.to_ascii_lowercase();
    let mut side = Side::Centre;
    let mut base = lower.clone();
    for (word, s) in [("left", Side::Left), ("right", Side::Right)] {
        if let Some(pos) = lower.find(word) {
            side = s;
            base = format!("{}{}", &lower[..pos], &lower[pos + word.len()..]);
            break;
        }
    }
    if side == Side::Centre {
        let b = after_ns.as_bytes();
        // `L_Foot`, `l_foot`, `LFoot` (upper-case L followed by an upper-case letter).
        let prefix = |c: u8| {
            b.len() > 2
                && b[0].eq_ignore_ascii_case(&c)
                && (b[1] == b'_'
                    || b[1] == b'.'
                    || (b[0].is_ascii_uppercase() && b[1].is_ascii_uppercase()))
        };
        // `foot.L`, `foot_l`, `Foot L`.
        let suffix = |c: u8| {
            b.len() > 2
                && b[b.len() - 1].eq_ignore_ascii_case(&c)
                && matches!(b[b.len() - 2], b'_' | b'.' | b' ')
        };
        if prefix(b'l') {
            side = Side::Left;
            base = lower[1..].to_string();
        } else if prefix(b'r') {
            side = Side::Right;
            base = lower[1..].to_string();
        } else if suffix(b'l') {
            side = Side::Left;
            base = lower[..lower.len() - 1].to_string();
        } else if suffix(b'r') {
            side = Side::Right;
            base = lower[..lower.len() - 1].to_string();
        }
    }
    let base: String = base.chars().filter(|c| c.is_ascii_alphanumeric()).collect();
    (side, base)
}

/// First joint (in skeleton order) whose side matches and whose base name is one of `names`,
/// trying the names in priority order.
fn by_name(classes: &[(Side, String)], side: Side, names: &[&str]) -> Option<usize> {
    names
        .iter()
        .find_map(|n| classes.iter().position(|(s, b)| *s == side && b == n))
}

impl RoleMap {
    /// Finds the roles of `skeleton` from joint names and hierarchy; `overrides` name joints
    /// explicitly. `clip` names the clip in errors.
    pub fn detect(
        skeleton: &Skeleton,
        overrides: &RoleOverrides,
        clip: &str,
    ) -> Result<RoleMap, GraphError> {
        let classes: Vec<(Side, String)> =
            skeleton.joints.iter().map(|j| classify(&j.name)).collect();
        let parent = |j: Option<usize>| j.and_then(|j| skeleton.joints.get(j)?.parent);
        let end_child = |j: Option<usize>| {
            let j = j?;
            skeleton
                .children(j)
                .into_iter()
                .find(|&k| skeleton.joints[k].end_site)
        };
        let mut found: [Option<usize>; Role::COUNT] = [None; Role::COUNT];
        for (role, joint_name) in overrides {
            if let Some(r) = Role::from_name(role) {
                if let Some(j) = skeleton.find(joint_name) {
                    found[r.index()] = Some(j);
                }
            }
        }
        let c = Side::Centre;
        let set = |found: &mut [Option<usize>; Role::COUNT], r: Role, v: Option<usize>| {
            if found[r.index()].is_none() {
                found[r.index()] = v;
            }
        };
        set(
            &mut found,
            Role::Hips,
            by_name(&classes, c, &["hips", "hip", "pelvis", "root"]),
        );
        if found[Role::Hips.index()].is_none() && !skeleton.is_empty() {
            found[Role::Hips.index()] = Some(0);
        }
        set(
            &mut found,
            Role::Neck,
            by_name(&classes, c, &["neck", "neck1"]),
        );
        set(
            &mut found,
            Role::Head,
            by_name(
                &classes,
                c,
                &["head", "face", "headend", "headtopend", "neckend"],
            ),
        );
        if found[Role::Neck.index()].is_none() {
            found[Role::Neck.index()] = parent(found[Role::Head.index()]);
        }
        set(
            &mut found,
            Role::Chest,
            by_name(
                &classes,
                c,
                &[
                    "chest",
                    "upperchest",
                    "chest2",
                    "spine2",
                    "spine3",
                    "spine001",
                    "spine1",
                ],
            ),
        );
        if found[Role::Chest.index()].is_none() {
            found[Role::Chest.index()] = parent(found[Role::Neck.index()]);
        }
        for (side, sh, el, ha, hi, kn, fo) in [
            (
                Side::Left,
                Role::LeftShoulder,
                Role::LeftElbow,
                Role::LeftHand,
                Role::LeftHip,
                Role::LeftKnee,
                Role::LeftFoot,
            ),
            (
                Side::Right,
                Role::RightShoulder,
                Role::RightElbow,
                Role::RightHand,
                Role::RightHip,
                Role::RightKnee,
                Role::RightFoot,
            ),
        ] {
            set(
                &mut found,
                el,
                by_name(&classes, side, &["forearm", "elbow", "lowerarm"]),
            );
            set(&mut found, ha, by_name(&classes, side, &["hand", "wrist"]));
            if found[ha.index()].is_none() {
                found[ha.index()] = end_child(found[el.index()]);
            }
            if found[el.index()].is_none() {
                found[el.index()] = parent(found[ha.index()]);
            }
            let up_arm = parent(found[el.index()]);
            set(&mut found, sh, up_arm);
            set(
                &mut found,
                kn,
                by_name(&classes, side, &["knee", "leg", "shin", "lowerleg", "calf"]),
            );
            set(&mut found, fo, by_name(&classes, side, &["foot", "ankle"]));
            if found[kn.index()].is_none() {
                found[kn.index()] = parent(found[fo.index()]);
            }
            let thigh = parent(found[kn.index()]);
            set(&mut found, hi, thigh);
        }
        let mut joints = [0usize; Role::COUNT];
        for r in Role::ALL {
            joints[r.index()] = found[r.index()].ok_or_else(|| GraphError::MissingRole {
                clip: clip.to_string(),
                role: r.name(),
                joints: skeleton
                    .joints
                    .iter()
                    .map(|j| j.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
        }
        Ok(RoleMap { joints })
    }

    /// The joint index of a role.
    pub fn joint(&self, role: Role) -> usize {
        self.joints[role.index()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::{read_bvh_path, Joint, RotationOrder};
    use glam::Vec3;

    fn skeleton(names: &[(&str, Option<usize>)]) -> Skeleton {
        Skeleton {
            joints: names
                .iter()
                .map(|(n, p)| Joint {
                    name: n.to_string(),
                    parent: *p,
                    offset: Vec3::Y,
                    channels: vec![],
                    rotation_order: RotationOrder::ZYX,
                    end_site: n.ends_with("_end"),
                })
                .collect(),
        }
    }

    #[test]
    fn side_markers_are_recognised() {
        assert_eq!(classify("LeftUpLeg"), (Side::Left, "upleg".into()));
        assert_eq!(
            classify("mixamorig:RightHand"),
            (Side::Right, "hand".into())
        );
        assert_eq!(classify("thigh.L"), (Side::Left, "thigh".into()));
        assert_eq!(classify("foot_r"), (Side::Right, "foot".into()));
        assert_eq!(classify("L_Wrist"), (Side::Left, "wrist".into()));
        assert_eq!(classify("LFoot"), (Side::Left, "foot".into()));
        assert_eq!(classify("left_knee"), (Side::Left, "knee".into()));
        assert_eq!(classify("Leg"), (Side::Centre, "leg".into()));
        assert_eq!(classify("spine.001"), (Side::Centre, "spine001".into()));
        assert_eq!(classify("Hips"), (Side::Centre, "hips".into()));
    }

    #[test]
    fn blender_style_rig_uses_hierarchy_for_hands() {
        let sk = skeleton(&[
            ("pelvis", None),
            ("spine", Some(0)),
            ("spine.001", Some(1)),
            ("neck", Some(2)),
            ("face", Some(3)),
            ("upper_arm.L", Some(2)),
            ("forearm.L", Some(5)),
            ("forearm.L_end", Some(6)),
            ("upper_arm.R", Some(2)),
            ("forearm.R", Some(8)),
            ("forearm.R_end", Some(9)),
            ("thigh.L", Some(0)),
            ("shin.L", Some(11)),
            ("foot.L", Some(12)),
            ("thigh.R", Some(0)),
            ("shin.R", Some(14)),
            ("foot.R", Some(15)),
        ]);
        let m = RoleMap::detect(&sk, &RoleOverrides::new(), "t").unwrap();
        assert_eq!(m.joint(Role::LeftHand), 7);
        assert_eq!(m.joint(Role::LeftShoulder), 5);
        assert_eq!(m.joint(Role::RightKnee), 15);
        assert_eq!(m.joint(Role::LeftHip), 11);
        assert_eq!(m.joint(Role::Head), 4);
        assert_eq!(m.joint(Role::Chest), 2);
    }

    #[test]
    fn missing_role_is_a_clear_error_and_override_fixes_it() {
        let sk = skeleton(&[("root", None), ("a", Some(0)), ("b", Some(1))]);
        let err = RoleMap::detect(&sk, &RoleOverrides::new(), "weird").unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("weird") && msg.contains("role"), "{msg}");
        let mut o = RoleOverrides::new();
        for r in Role::ALL {
            o.insert(r.name().into(), "b".into());
        }
        let m = RoleMap::detect(&sk, &o, "weird").unwrap();
        assert_eq!(m.joint(Role::Head), 2);
    }

    #[test]
    fn every_real_rig_maps() {
        let names = [
            "blender_gestures.bvh",
            "lafan_dance1.bvh",
            "mixamo_walk_turn.bvh",
            "mocapbank_kneel.bvh",
            "sword_attack.bvh",
        ];
        for n in names {
            let Some(p) = crate::data::data_file("bvh", n) else {
                eprintln!("skipping {n}: run `cargo xtask setup`");
                continue;
            };
            let imp = read_bvh_path(&p).unwrap();
            let sk = &imp.clip.skeleton;
            let m = RoleMap::detect(sk, &RoleOverrides::new(), n).unwrap();
            let name = |r: Role| sk.joints[m.joint(r)].name.to_ascii_lowercase();
            assert!(
                name(Role::LeftFoot).contains("foot") || name(Role::LeftFoot).contains("ankle"),
                "{n}"
            );
            assert!(
                name(Role::RightHand).contains('r'),
                "{n}: {}",
                name(Role::RightHand)
            );
            assert_ne!(m.joint(Role::LeftHand), m.joint(Role::RightHand), "{n}");
            // Left hand is on the left of the body: the left chain must not share the right one.
            assert_ne!(m.joint(Role::LeftKnee), m.joint(Role::RightKnee), "{n}");
        }
    }
}
