//! DeepMimic motion clips (pybullet's `humanoid3d_*.txt`) on the humanoid URDF.
//!
//! A clip is JSON `{"Loop": "wrap"|"none", "Frames": [[dt, root xyz, root quat, joints…], …]}`
//! with 44 numbers a frame. Quaternions are (w, x, y, z); knees and elbows are one angle in
//! radians about the URDF joint axis. The joint order is fixed by DeepMimic's humanoid
//! ([`DEEPMIMIC_JOINTS`]); offsets come from the URDF, scaled by [`URDF_SCALE`] (pybullet
//! loads `humanoid.urdf` with `globalScaling = 0.25`, so the clips' root heights of ~0.85 m
//! match). Y is up; the character walks along +X with its right side towards +Z.
//!
//! End sites are added for the head top and the toe tips (from the URDF's head sphere and foot
//! box) so that rendering and foot-contact detection see the whole body.

use std::path::Path;

use glam::{Quat, Vec3};

use super::clip::{Clip, Pose};
use super::skeleton::{Joint, RotationOrder, Skeleton};
use super::urdf::{read_urdf_path, UrdfJoint};
use super::MotionError;

/// Scale applied to URDF lengths (pybullet's `globalScaling` for the DeepMimic humanoid).
pub const URDF_SCALE: f32 = 0.25;

/// Numbers per frame: dt, root position (3), root quaternion (4), 8 spherical joints (4 each),
/// 4 revolute joints (1 each).
pub const DEEPMIMIC_FRAME_LEN: usize = 44;

/// The animated joints in frame order, and whether each is a one-angle (revolute) joint.
pub const DEEPMIMIC_JOINTS: [(&str, bool); 12] = [
    ("chest", false),
    ("neck", false),
    ("right_hip", false),
    ("right_knee", true),
    ("right_ankle", false),
    ("right_shoulder", false),
    ("right_elbow", true),
    ("left_hip", false),
    ("left_knee", true),
    ("left_ankle", false),
    ("left_shoulder", false),
    ("left_elbow", true),
];

/// Head-top end site in the neck frame, URDF units (head sphere centre 0.7 + radius 0.41).
const HEAD_TOP: Vec3 = Vec3::new(0.0, 1.11, 0.0);
/// Toe-tip end site in the ankle frame, URDF units (front-bottom edge of the foot box).
const TOE_TIP: Vec3 = Vec3::new(0.534, -0.2, 0.0);

/// A DeepMimic clip with its loop mode.
#[derive(Debug, Clone)]
pub struct DeepMimicClip {
    /// The clip (metres, seconds).
    pub clip: Clip,
    /// Whether the file says `"Loop": "wrap"` (the motion is meant to cycle).
    pub looping: bool,
}

/// Builds the humanoid skeleton from the URDF joints (metres, after [`URDF_SCALE`]).
pub fn humanoid_skeleton(urdf: &[UrdfJoint], path: &Path) -> Result<Skeleton, MotionError> {
    let find = |name: &str| urdf.iter().find(|j| j.name == name);
    let mut joints = vec![Joint {
        name: "root".into(),
        parent: None,
        offset: Vec3::ZERO,
        channels: Vec::new(),
        rotation_order: RotationOrder::ZYX,
        end_site: false,
    }];
    // Order: the animated joints, then wrists, then end sites; parents always come first
    // because DEEPMIMIC_JOINTS lists parents before children.
    let mut names: Vec<String> = DEEPMIMIC_JOINTS
        .iter()
        .map(|(n, _)| n.to_string())
        .collect();
    names.extend(["right_wrist".to_string(), "left_wrist".to_string()]);
    for name in &names {
        let j = find(name).ok_or_else(|| {
            MotionError::parse(path, 1, format!("URDF has no joint named {name}"))
        })?;
        // URDF joints connect links; link names equal joint names in this model, and the
        // pelvis link is called "root".
        let parent = joints
            .iter()
            .position(|k| k.name == j.parent)
            .ok_or_else(|| {
                MotionError::parse(
                    path,
                    1,
                    format!(
                        "joint {name}: parent link {} is not a known joint",
                        j.parent
                    ),
                )
            })?;
        joints.push(Joint {
            name: name.clone(),
            parent: Some(parent),
            offset: j.origin * URDF_SCALE,
            channels: Vec::new(),
            rotation_order: RotationOrder::ZYX,
            end_site: false,
        });
    }
    let mut add_end = |name: &str, parent: &str, offset: Vec3| {
        if let Some(p) = joints.iter().position(|k| k.name == parent) {
            joints.push(Joint {
                name: name.into(),
                parent: Some(p),
                offset: offset * URDF_SCALE,
                channels: Vec::new(),
                rotation_order: RotationOrder::ZYX,
                end_site: true,
            });
        }
    };
    add_end("head_end", "neck", HEAD_TOP);
    add_end("right_toe", "right_ankle", TOE_TIP);
    add_end("left_toe", "left_ankle", TOE_TIP);
    add_end("right_hand", "right_wrist", Vec3::new(0.0, -0.3, 0.0));
    add_end("left_hand", "left_wrist", Vec3::new(0.0, -0.3, 0.0));
    // Give animated joints BVH-style channels so exports are complete.
    use super::skeleton::{Axis, Channel};
    for (i, j) in joints.iter_mut().enumerate() {
        if j.end_site {
            continue;
        }
        if i == 0 {
            j.channels
                .extend([Axis::X, Axis::Y, Axis::Z].map(Channel::Position));
        }
        j.channels
            .extend([Axis::Z, Axis::Y, Axis::X].map(Channel::Rotation));
    }
    let sk = Skeleton { joints };
    sk.validate().map_err(|r| MotionError::parse(path, 1, r))?;
    Ok(sk)
}

