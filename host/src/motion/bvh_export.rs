//! BVH export: writes a [`Clip`] so that our importer and other tools read it back.
//!
//! Each joint keeps its channel layout when it has all three rotation channels (so imported
//! files round-trip with the same columns); other joints get `Xposition Yposition Zposition`
//! (roots and joints with animated translation) followed by three rotations in the joint's
//! rotation order. End sites become `End Site` blocks. Angles are degrees and all values are
//! printed with 6 decimals.

use std::fmt::Write as _;
use std::path::Path;

use super::clip::{Clip, Pose};
use super::skeleton::{Axis, Channel, Joint, Skeleton};
use super::MotionError;

/// Channels a joint is written with (see the module docs).
pub fn export_channels(skeleton: &Skeleton, j: usize) -> Vec<Channel> {
    let Some(joint) = skeleton.joints.get(j) else {
        return Vec::new();
    };
    if joint.end_site {
        return Vec::new();
    }
    let rotations = joint
        .channels
        .iter()
        .filter(|c| matches!(c, Channel::Rotation(_)))
        .count();
    if rotations == 3 && (joint.parent.is_some() || joint.has_position()) {
        return joint.channels.clone();
    }
    let mut out = Vec::with_capacity(6);
    if joint.parent.is_none() || joint.has_position() {
        out.extend([Axis::X, Axis::Y, Axis::Z].map(Channel::Position));
    }
    out.extend(joint.rotation_order.0.map(Channel::Rotation));
    out
}

/// Renders a clip as BVH text.
pub fn write_bvh_string(clip: &Clip) -> Result<String, MotionError> {
    let sk = &clip.skeleton;
    sk.validate().map_err(MotionError::Invalid)?;
    if clip.frames.is_empty() {
        return Err(MotionError::Invalid(format!(
            "clip {} has no frames to export",
            clip.name
        )));
    }
    if !(clip.frame_time.is_finite() && clip.frame_time > 0.0) {
        return Err(MotionError::Invalid(format!(
            "clip {} has frame time {}",
            clip.name, clip.frame_time
        )));
    }
    let channels: Vec<Vec<Channel>> = (0..sk.len()).map(|j| export_channels(sk, j)).collect();
    let mut out = String::from("HIERARCHY\n");
    for (j, joint) in sk.joints.iter().enumerate() {
        if joint.parent.is_none() {
            write_joint(sk, &channels, j, 0, &mut out);
        }
    }
    let _ = writeln!(out, "MOTION");
    let _ = writeln!(out, "Frames: {}", clip.frames.len());
    let _ = writeln!(out, "Frame Time: {:.8}", clip.frame_time);
    for pose in &clip.frames {
        write_frame(sk, &channels, pose, &mut out);
    }
    Ok(out)
}

