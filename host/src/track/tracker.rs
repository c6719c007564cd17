//! One tag — or the tags of a rig around the figurine — followed frame by frame: detection →
//! the rig's ids → a pose per tag → one figurine pose ([`super::fuse`]) → a pose-log sample.
//!
//! The tags are looked for first in a region around where the rig was last seen, moved on at
//! its image velocity (about a millisecond, where the whole 640×480 frame takes tens), and in
//! the whole frame when none is found there or the rig was not seen lately. The region finds
//! the corners the whole frame would, to within a tenth of a pixel.
//!
//! Where no tag is found, or none with a pose the tracker trusts, the frame gives no sample:
//! the recognizer treats the gap as a gap. The quaternion's sign is kept continuous from
//! sample to sample (q and −q are the same pose; a steady sign reads better).

use glam::{DQuat, DVec3};

use super::detect::{
    tag_pattern, CameraPose, Detection, Detector, GrayFrame, Intrinsics, Region, TagPattern,
    ENLARGE,
};
use super::fuse::{fuse, solve_tags, Fused};
use super::mirror::MirrorChooser;
use super::photo::evidence;
use super::pose::{figurine_pose, project};
use super::rig::Rig;
use super::smooth::OrientationFilter;
use crate::poselog::PoseSample;

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

/// A tag last seen narrower than this (its longest side, pixels) and not found near its last
/// place is looked for there again in the picture enlarged
/// ([`Detector::detect_in_enlarged`]) before the whole frame is searched: at 1 m a 4 cm tag
/// turned 45° is ~15 px wide, cells of 1.5 px, at the library's limit.
pub const SMALL_TAG_PX: f64 = 32.0;

/// The camera's exposure assumed when none is given, seconds: a webcam indoors exposes 5–15 ms
/// (the track bench renders 8 ms). Only the motion-blur retry uses it, to predict how far a
/// moving tag is smeared.
pub const DEFAULT_EXPOSURE_S: f64 = 0.008;

/// A tag not found near its predicted place is looked for there again with the motion blur
/// undone ([`Detector::detect_in_deblurred`]) when its predicted smear is at least this long,
/// pixels: shorter smears do not stop the library, and the restoration costs milliseconds.
pub const MIN_BLUR_PX: f64 = 2.0;

/// Where the rig was last seen, for searching near it first.
#[derive(Debug, Clone, PartialEq)]
struct Seen {
    t: f64,
    /// The tag's corners (one tag), or every rig tag's corners at the pose found (a rig: so a
    /// face turning into view is inside the region too), pixels.
    points: Vec<[f64; 2]>,
    /// Longest side of a tag found, pixels.
    side: f64,
    /// Image velocity of the points' centre, pixels per second (zero after one sighting).
    velocity: [f64; 2],
}

/// Follows one tag id, or the tags of a rig around the figurine.
#[derive(Debug)]
pub struct Tracker {
    detector: Detector,
    rig: Rig,
    intrinsics: Intrinsics,
    last: Option<DQuat>,
    /// Which of a lone tag's mirror poses to report, decided over frames.
    mirror: MirrorChooser,
    smooth: Option<OrientationFilter>,
    seen: Option<Seen>,
    search_near: bool,
    /// The camera's exposure, seconds, for predicting motion blur (0: no blur retry).
    exposure_s: f64,
    /// The camera's frame in the world ([`super::pose::camera_tilt`]; identity: level).
    camera: DQuat,
    /// Each rig tag's printed pattern, by id, for judging a lone tag's mirror on its picture
    /// ([`super::photo`]); a tag whose pattern the library cannot draw is judged on its corners.
    patterns: Vec<(u32, TagPattern)>,
}

/// What one frame gave.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameResult {
    /// The sample, when a tag was seen with a trusted pose.
    pub sample: Option<PoseSample>,
    /// The largest detection of a tracked id, if any (for overlays).
    pub detection: Option<Detection>,
    /// Every tag of the rig found, in the rig's order.
    pub detections: Vec<Detection>,
    /// The body's pose in the camera frame (for one tag, the tag's), trusted or not.
    pub pose: Option<super::detect::CameraPose>,
    /// The region searched first, near the tag's last place (`None`: the whole frame only).
    pub region: Option<Region>,
    /// Pixels the detector searched for this frame, over every try (a region searched
    /// enlarged counts its enlarged pixels): the work the region search saves.
    pub searched_px: usize,
}

