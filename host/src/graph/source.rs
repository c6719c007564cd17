//! Graph sources: clips loaded from files, resampled to [`FPS`], with role points.
//!
//! Every clip is resampled to 30 fps (slerp between neighbouring frames), so windows of
//! [`WINDOW`] frames span the same 1.13 s whatever the capture rate (the sword clip is 120 fps,
//! Blender's 24 fps). Role points are world positions of the [`Role`] joints, scaled so that the
//! body measures [`STANDARD_HEIGHT`] metres (the paper retargeted all motions to one skeleton
//! with standard proportions; scaling by the bone-chain height does the same for lengths and
//! removes the source's length unit), and shifted so the clip's floor is at y = 0 and its mean
//! horizontal root position is at the origin.

use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::motion::{read_bvh_path, read_deepmimic_path, Clip, Skeleton};

use super::roles::{Role, RoleMap, RoleOverrides};
use super::{GraphError, FPS, WINDOW};

/// Body height every clip is scaled to for analysis, metres.
pub const STANDARD_HEIGHT: f32 = 1.7;

/// A clip ready for analysis.
#[derive(Debug, Clone)]
pub struct GraphClip {
    /// The clip resampled to [`FPS`] (original skeleton and length unit).
    pub clip: Clip,
    /// Where the clip came from.
    pub path: PathBuf,
    /// The role joints of the skeleton.
    pub roles: RoleMap,
    /// Factor from the clip's length unit to analysis metres.
    pub scale: f32,
    /// Role points per frame (`frames × Role::COUNT`), analysis metres, floor at y = 0.
    pub points: Vec<[Vec3; Role::COUNT]>,
}

impl GraphClip {
    /// Number of frames (at [`FPS`]).
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the clip has no frames.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Rig identity: joint names and parents; clips with equal keys can be spliced together.
    pub fn rig_key(&self) -> String {
        rig_key(&self.clip.skeleton)
    }
}

/// Rig identity of a skeleton (joint names and parent indices).
pub fn rig_key(sk: &Skeleton) -> String {
    sk.joints
        .iter()
        .map(|j| format!("{}<{}", j.name, j.parent.map(|p| p as i64).unwrap_or(-1)))
        .collect::<Vec<_>>()
        .join("|")
}

/// Height of a skeleton along its bones: head chain plus one leg chain, in its length unit.
fn bone_height(sk: &Skeleton, roles: &RoleMap) -> f32 {
    let chain_len = |j: usize| -> f32 {
        sk.chain_to(j)
            .iter()
            .skip(1)
            .map(|&k| sk.joints[k].offset.length())
            .sum()
    };
    let hips = roles.joint(Role::Hips);
    let hips_depth = chain_len(hips);
    let up = chain_len(roles.joint(Role::Head)) - hips_depth;
    let down = chain_len(roles.joint(Role::LeftFoot)) - hips_depth;
    up + down
}

/// Reads a BVH or DeepMimic clip (by extension: `.bvh`, else DeepMimic `.txt`/`.json` with
/// `humanoid.urdf` next to it) and prepares it for analysis.
pub fn load_clip(path: &Path, overrides: &RoleOverrides) -> Result<GraphClip, GraphError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let clip = if ext == "bvh" {
        read_bvh_path(path)?.clip
    } else {
        let urdf = path
            .parent()
            .map(|d| d.join("humanoid.urdf"))
            .unwrap_or_else(|| PathBuf::from("humanoid.urdf"));
        if !urdf.is_file() {
            return Err(GraphError::format(
                path,
                format!(
                    "not a .bvh file, and no DeepMimic humanoid.urdf next to it ({})",
                    urdf.display()
                ),
            ));
        }
        read_deepmimic_path(path, &urdf)?.clip
    };
    prepare(clip, path, overrides)
}

