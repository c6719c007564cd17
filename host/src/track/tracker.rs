//! One tag followed frame by frame: detection → the chosen id → pose → a pose-log sample.
//!
//! The tag is looked for first in a region around where it was last seen, moved on at its
//! image velocity (about a millisecond, where the whole 640×480 frame takes tens), and in
//! the whole frame when it is not found there or was not seen lately. The region finds the
//! corners the whole frame would, to within a tenth of a pixel.
//!
//! Where the tag is not found, or found with a pose the library itself finds poor, the frame
//! gives no sample: the recognizer treats the gap as a gap. The quaternion's sign is kept
//! continuous from sample to sample (q and −q are the same pose; a steady sign reads better).

use glam::DQuat;

use super::detect::{Detection, Detector, GrayFrame, Intrinsics, Region};
use super::pnp::solve_pose;
use super::pose::figurine_pose;
use super::smooth::OrientationFilter;
use crate::poselog::PoseSample;

/// RMS corner reprojection error (pixels) above which a pose is not trusted: corners that no
/// flat square explains (a misread, or a frame smeared by fast motion). Good poses sit
/// well under a pixel.
pub const MAX_POSE_ERROR_PX: f64 = 2.0;

/// Around the tag's predicted place, the search region reaches this many tag widths beyond
/// its corners: the tag's white margin and card (a quarter width) must be inside for the
/// library to see the border, and the rest covers a change of speed between frames.
pub const SEARCH_MARGIN_TAGS: f64 = 1.0;

/// Least margin of the search region, pixels: the library's thresholding works on 4×4 tiles
/// and looks 1 tile further, so a small tag far away still gets a few tiles around it.
pub const MIN_SEARCH_MARGIN_PX: f64 = 16.0;

/// The region search is tried only when the tag was seen within this many seconds; after a
/// longer gap the tag may be anywhere and the whole frame is searched.
pub const MAX_SEARCH_GAP_S: f64 = 0.1;

/// Where the tag was last seen, for searching near it first.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Seen {
    t: f64,
    corners: [[f64; 2]; 4],
    /// Image velocity of the tag's centre, pixels per second (zero after one sighting).
    velocity: [f64; 2],
}

/// Follows one tag id.
#[derive(Debug)]
pub struct Tracker {
    detector: Detector,
    id: u32,
    tag_size: f64,
    intrinsics: Intrinsics,
    last: Option<DQuat>,
    last_cam: Option<DQuat>,
    smooth: Option<OrientationFilter>,
    seen: Option<Seen>,
    search_near: bool,
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
    /// The region searched first, near the tag's last place (`None`: the whole frame only).
    pub region: Option<Region>,
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
            seen: None,
            search_near: true,
        }
    }

    /// Whether to search near the tag's last place first (on by default); off, every frame
    /// is searched whole (the same detections, slower: for comparing the two).
    pub fn with_region_search(mut self, on: bool) -> Self {
        self.search_near = on;
        self
    }

    /// Smooths the orientation (see [`super::smooth`]); off by default.
    pub fn with_smoothing(mut self, on: bool) -> Self {
        self.smooth = on.then(OrientationFilter::default);
        self
    }

    /// The camera's intrinsics in use.
    pub fn intrinsics(&self) -> Intrinsics {
        self.intrinsics
    }

    /// Processes the frame taken at `t` seconds.
    pub fn frame(&mut self, t: f64, frame: &GrayFrame) -> FrameResult {
        let near = self.search_region(t, frame);
        let id = self.id;
        let mut best = near.and_then(|r| clearest(id, self.detector.detect_in(frame, r)));
        if best.is_none() {
            best = clearest(id, self.detector.detect(frame));
        }
        self.seen = best.as_ref().map(|d| {
            let velocity = match self.seen {
                Some(s) if t > s.t && t - s.t <= MAX_SEARCH_GAP_S => {
                    let (a, b) = (centre(&s.corners), centre(&d.corners));
                    [(b[0] - a[0]) / (t - s.t), (b[1] - a[1]) / (t - s.t)]
                }
                _ => [0.0; 2],
            };
            Seen {
                t,
                corners: d.corners,
                velocity,
            }
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
            region: near,
        }
    }
}

/// Several copies of one id (a reflection, a second print): the clearest read wins.
fn clearest(id: u32, found: Vec<Detection>) -> Option<Detection> {
    found.into_iter().filter(|d| d.id == id).min_by(|a, b| {
        (a.hamming, -a.margin)
            .partial_cmp(&(b.hamming, -b.margin))
            .unwrap_or(std::cmp::Ordering::Equal)
    })
}

