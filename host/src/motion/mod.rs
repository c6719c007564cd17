//! Motion data: skeletons, clips, forward kinematics, and file formats.
//!
//! Lengths are in the unit of the source (BVH files are often centimetres; DeepMimic clips are
//! imported in metres); rotations are unit quaternions; time is seconds. World frame: +Y up.
//!
//! - [`skeleton`]: joints, offsets, channels, per-joint rotation orders.
//! - [`clip`]: poses, clips, forward kinematics, sampling.
//! - [`bvh_import`] / [`bvh_export`]: Biovision Hierarchy.
//! - [`urdf`] / [`deepmimic`]: DeepMimic motion JSON on pybullet's humanoid URDF.
//! - [`gltf_export`]: binary glTF 2.0 (.glb) with skin and animation.

use std::path::{Path, PathBuf};

use thiserror::Error;

pub mod bvh_export;
pub mod bvh_import;
pub mod clip;
pub mod deepmimic;
pub mod gltf_export;
pub mod skeleton;
pub mod urdf;

pub use bvh_export::{write_bvh_path, write_bvh_string};
pub use bvh_import::{read_bvh, read_bvh_path, BvhImport};
pub use clip::{slerp_short, Clip, Pose, WorldJoint};
pub use deepmimic::{read_deepmimic_path, DeepMimicClip};
pub use gltf_export::{write_glb_bytes, write_glb_path};
pub use skeleton::{Axis, Channel, Joint, RotationOrder, Skeleton};

/// Body height (in the file's unit) above which a take is read as centimetres: no performer
/// is 3 m tall, and no one is 3 cm.
pub const CENTIMETRE_HEIGHT: f32 = 3.0;

/// Reads a motion-capture take: a `.bvh` file, or a DeepMimic clip (`.txt` or `.json`) read on
/// `urdf` (default: the humanoid URDF `cargo xtask setup` fetches).
pub fn read_take(path: &Path, urdf: Option<&Path>) -> anyhow::Result<Clip> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("bvh") => Ok(read_bvh_path(path)?.clip),
        Some("txt") | Some("json") => {
            let urdf = match urdf {
                Some(u) => u.to_path_buf(),
                None => crate::data::require_data_file("deepmimic", "humanoid.urdf")?,
            };
            Ok(read_deepmimic_path(path, &urdf)?.clip)
        }
        _ => anyhow::bail!(
            "{}: not a motion-capture take (.bvh, or a DeepMimic .txt or .json)",
            path.display()
        ),
    }
}

/// Why motion data could not be read or written.
#[derive(Debug, Error)]
pub enum MotionError {
    /// A file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The content of a file is malformed at a line.
    #[error("{path}:{line}: {reason}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// The data cannot be represented (e.g. an empty clip on export).
    #[error("{0}")]
    Invalid(String),
}

impl MotionError {
    /// A parse error at `path:line`.
    pub fn parse(path: &Path, line: usize, reason: impl Into<String>) -> MotionError {
        MotionError::Parse {
            path: path.to_path_buf(),
            line,
            reason: reason.into(),
        }
    }
}