/// Resamples `clip` to [`FPS`], finds its roles and computes role points.
pub fn prepare(
    clip: Clip,
    path: &Path,
    overrides: &RoleOverrides,
) -> Result<GraphClip, GraphError> {
    if !(clip.frame_time.is_finite() && clip.frame_time > 0.0) {
        return Err(GraphError::format(
            path,
            "frame time is not a positive number",
        ));
    }
    let roles = RoleMap::detect(&clip.skeleton, overrides, &clip.name)?;
    let height = bone_height(&clip.skeleton, &roles);
    if !(height.is_finite() && height > 0.0) {
        return Err(GraphError::format(
            path,
            "the skeleton has no height between head and feet (check the role map)",
        ));
    }
    let scale = STANDARD_HEIGHT / height;
    let clip = resample(&clip, FPS);
    let mut points: Vec<[Vec3; Role::COUNT]> = clip
        .frames
        .iter()
        .map(|pose| {
            let world = clip.skeleton.positions(pose);
            let mut p = [Vec3::ZERO; Role::COUNT];
            for r in Role::ALL {
                p[r.index()] = world.get(roles.joint(r)).copied().unwrap_or(Vec3::ZERO) * scale;
            }
            p
        })
        .collect();
    if points.iter().flatten().any(|v| !v.is_finite()) {
        return Err(GraphError::format(path, "non-finite joint positions"));
    }
    let floor = points
        .iter()
        .map(|p| {
            p[Role::LeftFoot.index()]
                .y
                .min(p[Role::RightFoot.index()].y)
        })
        .fold(f32::INFINITY, f32::min);
    let n = points.len().max(1) as f32;
    let centre = points
        .iter()
        .map(|p| p[Role::Hips.index()])
        .fold(Vec3::ZERO, |a, b| a + b)
        / n;
    let shift = Vec3::new(
        centre.x,
        if floor.is_finite() { floor } else { 0.0 },
        centre.z,
    );
    for p in &mut points {
        for v in p.iter_mut() {
            *v -= shift;
        }
    }
    Ok(GraphClip {
        clip,
        path: path.to_path_buf(),
        roles,
        scale,
        points,
    })
}

/// The clip resampled to `fps` frames per second (unchanged if already at that rate).
pub fn resample(clip: &Clip, fps: f32) -> Clip {
    let target = 1.0 / fps;
    if (clip.frame_time - target).abs() < 1e-4 * target || clip.frames.len() < 2 {
        let mut c = clip.clone();
        c.frame_time = target;
        return c;
    }
    let n = (clip.duration() / target).floor() as usize + 1;
    let frames = (0..n).map(|k| clip.sample(k as f32 * target)).collect();
    Clip {
        name: clip.name.clone(),
        skeleton: clip.skeleton.clone(),
        frame_time: target,
        frames,
    }
}

/// Loads many clips; clips shorter than a window are skipped with a warning on stderr.
///
/// Errors (malformed files) name the file and stop the load.
pub fn load_clips(
    paths: &[PathBuf],
    overrides: &RoleOverrides,
) -> Result<Vec<GraphClip>, GraphError> {
    let mut out = Vec::new();
    for p in paths {
        let c = load_clip(p, overrides)?;
        if c.len() < WINDOW {
            eprintln!(
                "warning: {}: {} frames at {FPS} fps is shorter than one {WINDOW}-frame window; skipped",
                p.display(),
                c.len()
            );
            continue;
        }
        out.push(c);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::data_file;

    #[test]
    fn rates_are_resampled_to_30fps() {
        let Some(p) = data_file("bvh", "sword_attack.bvh") else {
            eprintln!("skipping: run `cargo xtask setup`");
            return;
        };
        let c = load_clip(&p, &RoleOverrides::new()).unwrap();
        let orig = read_bvh_path(&p).unwrap().clip;
        assert!((c.clip.frame_time - 1.0 / 30.0).abs() < 1e-6);
        let expect = (orig.duration() * 30.0).floor() as usize + 1;
        assert_eq!(c.len(), expect);
        // Standing body: head about STANDARD_HEIGHT-ish above the floor, feet near 0.
        let head = c.points[0][Role::Head.index()].y;
        assert!(head > 1.0 && head < 2.0, "head at {head} m");
    }

    #[test]
    fn units_are_normalised_across_rigs() {
        for n in [
            "lafan_dance1.bvh",
            "blender_gestures.bvh",
            "mocapbank_kneel.bvh",
        ] {
            let Some(p) = data_file("bvh", n) else {
                eprintln!("skipping: run `cargo xtask setup`");
                return;
            };
            let c = load_clip(&p, &RoleOverrides::new()).unwrap();
            let h = c.points[0][Role::Hips.index()].y;
            assert!(h > 0.3 && h < 1.3, "{n}: hips at {h} m");
        }
    }

    #[test]
    fn malformed_file_error_names_it() {
        let dir = std::env::temp_dir().join(format!("figurine-graph-src-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("broken.bvh");
        std::fs::write(&p, "HIERARCHY\nROOT Hips\n{\nOFFSET 0 x 0\n").unwrap();
        let e = load_clip(&p, &RoleOverrides::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("broken.bvh"), "{e}");
        let q = dir.join("motion.txt");
        std::fs::write(&q, "{}").unwrap();
        let e = load_clip(&q, &RoleOverrides::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("motion.txt"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