impl Tracker {
    /// The region to search first at `t`: the last corners moved on at the tag's image
    /// velocity, grown by a margin of [`SEARCH_MARGIN_TAGS`] tag widths plus the distance the
    /// tag moved in the last frame (a change of speed up to the speed itself is still found);
    /// `None` when the tag was not seen lately or the region would be most of the frame.
    fn search_region(&self, t: f64, frame: &GrayFrame) -> Option<Region> {
        let seen = self.seen.filter(|_| self.search_near)?;
        let dt = t - seen.t;
        if !(dt > 0.0 && dt <= MAX_SEARCH_GAP_S) {
            return None;
        }
        let (vx, vy) = (seen.velocity[0] * dt, seen.velocity[1] * dt);
        let moved = seen.corners.map(|[x, y]| [x + vx, y + vy]);
        let side = (0..4)
            .map(|i| {
                let (a, b) = (seen.corners[i], seen.corners[(i + 1) % 4]);
                (a[0] - b[0]).hypot(a[1] - b[1])
            })
            .fold(0.0, f64::max);
        let margin = (SEARCH_MARGIN_TAGS * side).max(MIN_SEARCH_MARGIN_PX) + vx.hypot(vy);
        let r = Region::around(&moved, margin, frame.width, frame.height)?;
        (2 * r.area() < frame.width * frame.height).then_some(r)
    }
}

fn centre(c: &[[f64; 2]; 4]) -> [f64; 2] {
    [
        (c[0][0] + c[1][0] + c[2][0] + c[3][0]) / 4.0,
        (c[0][1] + c[1][1] + c[2][1] + c[3][1]) / 4.0,
    ]
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::detect::{DetectorSettings, Family};
    use crate::track::render::{tests::test_scene, Faults, Scene};

    fn scene() -> Scene {
        let faults = Faults {
            occlusion_every_s: 0.0,
            ..Faults::default()
        };
        test_scene(faults, 4)
    }

    fn tracker(scene: &Scene) -> Tracker {
        let d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        Tracker::new(d, 0, scene.tag_size, scene.intrinsics).with_smoothing(true)
    }

    /// A figurine sliding across the view at 0.6 m/s, 0.7 m away, turning a little.
    fn slide(t: f64) -> PoseSample {
        let q = DQuat::from_rotation_y(0.3 * (3.0 * t).sin());
        PoseSample {
            t,
            pos: [-0.15 + 0.6 * t, 0.02, -0.7],
            quat: [q.w, q.x, q.y, q.z],
        }
    }

    #[test]
    fn searching_near_the_last_place_finds_what_the_whole_frame_does() {
        let s = scene();
        let bg = s.background();
        let (mut near, mut whole) = (tracker(&s), tracker(&s).with_region_search(false));
        let mut in_region = 0;
        for i in 0..15 {
            let t = i as f64 / 30.0;
            let frame = s.render(&bg, i, t, |t| Some(slide(t))).frame;
            let (a, b) = (near.frame(t, &frame), whole.frame(t, &frame));
            in_region += usize::from(a.region.is_some());
            assert!(b.region.is_none());
            let (Some(a), Some(b)) = (a.sample, b.sample) else {
                panic!("frame {i}: lost");
            };
            let gap = (0..3)
                .map(|k| (a.pos[k] - b.pos[k]).abs())
                .fold(0.0, f64::max);
            let turn = DQuat::from_array([a.quat[1], a.quat[2], a.quat[3], a.quat[0]])
                .angle_between(DQuat::from_array([
                    b.quat[1], b.quat[2], b.quat[3], b.quat[0],
                ]));
            assert!(gap < 1e-3, "frame {i}: {:.2} mm apart", gap * 1000.0);
            assert!(turn < 0.02, "frame {i}: {turn} rad apart");
        }
        assert!(
            in_region >= 13,
            "searched near the tag in {in_region} of 15 frames"
        );
    }

    #[test]
    fn a_lost_tag_is_searched_for_in_the_whole_frame() {
        let s = scene();
        let bg = s.background();
        let mut tr = tracker(&s);
        let frame = s.render(&bg, 0, 0.0, |t| Some(slide(t))).frame;
        assert!(tr.frame(0.0, &frame).sample.is_some());
        // Jumped far across the frame: the region misses it, the whole frame finds it.
        let far = |t: f64| {
            Some(PoseSample {
                pos: [0.2, -0.1, -0.7],
                ..slide(t)
            })
        };
        let frame = s.render(&bg, 1, 1.0 / 30.0, far).frame;
        let r = tr.frame(1.0 / 30.0, &frame);
        assert!(r.region.is_some() && r.sample.is_some());
        assert!((r.sample.unwrap().pos[0] - 0.2).abs() < 0.01);
    }
}