/// Reads a DeepMimic clip, with the humanoid skeleton from `urdf_path`.
pub fn read_deepmimic_path(
    clip_path: &Path,
    urdf_path: &Path,
) -> Result<DeepMimicClip, MotionError> {
    let urdf = read_urdf_path(urdf_path)?;
    let skeleton = humanoid_skeleton(&urdf, urdf_path)?;
    let text = std::fs::read_to_string(clip_path).map_err(|source| MotionError::Io {
        path: clip_path.to_path_buf(),
        source,
    })?;
    let mut c = read_deepmimic(&text, clip_path, &skeleton, &urdf)?;
    if let Some(stem) = clip_path.file_stem() {
        let stem = stem.to_string_lossy();
        c.clip.name = stem
            .strip_prefix("humanoid3d_")
            .unwrap_or(&stem)
            .to_string();
    }
    Ok(c)
}

/// Parses DeepMimic JSON for a humanoid skeleton built by [`humanoid_skeleton`].
pub fn read_deepmimic(
    text: &str,
    path: &Path,
    skeleton: &Skeleton,
    urdf: &[UrdfJoint],
) -> Result<DeepMimicClip, MotionError> {
    if skeleton.is_empty() {
        return Err(MotionError::Invalid(
            "DeepMimic clips need the humanoid skeleton (it is empty)".into(),
        ));
    }
    let v: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| MotionError::parse(path, e.line().max(1), e.to_string()))?;
    let looping = v.get("Loop").and_then(|l| l.as_str()) == Some("wrap");
    let frames = v
        .get("Frames")
        .and_then(|f| f.as_array())
        .ok_or_else(|| MotionError::parse(path, 1, "no \"Frames\" array"))?;
    // serde_json::Value keeps no positions: find each frame's line by scanning for '[' at depth 2.
    let frame_lines = frame_line_numbers(text);
    let line_of = |i: usize| frame_lines.get(i).copied().unwrap_or(1);
    let axis_of = |name: &str| {
        urdf.iter()
            .find(|j| j.name == name)
            .map(|j| j.axis.normalize_or(Vec3::Z))
            .unwrap_or(Vec3::Z)
    };
    let index_of = |name: &str| skeleton.find(name);
    let mut poses = Vec::with_capacity(frames.len());
    let mut dts = Vec::with_capacity(frames.len());
    for (i, f) in frames.iter().enumerate() {
        let nums: Vec<f64> = f
            .as_array()
            .ok_or_else(|| {
                MotionError::parse(path, line_of(i), format!("frame {i} is not an array"))
            })?
            .iter()
            .map(|x| x.as_f64())
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| {
                MotionError::parse(path, line_of(i), format!("frame {i} holds a non-number"))
            })?;
        if nums.len() != DEEPMIMIC_FRAME_LEN {
            return Err(MotionError::parse(
                path,
                line_of(i),
                format!(
                    "frame {i} has {} numbers, expected {DEEPMIMIC_FRAME_LEN}",
                    nums.len()
                ),
            ));
        }
        if nums.iter().any(|x| !x.is_finite()) {
            return Err(MotionError::parse(
                path,
                line_of(i),
                format!("frame {i}: non-finite"),
            ));
        }
        let n: Vec<f32> = nums.iter().map(|&x| x as f32).collect();
        dts.push(n[0]);
        let mut pose = Pose::rest(skeleton);
        pose.translations[0] = Vec3::new(n[1], n[2], n[3]);
        pose.rotations[0] = quat_wxyz(&n[4..8]);
        let mut k = 8;
        for (name, revolute) in DEEPMIMIC_JOINTS {
            let Some(j) = index_of(name) else { continue };
            if revolute {
                pose.rotations[j] = Quat::from_axis_angle(axis_of(name), n[k]);
                k += 1;
            } else {
                pose.rotations[j] = quat_wxyz(&n[k..k + 4]);
                k += 4;
            }
        }
        poses.push(pose);
    }
    if poses.len() < 2 {
        return Err(MotionError::parse(path, 1, "fewer than two frames"));
    }
    // The last frame's dt is often 0 (it has no successor); use the others.
    let used: Vec<f32> = dts
        .iter()
        .take(dts.len() - 1)
        .copied()
        .filter(|d| *d > 0.0)
        .collect();
    if used.is_empty() {
        return Err(MotionError::parse(
            path,
            line_of(0),
            "all frame durations are zero",
        ));
    }
    let frame_time = used.iter().sum::<f32>() / used.len() as f32;
    Ok(DeepMimicClip {
        clip: Clip {
            name: "deepmimic".into(),
            skeleton: skeleton.clone(),
            frame_time,
            frames: poses,
        },
        looping,
    })
}

