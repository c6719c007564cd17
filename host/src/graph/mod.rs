//! Style-coherent motion graphs (seed 003, Aristidou et al. 2017).
//!
//! Data flow, one file per stage:
//! - [`roles`]: which joint of any rig is the hips, head, hands, feet … (names + override file).
//! - [`source`]: clips loaded from BVH / DeepMimic, resampled to 30 fps, role points in
//!   height-normalised metres.
//! - [`lma`]: the 29 LMA features of Table 1 → 114 measurements per 35-frame window.
//! - [`posture`]: eq. 1, Kovar's posture distance with the closed-form 2-D alignment.
//! - [`style`]: eq. 2, Pearson style correlation per LMA component, weights, Gaussian smoothing.
//! - [`search`]: the tiled, streaming O(N²) posture search (never an N×N matrix).
//! - [`build`]: the single-machine build: features, every kernel tile on both cores, assembly.
//! - [`store`]: the per-frame / per-window feature store of a distributed job (Arrow IPC).
//! - [`plan`], [`tile`], [`merge`]: the build split into independent tiles for many machines;
//!   [`slurm`] writes the Slurm job array that runs them.
//! - [`graph`]: nodes, transition edges, blends, strongly connected trimming, the file format.
//! - [`synth`]: synthesis by highest similarity (§5.3) and by example (§5.4).
//! - [`effort`]: Laban Effort (Lt, Lw) from the Effort-component measurements, for choosing
//!   clip variants and transitions by a recognised effort.
//! - [`eval`]: the paper's §5.2–5.3 evaluation (label costs, transition counts).
//! - [`cli`]: `figurine graph build | synth | eval`; `job_cli`: `figurine graph plan | tile | merge`;
//!   [`inputs`]: the clips and build options both take.

use std::path::PathBuf;

use thiserror::Error;

pub mod build;
pub mod cli;
pub mod effort;
pub mod eval;
#[allow(clippy::module_inception)]
pub mod graph;
pub mod inputs;
pub mod ipc_floats;
pub mod ipc_prefix;
mod job_cli;
pub mod lma;
pub mod merge;
pub mod plan;
pub mod posture;
pub mod roles;
pub mod search;
pub mod slurm;
pub mod source;
pub mod store;
pub mod style;
pub mod synth;
pub mod tile;

pub use build::build_graph;
pub use graph::BuildParams;
pub use graph::{Edge, MotionGraph, Variant};
pub use roles::{Role, RoleMap};
pub use source::{load_clip, GraphClip};

/// Frames per second every clip is resampled to (the paper's capture rate).
pub const FPS: f32 = 30.0;
/// Frames in one analysis window (Table 1's 35-frame window at 30 fps).
pub const WINDOW: usize = 35;
/// Frames on each side of a window's centre frame.
pub const HALF: usize = WINDOW / 2;

/// Peak resident memory of this process so far, MiB (VmHWM from /proc/self/status; None where
/// there is no such file).
pub fn peak_memory_mib() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// CPU time this process has used so far, user + system over all threads, seconds (from
/// /proc/self/stat at Linux's 100 ticks per second; None where there is no such file). On a
/// shared machine it measures work where wall time also measures the neighbours.
pub fn cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    let mut f = s.get(s.rfind(')')? + 1..)?.split_whitespace();
    let utime: f64 = f.nth(11)?.parse().ok()?;
    let stime: f64 = f.next()?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

/// Why a motion-graph step failed.
#[derive(Debug, Error)]
pub enum GraphError {
    /// A motion file could not be read (the message names the file).
    #[error(transparent)]
    Motion(#[from] crate::motion::MotionError),
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A file's content is malformed (graph file, role override, labels …).
    #[error("{path}: {reason}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A skeleton lacks a joint for a role and no override names one.
    #[error("{clip}: no joint found for role `{role}` (joints: {joints}); name it in a role override file (--roles ROLES.json)")]
    MissingRole {
        /// The clip.
        clip: String,
        /// The role name.
        role: &'static str,
        /// The skeleton's joint names, comma-separated.
        joints: String,
    },
    /// The request cannot be served (no usable clips, empty graph …).
    #[error("{0}")]
    Invalid(String),
}

impl GraphError {
    /// A format error for `path`.
    pub fn format(path: impl Into<PathBuf>, reason: impl Into<String>) -> GraphError {
        GraphError::Format {
            path: path.into(),
            reason: reason.into(),
        }
    }
}