/// Writes a clip to a BVH file.
pub fn write_bvh_path(clip: &Clip, path: &Path) -> Result<(), MotionError> {
    let text = write_bvh_string(clip)?;
    std::fs::write(path, text).map_err(|source| MotionError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn write_joint(sk: &Skeleton, channels: &[Vec<Channel>], j: usize, depth: usize, out: &mut String) {
    let Some(joint) = sk.joints.get(j) else {
        return;
    };
    let ind = "\t".repeat(depth);
    let o = joint.offset;
    if joint.end_site {
        let _ = writeln!(out, "{ind}End Site\n{ind}{{");
        let _ = writeln!(out, "{ind}\tOFFSET {:.6} {:.6} {:.6}", o.x, o.y, o.z);
        let _ = writeln!(out, "{ind}}}");
        return;
    }
    let kw = if joint.parent.is_none() {
        "ROOT"
    } else {
        "JOINT"
    };
    let _ = writeln!(out, "{ind}{kw} {}\n{ind}{{", bvh_name(joint));
    let _ = writeln!(out, "{ind}\tOFFSET {:.6} {:.6} {:.6}", o.x, o.y, o.z);
    let chans = channels.get(j).map(Vec::as_slice).unwrap_or(&[]);
    let names: Vec<String> = chans.iter().map(|c| c.bvh_name()).collect();
    let _ = writeln!(out, "{ind}\tCHANNELS {} {}", chans.len(), names.join(" "));
    for k in sk.children(j) {
        write_joint(sk, channels, k, depth + 1, out);
    }
    let _ = writeln!(out, "{ind}}}");
}

/// Joint names must be one token in most readers: whitespace becomes `_`.
fn bvh_name(joint: &Joint) -> String {
    let n: String = joint
        .name
        .chars()
        .map(|c| {
            if c.is_whitespace() || c == '{' || c == '}' {
                '_'
            } else {
                c
            }
        })
        .collect();
    if n.is_empty() {
        "joint".into()
    } else {
        n
    }
}

/// Writes one frame's values in the depth-first order the hierarchy was written in.
fn write_frame(sk: &Skeleton, channels: &[Vec<Channel>], pose: &Pose, out: &mut String) {
    let mut vals: Vec<f32> = Vec::new();
    for j in sk.dfs_order() {
        let Some(joint) = sk.joints.get(j) else {
            continue;
        };
        let chans = channels.get(j).map(Vec::as_slice).unwrap_or(&[]);
        if chans.is_empty() {
            continue;
        }
        let t = pose.translations.get(j).copied().unwrap_or(joint.offset);
        let q = pose
            .rotations
            .get(j)
            .copied()
            .unwrap_or(glam::Quat::IDENTITY);
        let rot_axes: Vec<Axis> = chans
            .iter()
            .filter_map(|c| match c {
                Channel::Rotation(a) => Some(*a),
                Channel::Position(_) => None,
            })
            .collect();
        let order = match rot_axes.as_slice() {
            [a, b, c] => super::skeleton::RotationOrder([*a, *b, *c]),
            _ => joint.rotation_order,
        };
        let angles = order.from_quat(q);
        for c in chans {
            vals.push(match c {
                Channel::Position(Axis::X) => t.x,
                Channel::Position(Axis::Y) => t.y,
                Channel::Position(Axis::Z) => t.z,
                Channel::Rotation(a) => order
                    .0
                    .iter()
                    .position(|x| x == a)
                    .and_then(|i| angles.get(i))
                    .map(|r| r.to_degrees())
                    .unwrap_or(0.0),
            });
        }
    }
    let line: Vec<String> = vals.iter().map(|v| format!("{v:.6}")).collect();
    out.push_str(&line.join(" "));
    out.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::bvh_import::read_bvh;

    /// Compares two clips joint by joint: rotations by angle, translations relative to size.
    pub(crate) fn assert_same_motion(a: &Clip, b: &Clip, tol: f32) {
        assert_eq!(a.frames.len(), b.frames.len());
        assert!((a.frame_time - b.frame_time).abs() < 1e-6);
        assert_eq!(a.skeleton.len(), b.skeleton.len());
        for (pa, pb) in a.frames.iter().zip(&b.frames) {
            for (qa, qb) in pa.rotations.iter().zip(&pb.rotations) {
                assert!(qa.dot(*qb).abs() > 1.0 - 1e-6, "{qa} vs {qb}");
            }
            for (ta, tb) in pa.translations.iter().zip(&pb.translations) {
                let scale = ta.length().max(1.0);
                assert!((*ta - *tb).length() <= tol * scale, "{ta} vs {tb}");
            }
        }
    }

    #[test]
    fn every_shared_bvh_round_trips() {
        let dir = crate::data::data_dir().join("bvh");
        let Ok(entries) = std::fs::read_dir(&dir) else {
            eprintln!("skipping: no {} — run `cargo xtask setup`", dir.display());
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.extension().and_then(|x| x.to_str()) != Some("bvh") {
                continue;
            }
            let mut clip = crate::motion::read_bvh_path(&p).unwrap().clip;
            // Keep the test fast: the first 200 frames exercise every channel layout.
            clip.frames.truncate(200);
            let text = write_bvh_string(&clip).unwrap();
            let back = read_bvh(&text, Path::new("rt.bvh")).unwrap().clip;
            assert_eq!(
                clip.skeleton
                    .joints
                    .iter()
                    .map(|j| &j.name)
                    .collect::<Vec<_>>(),
                back.skeleton
                    .joints
                    .iter()
                    .map(|j| &j.name)
                    .collect::<Vec<_>>(),
            );
            assert_same_motion(&clip, &back, 2e-6);
        }
    }
}
