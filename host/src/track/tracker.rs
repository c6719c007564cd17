//! One tag followed frame by frame: detection → the chosen id → pose → a pose-log sample.
//!
//! Where the tag is not found, or found with a pose the library itself finds poor, the frame
//! gives no sample: the recognizer treats the gap as a gap. The quaternion's sign is kept
//! continuous from sample to sample (q and −q are the same pose; a steady sign reads better).

use glam::DQuat;

use super::detect::{Detection, Detector, GrayFrame, Intrinsics};
use super::pnp::solve_pose;
use super::pose::figurine_pose;
use crate::poselog::PoseSample;

/// RMS corner reprojection error (pixels) above which a pose is not trusted: corners that no
/// flat square explains (a misread, or a frame smeared by fast motion). Good poses sit
/// well under a pixel.
pub const MAX_POSE_ERROR_PX: f64 = 2.0;

/// Follows one tag id.
#[derive(Debug)]
pub struct Tracker {
    detector: Detector,
    id: u32,
    tag_size: f64,
    intrinsics: Intrinsics,
    last: Option<DQuat>,
    last_cam: Option<DQuat>,
    smooth: Option<super::smooth::OrientationFilter>,
}

/// What one frame gave.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameResult {
    /// The sample, when the tag was seen with a trusted pose.
    pub sample: Option<PoseSample>,
    /// The detection of the tracked id, if any (for overlays).
    pub detection: Option<Detection>,
    /// Its pose in the camera frame, trusted or not.
    pub pose: Option<super::detect::CameraPose>,
}

impl Tracker {
    /// Follows tag `id` (edge of its black square `tag_size` metres) through a camera with
    /// `intrinsics`.
    pub fn new(detector: Detector, id: u32, tag_size: f64, intrinsics: Intrinsics) -> Self {
        Self {
            detector,
            id,
            tag_size,
            intrinsics,
            last: None,
            last_cam: None,
            smooth: None,
        }
    }

    /// Smooths the orientation (see [`super::smooth`]); off by default.
    pub fn with_smoothing(mut self, on: bool) -> Self {
        self.smooth = on.then(super::smooth::OrientationFilter::default);
        self
    }

    /// The camera's intrinsics in use.
    pub fn intrinsics(&self) -> Intrinsics {
        self.intrinsics
    }

    /// Processes the frame taken at `t` seconds.
    pub fn frame(&mut self, t: f64, frame: &GrayFrame) -> FrameResult {
        let found = self.detector.detect(frame);
        // Several copies of one id (a reflection, a second print): the clearest read wins.
        let best = found
            .into_iter()
            .filter(|d| d.id == self.id)
            .min_by(|a, b| {
                (a.hamming, -a.margin)
                    .partial_cmp(&(b.hamming, -b.margin))
                    .unwrap_or(std::cmp::Ordering::Equal)
            });
        let pose = best
            .as_ref()
            .and_then(|d| solve_pose(&d.corners, self.tag_size, &self.intrinsics, self.last_cam));
        let sample = pose.as_ref().and_then(|pose| {
            if pose.error > MAX_POSE_ERROR_PX {
                return None;
            }
            self.last_cam = Some(pose.quat());
            let (p, mut q) = figurine_pose(pose);
            if let Some(f) = &mut self.smooth {
                q = f.push(t, q);
            }
            if let Some(last) = self.last {
                if q.dot(last) < 0.0 {
                    q = -q;
                }
            }
            self.last = Some(q);
            Some(PoseSample {
                t,
                pos: p.to_array(),
                quat: [q.w, q.x, q.y, q.z],
            })
        });
        FrameResult {
            sample,
            detection: best,
            pose,
        }
    }
}

/// A whole source tracked.
#[derive(Debug, Clone, Default)]
pub struct TrackRun {
    /// One sample per frame where the tag was seen.
    pub log: crate::poselog::PoseLog,
    /// Frames read.
    pub frames: u64,
    /// Per frame, the time from the decoded frame to its sample (detection and pose),
    /// seconds.
    pub latency_s: Vec<f64>,
}

/// Tracks every frame of `reader`, handing each sample to `sink` as it is made (a live pipe
/// prints it at once).
pub fn track_reader(
    reader: &mut super::video::FrameReader,
    tracker: &mut Tracker,
    mut sink: impl FnMut(&PoseSample) -> Result<(), super::TrackError>,
) -> Result<TrackRun, super::TrackError> {
    let mut run = TrackRun::default();
    while let Some((t, frame)) = reader.next_frame()? {
        let start = std::time::Instant::now();
        let result = tracker.frame(t, &frame);
        run.latency_s.push(start.elapsed().as_secs_f64());
        run.frames += 1;
        if let Some(s) = result.sample {
            sink(&s)?;
            run.log.samples.push(s);
        }
    }
    Ok(run)
}