impl Tracker {
    /// Follows tag `id` (edge of its black square `tag_size` metres) through a camera with
    /// `intrinsics`.
    pub fn new(detector: Detector, id: u32, tag_size: f64, intrinsics: Intrinsics) -> Self {
        Self::with_rig(detector, Rig::single(id, tag_size), intrinsics)
    }

    /// Follows the tags of `rig` (of the detector's family) through a camera with
    /// `intrinsics`.
    pub fn with_rig(detector: Detector, rig: Rig, intrinsics: Intrinsics) -> Self {
        let patterns = rig
            .faces
            .iter()
            .filter_map(|f| Some((f.id, tag_pattern(detector.family(), f.id).ok()?)))
            .collect();
        Self {
            detector,
            rig,
            intrinsics,
            last: None,
            mirror: MirrorChooser::default(),
            smooth: None,
            seen: None,
            search_near: true,
            exposure_s: DEFAULT_EXPOSURE_S,
            camera: DQuat::IDENTITY,
            patterns,
        }
    }

    /// The camera looks down `deg` degrees (0 unless set: level): every pose is turned from
    /// the camera's frame into the world's, whose +Y is up, before it is reported.
    pub fn with_camera_tilt(mut self, deg: f64) -> Self {
        self.camera = if deg.is_finite() {
            super::pose::camera_tilt(deg)
        } else {
            DQuat::IDENTITY
        };
        self
    }

