//! `figurine track`: a webcam and a printed AprilTag as a 6-DoF tracker anyone has.
//!
//! Frames come from a video file or a V4L2 camera through ffmpeg ([`video`]); libapriltag
//! finds the tag and its corners ([`detect`]), near its last place first and in the whole
//! frame when it is not there; [`pnp`] solves its pose from them (homography, then
//! Levenberg–Marquardt on the four corners); [`pose`] turns that into the pose log's frames;
//! [`tracker`] keeps one tag id and writes a sample per frame where it was seen — a lost tag
//! gives no sample, never a made-up pose; a camera that looks down has its tilt undone
//! ([`pose::camera_tilt`], measured by [`level`]). [`render`] draws test videos of the tag on
//! a moving figurine and [`eval`] compares what was tracked with the truth.

pub mod bench;
pub mod body;
pub mod calibrate;
pub mod cli;
pub mod deblur;
pub mod detect;
pub mod eval;
pub mod fuse;
pub mod level;
pub mod mirror;
pub mod photo;
pub mod pnp;
pub mod pose;
pub mod print;
pub mod render;
pub mod rig;
pub mod smooth;
pub mod still;
pub mod tracker;
pub mod trial;
pub mod video;

use std::path::PathBuf;

use thiserror::Error;

/// What can go wrong tracking a tag.
#[derive(Debug, Error)]
pub enum TrackError {
    /// The video file cannot be read.
    #[error("{path}: cannot read the video: {reason}")]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The camera cannot be opened or stopped delivering.
    #[error("{device}: {reason}")]
    Camera {
        /// The device node.
        device: PathBuf,
        /// Why.
        reason: String,
    },
    /// The tag was never seen.
    #[error(
        "{source_name}: no {family} tag {ids} in any of {frames} frames (is the tag in view, \
         well lit, of this family and id? a tag under ~15 px across is too small)"
    )]
    NoTag {
        /// The video file or camera.
        source_name: String,
        /// The family looked for.
        family: &'static str,
        /// The ids looked for ("0", or a rig's "0, 1, 2, 3").
        ids: String,
        /// Frames searched.
        frames: u64,
    },
    /// A calibration file is unreadable or holds no camera.
    #[error("{path}: bad calibration file: {reason}")]
    BadCalibration {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A tag id the family does not have.
    #[error("{family} has ids 0..{count}, not {id}")]
    BadTagId {
        /// The family.
        family: &'static str,
        /// The id asked for.
        id: u32,
        /// How many ids it has.
        count: u32,
    },
    /// A rig description that cannot be tracked.
    #[error("bad rig: {0}")]
    BadRig(String),
    /// An argument makes no sense.
    #[error("{0}")]
    BadArgument(String),
    /// An external tool (ffmpeg, ffprobe) is missing or failed.
    #[error("{tool}: {reason}")]
    Tool {
        /// The program.
        tool: String,
        /// What happened.
        reason: String,
    },
    /// The detector library failed.
    #[error("libapriltag: {0}")]
    Detector(String),
    /// An output file could not be written.
    #[error("{path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}