fn quat_wxyz(v: &[f32]) -> Quat {
    match v {
        [w, x, y, z] => Quat::from_xyzw(*x, *y, *z, *w).normalize_or(Quat::IDENTITY),
        _ => Quat::IDENTITY,
    }
}

trait NormalizeOr {
    fn normalize_or(self, fallback: Self) -> Self;
}

impl NormalizeOr for Quat {
    fn normalize_or(self, fallback: Quat) -> Quat {
        let l = self.length();
        if l.is_finite() && l > 1e-6 {
            self / l
        } else {
            fallback
        }
    }
}

/// 1-based line numbers of the inner arrays of the top-level "Frames" array.
fn frame_line_numbers(text: &str) -> Vec<usize> {
    let mut out = Vec::new();
    let mut depth = 0usize;
    let mut line = 1usize;
    let mut in_str = false;
    for ch in text.chars() {
        match ch {
            '\n' => line += 1,
            '"' => in_str = !in_str,
            '[' if !in_str => {
                depth += 1;
                if depth == 2 {
                    out.push(line);
                }
            }
            ']' if !in_str => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn files() -> Option<(std::path::PathBuf, std::path::PathBuf)> {
        let urdf = crate::data::data_file("deepmimic", "humanoid.urdf")?;
        let walk = crate::data::data_file("deepmimic", "humanoid3d_walk.txt")?;
        Some((walk, urdf))
    }

    #[test]
    fn walk_clip_stands_on_the_ground_and_walks_along_x() {
        let Some((walk, urdf)) = files() else {
            eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
            return;
        };
        let c = read_deepmimic_path(&walk, &urdf).unwrap();
        assert!(c.looping);
        let clip = &c.clip;
        assert!((clip.fps() - 30.0).abs() < 0.5, "{}", clip.fps());
        let sk = &clip.skeleton;
        let head = sk.find("head_end").unwrap();
        let toe = sk.find("right_toe").unwrap();
        let p = clip.joint_positions(0);
        assert!(p[head].y > 1.4 && p[head].y < 2.0, "head {}", p[head]);
        let floor = clip.min_height();
        assert!(floor.abs() < 0.06, "lowest point {floor} m");
        assert!(p[toe].y < 0.1);
        let path = clip.root_path();
        let dx = path[path.len() - 1].x - path[0].x;
        assert!(dx > 0.5, "walks {dx} m along x");
    }

    #[test]
    fn every_deepmimic_clip_imports() {
        let Some((walk, urdf)) = files() else {
            eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
            return;
        };
        let dir = walk.parent().unwrap().to_path_buf();
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.extension().and_then(|x| x.to_str()) == Some("txt") {
                let c = read_deepmimic_path(&p, &urdf).unwrap_or_else(|e| panic!("{e}"));
                assert!(c.clip.len() > 10, "{}", p.display());
            }
        }
    }

    #[test]
    fn malformed_json_names_file_and_line() {
        let urdf_text = "<robot><joint name=\"chest\" type=\"spherical\"><parent link=\"root\"/><child link=\"chest\"/></joint></robot>";
        let _ = urdf_text;
        let sk = Skeleton {
            joints: vec![crate::motion::Joint {
                name: "root".into(),
                parent: None,
                offset: Vec3::ZERO,
                channels: vec![],
                rotation_order: RotationOrder::ZYX,
                end_site: false,
            }],
        };
        let full = format!("{{\"Frames\": [[{}]]}}", vec!["0.1"; 44].join(","));
        assert!(read_deepmimic(&full, Path::new("c.txt"), &Skeleton::default(), &[]).is_err());
        assert!(read_deepmimic(&full, Path::new("c.txt"), &sk, &[]).is_err()); // one frame only
        let bad = "{\n\"Loop\": \"none\",\n\"Frames\": [\n[0.1, 1, 2],\n]\n}";
        let e = read_deepmimic(bad, Path::new("c.txt"), &sk, &[])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.txt:5:"), "{e}");
        let short = "{\n\"Loop\": \"none\",\n\"Frames\": [\n[0.1, 1, 2]\n]\n}";
        let e = read_deepmimic(short, Path::new("c.txt"), &sk, &[])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.txt:4:"), "{e}");
    }
}