    /// The camera's exposure (seconds; [`DEFAULT_EXPOSURE_S`] unless set), from which a moving
    /// tag's smear is predicted for the blur retry; 0 turns the retry off.
    pub fn with_exposure(mut self, seconds: f64) -> Self {
        self.exposure_s = if seconds.is_finite() {
            seconds.max(0.0)
        } else {
            0.0
        };
        self
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

    /// The rig followed.
    pub fn rig(&self) -> &Rig {
        &self.rig
    }

    /// Processes the frame taken at `t` seconds.
    pub fn frame(&mut self, t: f64, frame: &GrayFrame) -> FrameResult {
        let near = self.search_region(t, frame);
        let mut searched = near.map_or(0, |r| r.area());
        let mut found = near
            .map(|r| clearest(&self.rig, self.detector.detect_in(frame, r)))
            .unwrap_or_default();
        let small = self.seen.as_ref().is_some_and(|s| s.side < SMALL_TAG_PX);
        if let Some(r) = near.filter(|_| found.is_empty() && small) {
            searched += r.area() * ENLARGE * ENLARGE;
            found = clearest(&self.rig, self.detector.detect_in_enlarged(frame, r));
        }
        if found.is_empty() {
            if let Some((r, blur)) = self.blur_region(t, frame) {
                searched += r.area();
                found = clearest(&self.rig, self.detector.detect_in_deblurred(frame, r, blur));
            }
        }
        if found.is_empty() {
            searched += frame.width * frame.height;
            found = clearest(&self.rig, self.detector.detect(frame));
        }
        let k = self.intrinsics;
        let tags = solve_tags(&self.rig, found.clone(), &k);
        let fused = match fuse(&self.rig, &tags, &k) {
            Some(Fused::Settled(pose)) => {
                self.mirror.settle(t, &pose);
                Some(pose)
            }
            Some(Fused::Lone {
                candidates,
                corners,
                id,
                tag_poses,
            }) => {
                let pattern = self.patterns.iter().find(|(p, _)| *p == id);
                let tag_size = self.rig.tag_size;
                self.mirror.choose(t, &candidates, &corners, || {
                    pattern.and_then(|(_, p)| evidence(frame, &k, p, tag_size, &tag_poses))
                })
            }
            None => None,
        };
        let largest = tags
            .iter()
            .max_by(|a, b| a.area_px().total_cmp(&b.area_px()));
        let best = largest
            .map(|s| s.detection.clone())
            .or_else(|| found.first().cloned());
        self.remember(t, &found, fused.as_ref());
        let sample = fused.as_ref().map(|pose| {
            let (p, mut q) = figurine_pose(pose);
            if let Some(f) = &mut self.smooth {
                q = f.push(t, q);
            }
            let (p, mut q) = (self.camera * p, (self.camera * q).normalize());
            if let Some(last) = self.last {
                if q.dot(last) < 0.0 {
                    q = -q;
                }
            }
            self.last = Some(q);
            PoseSample {
                t,
                pos: p.to_array(),
                quat: [q.w, q.x, q.y, q.z],
            }
        });
        FrameResult {
            sample,
            detection: best,
            detections: found,
            pose: fused.or_else(|| largest.map(|s| s.body)),
            region: near,
            searched_px: searched,
        }
    }

    /// Keeps where the rig was seen at `t` for the next frame's region search: one tag's
    /// corners, or for a rig every tag's corners at the pose found (a face turning into view
    /// is then inside the region). When no tag was found the last sighting stays: the next
    /// frames still search where it has moved on to, until [`MAX_SEARCH_GAP_S`] has passed
    /// (a tag lost to one smeared frame is then looked for, unsmeared, where it went).
    fn remember(&mut self, t: f64, found: &[Detection], pose: Option<&CameraPose>) {
        if found.is_empty() {
            return;
        }
        let k = self.intrinsics;
        let projected: Vec<[f64; 2]> = match pose {
            Some(pose) if self.rig.faces.len() > 1 => {
                let (r, tr) = (pose.matrix(), DVec3::from_array(pose.translation));
                self.rig
                    .faces
                    .iter()
                    .flat_map(|f| f.corners_in_body(self.rig.tag_size))
                    .filter_map(|c| project(&k, r * c + tr))
                    .collect()
            }
            _ => Vec::new(),
        };
        let points = if projected.is_empty() {
            found.iter().flat_map(|d| d.corners).collect()
        } else {
            projected
        };
        let side = found
            .iter()
            .flat_map(|d| {
                (0..4).map(|i| {
                    let (a, b) = (d.corners[i], d.corners[(i + 1) % 4]);
                    (a[0] - b[0]).hypot(a[1] - b[1])
                })
            })
            .fold(0.0, f64::max);
        let velocity = match &self.seen {
            Some(s) if t > s.t && t - s.t <= MAX_SEARCH_GAP_S => {
                let (a, b) = (centre(&s.points), centre(&points));
                [(b[0] - a[0]) / (t - s.t), (b[1] - a[1]) / (t - s.t)]
            }
            _ => [0.0; 2],
        };
        self.seen = Some(Seen {
            t,
            points,
            side,
            velocity,
        });
    }
}

/// The rig's tags among what the detector found, one per id (several copies of one id — a
/// reflection, a second print —: the clearest read wins), in the rig's order.
fn clearest(rig: &Rig, found: Vec<Detection>) -> Vec<Detection> {
    rig.faces
        .iter()
        .filter_map(|f| {
            found.iter().filter(|d| d.id == f.id).min_by(|a, b| {
                (a.hamming, -a.margin)
                    .partial_cmp(&(b.hamming, -b.margin))
                    .unwrap_or(std::cmp::Ordering::Equal)
            })
        })
        .cloned()
        .collect()
}

impl Tracker {
    /// The region to search first at `t`: the last points moved on at their image velocity,
    /// grown by a margin of [`SEARCH_MARGIN_TAGS`] tag widths plus the distance they moved in
    /// the last frame (a change of speed up to the speed itself is still found); `None` when
    /// the rig was not seen lately or the region would be most of the frame.
    fn search_region(&self, t: f64, frame: &GrayFrame) -> Option<Region> {
        let seen = self.seen.as_ref().filter(|_| self.search_near)?;
        let dt = t - seen.t;
        if !(dt > 0.0 && dt <= MAX_SEARCH_GAP_S) {
            return None;
        }
        let (vx, vy) = (seen.velocity[0] * dt, seen.velocity[1] * dt);
        let moved: Vec<[f64; 2]> = seen.points.iter().map(|[x, y]| [x + vx, y + vy]).collect();
        let margin = (SEARCH_MARGIN_TAGS * seen.side).max(MIN_SEARCH_MARGIN_PX) + vx.hypot(vy);
        let r = Region::around(&moved, margin, frame.width, frame.height)?;
        (2 * r.area() < frame.width * frame.height).then_some(r)
    }
}

impl Tracker {
    /// Where and how to retry with the motion blur undone at `t`: the tag's last corners moved
    /// on at its image velocity, with a margin of half a tag (its white card) plus the smear,
    /// and the smear itself — the image velocity times the exposure, pixels. `None` when the
    /// tag was not seen lately, was still, or its smear is under [`MIN_BLUR_PX`].
    fn blur_region(&self, t: f64, frame: &GrayFrame) -> Option<(Region, [f64; 2])> {
        let seen = self.seen.as_ref().filter(|_| self.search_near)?;
        let dt = t - seen.t;
        if !(dt > 0.0 && dt <= MAX_SEARCH_GAP_S) {
            return None;
        }
        let blur = seen.velocity.map(|v| v * self.exposure_s);
        let len = blur[0].hypot(blur[1]);
        if len.is_nan() || len < MIN_BLUR_PX {
            return None;
        }
        let (vx, vy) = (seen.velocity[0] * dt, seen.velocity[1] * dt);
        let moved: Vec<[f64; 2]> = seen.points.iter().map(|[x, y]| [x + vx, y + vy]).collect();
        let margin = (0.5 * seen.side).max(MIN_SEARCH_MARGIN_PX) + len;
        let r = Region::around(&moved, margin, frame.width, frame.height)?;
        (2 * r.area() < frame.width * frame.height).then_some((r, blur))
    }
}

/// The mean of the points, pixels.
fn centre(points: &[[f64; 2]]) -> [f64; 2] {
    let n = points.len().max(1) as f64;
    let (x, y) = points
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p[0], y + p[1]));
    [x / n, y / n]
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
    /// Per frame, the pixels the detector searched ([`FrameResult::searched_px`]).
    pub searched_px: Vec<usize>,
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
        run.searched_px.push(result.searched_px);
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
        Tracker::new(d, 0, scene.body.tag_size, scene.intrinsics).with_smoothing(true)
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
    fn two_faces_of_a_rendered_rig_agree_on_the_figurine_s_pose() {
        use crate::track::body::Body;
        use crate::track::detect::tag_pattern;
        use crate::track::fuse::solve_tags;
        use crate::track::pose::angle_between_deg;
        let rig = Rig::boxed(0, 0.04, 0.08, 0.08);
        let patterns = (0..4)
            .map(|id| tag_pattern(Family::Tag36h11, id).unwrap())
            .collect();
        let s = Scene {
            body: Body::rig_box(&rig, patterns, 0.08, 0.08),
            ..scene()
        };
        let d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        let mut tr = Tracker::with_rig(d, rig.clone(), s.intrinsics);
        // Turned 45° to its right, 0.6 m ahead: the front and the left face equally in sight.
        let q = DQuat::from_rotation_y(-45f64.to_radians());
        let truth = PoseSample {
            t: 0.0,
            pos: [0.01, 0.0, -0.6],
            quat: [q.w, q.x, q.y, q.z],
        };
        let frame = s.render(&s.background(), 0, 0.0, |_| Some(truth)).frame;
        let r = tr.frame(0.0, &frame);
        let ids: Vec<u32> = r.detections.iter().map(|d| d.id).collect();
        assert_eq!(ids, [0, 1], "the front and the left tag");
        let tags = solve_tags(&rig, r.detections.clone(), &s.intrinsics);
        let poses: Vec<_> = tags.iter().map(|t| figurine_pose(&t.body)).collect();
        let apart = (poses[0].0 - poses[1].0).length() * 1000.0;
        let turn = angle_between_deg(poses[0].1, poses[1].1);
        assert!(apart < 8.0, "{apart:.1} mm apart");
        assert!(turn < 4.0, "{turn:.2}° apart");
        // And the one sample of both is near the truth.
        let got = r.sample.expect("a sample");
        let err = (glam::DVec3::from_array(got.pos) - glam::DVec3::from_array(truth.pos)).length();
        assert!(err < 5e-3, "{:.1} mm off", err * 1000.0);
        let got_q = DQuat::from_xyzw(got.quat[1], got.quat[2], got.quat[3], got.quat[0]);
        assert!(angle_between_deg(got_q, q) < 2.0);
    }

    /// Pitch (about the figurine's +X, degrees) of a sample's orientation.
    fn pitch_deg(s: &PoseSample) -> f64 {
        let q = DQuat::from_xyzw(s.quat[1], s.quat[2], s.quat[3], s.quat[0]);
        q.to_euler(glam::EulerRot::XYZ).0.to_degrees()
    }

    #[test]
    fn a_lone_tag_pitched_through_face_on_at_1_m_is_reported_on_its_true_side() {
        // A kick at 1 m, as the track bench renders it (8 ms blur, defocus, noise): the toy
        // rests pitched +4°, swings to −18° in 0.2 s while rising 1.5 cm, holds, returns.
        let s = test_scene(Faults::default(), 9);
        let bg = s.background();
        let pitch = |t: f64| {
            let a = ((t - 0.3) / 0.2).clamp(0.0, 1.0);
            let b = ((t - 0.8) / 0.2).clamp(0.0, 1.0);
            let ease = |x: f64| x * x * (3.0 - 2.0 * x);
            4.0 - 22.0 * (ease(a) - ease(b))
        };
        let pose = |t: f64| {
            let q = DQuat::from_rotation_x(pitch(t).to_radians());
            let lift = 0.015 * (pitch(t) - 4.0) / -22.0;
            Some(PoseSample {
                t,
                pos: [0.0, lift, -1.0],
                quat: [q.w, q.x, q.y, q.z],
            })
        };
        let mut tr = tracker(&s);
        let mut wrong = Vec::new();
        for i in 0..36 {
            let t = i as f64 / 30.0;
            let frame = s.render(&bg, i, t, pose).frame;
            if let Some(got) = tr.frame(t, &frame).sample {
                let truth = pitch(t);
                if truth.abs() > 10.0 && (pitch_deg(&got) - truth).abs() > 10.0 {
                    wrong.push((i, truth.round(), pitch_deg(&got).round()));
                }
            }
        }
        assert!(wrong.is_empty(), "(frame, true pitch, reported): {wrong:?}");
    }

    #[test]
    fn a_deep_bow_is_followed_by_the_box_s_top_tag() {
        use crate::track::body::Body;
        use crate::track::detect::tag_pattern;
        use crate::track::pose::angle_between_deg;
        use crate::track::rig::BoxSize;
        let size = BoxSize {
            top: Some(0.09),
            ..BoxSize::sides(0.08, 0.08)
        };
        let rig = Rig::checked_box(Family::Tag36h11, 0, 0.04, size).unwrap();
        let patterns = (0..5)
            .map(|id| tag_pattern(Family::Tag36h11, id).unwrap())
            .collect();
        let s = Scene {
            body: Body::rig_box(&rig, patterns, 0.08, 0.08),
            ..scene()
        };
        let d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        let mut tr = Tracker::with_rig(d, rig, s.intrinsics);
        // Bowed 75° toward the camera, 0.8 m away: the front tag is a sliver, the top square on.
        let q = DQuat::from_rotation_x(75f64.to_radians());
        let truth = PoseSample {
            t: 0.0,
            pos: [0.0, 0.0, -0.8],
            quat: [q.w, q.x, q.y, q.z],
        };
        let frame = s.render(&s.background(), 0, 0.0, |_| Some(truth)).frame;
        let r = tr.frame(0.0, &frame);
        let ids: Vec<u32> = r.detections.iter().map(|d| d.id).collect();
        assert_eq!(ids, [4], "only the top tag");
        let got = r.sample.expect("a sample");
        let err = (glam::DVec3::from_array(got.pos) - glam::DVec3::from_array(truth.pos)).length();
        assert!(err < 6e-3, "{:.1} mm off", err * 1000.0);
        let got_q = DQuat::from_xyzw(got.quat[1], got.quat[2], got.quat[3], got.quat[0]);
        assert!(angle_between_deg(got_q, q) < 4.0);
    }

    /// Speeding up across the view 0.45 m away: 0.5 m/s at first, 1.35 m/s after 0.33 s
    /// (a smear of 8–13 px over the 8 ms exposure on a tag 50 px wide).
    fn dash(t: f64) -> PoseSample {
        let q = DQuat::from_rotation_y(0.2);
        PoseSample {
            t,
            pos: [-0.15 + 0.5 * t + 1.25 * t * t, 0.0, -0.45],
            quat: [q.w, q.x, q.y, q.z],
        }
    }

    #[test]
    fn a_smeared_tag_is_found_with_its_predicted_blur_undone() {
        let s = scene();
        let bg = s.background();
        let (mut retry, mut plain) = (tracker(&s), tracker(&s).with_exposure(0.0));
        let (mut lost_plain, mut lost_retry, mut worst_mm) = (0, 0, 0.0f64);
        for i in 0..11 {
            let t = i as f64 / 30.0;
            let frame = s.render(&bg, i, t, |t| Some(dash(t))).frame;
            let (a, b) = (retry.frame(t, &frame), plain.frame(t, &frame));
            lost_retry += usize::from(a.sample.is_none());
            if b.sample.is_some() {
                continue;
            }
            lost_plain += 1;
            // Where only the retry finds it, its pose is as good as a sharp tag's.
            if let Some(got) = a.sample {
                let truth = glam::DVec3::from_array(dash(t).pos);
                let err = (glam::DVec3::from_array(got.pos) - truth).length() * 1000.0;
                worst_mm = worst_mm.max(err);
            }
        }
        assert!(lost_plain >= 2, "the plain search lost {lost_plain} frames");
        assert_eq!(lost_retry, 0, "the retry lost {lost_retry} frames");
        assert!(worst_mm < 3.0, "{worst_mm:.1} mm off");
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
