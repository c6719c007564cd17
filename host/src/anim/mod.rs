//! Animation assembly (seed 000 §6): from recognised actions, their Laban efforts and the
//! doodle's path to a full-body character animation.
//!
//! Data flow, one file per stage:
//! [`library`] (action → clip variants; an entry's format in [`clip_spec`]; takes of other rigs
//! [`retarget`]ed onto its skeleton, clips that step to one side [`mirror`]ed for the other) →
//! [`variants`] (the variant matching the recognised effort, each variant's own effort measured
//! by [`variant_effort`]) →
//! [`phrasing`] (stages of each clip, §6.1) →
//! [`effort`] (retime eq. 6, rescale eq. 7 within the joints' ranges learnt from the library
//! and the hinges' ([`joint_limits`]), weight arc length, reshape; §6.3–6.4) →
//! [`trajectory`] (doodle → ground path, in-place offsets, cycles, jumps; §6.2) →
//! [`pacing`] (cycles at a human cadence, paths and retimes no faster than a person) →
//! [`looping`] (seamless repeats of looping clips) →
//! [`transition`] (best frames by windowed posture distance, seed 003 eq. 1; blending) →
//! [`contact`] (foot contacts, two-bone IK against ground penetration) → [`footing`] (feet on
//! the ground stand, the others clear it) →
//! [`assemble`] (the whole pipeline) → [`cli`] (`figurine animate`, `figurine clip stages|plot|variants`).
//! [`plot`] draws contact sheets to look at the result; [`check`] (`figurine check`) judges
//! it against real motion capture (penetration, floating, skating, joints bent backwards)
//! within the bounds of [`envelope`], which [`pacing`] holds a path to as well, and each
//! action's torso tilt against the real takes of its kind ([`tilt_reference`]; measured by
//! [`torso_tilt`], which effort transfer holds a frame's tilt with). [`sideways`]
//! (`figurine clip sideways`) searches takes for sideways stepping to cut a sidestep from.

use std::path::PathBuf;

use thiserror::Error;

use crate::motion::MotionError;

pub mod assemble;
pub mod check;
pub mod cli;
pub mod clip_spec;
pub mod contact;
pub mod defaults;
pub mod effort;
pub mod envelope;
pub mod footing;
pub mod graph_cuts;
pub mod joint_limits;
pub mod library;
pub mod looping;
pub mod mirror;
pub mod pacing;
pub mod phrasing;
pub mod plot;
pub mod retarget;
pub mod sideways;
pub mod tilt_reference;
pub mod torso_tilt;
pub mod trajectory;
pub mod transition;
pub mod variant_effort;
pub mod variants;

/// Why an animation could not be assembled.
#[derive(Debug, Error)]
pub enum AnimError {
    /// Reading or writing motion data failed.
    #[error(transparent)]
    Motion(#[from] MotionError),
    /// A file could not be read or written.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// A clip-library (or effort) file is malformed.
    #[error("{path}:{line}: {reason}")]
    Spec {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// Some recognised actions have no clip in the library.
    #[error("no clip for action(s) {} in {library} (it maps: {})", missing.join(", "), available.join(", "))]
    MissingClips {
        /// The library's file name.
        library: String,
        /// Actions without a mapping, sorted.
        missing: Vec<String>,
        /// Actions the library does map.
        available: Vec<String>,
    },
    /// Data is missing or inconsistent.
    #[error("{0}")]
    Data(String),
}
