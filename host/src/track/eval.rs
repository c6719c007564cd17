//! The tracker against the truth: doodles from the project's generator are placed in front of
//! a camera, rendered ([`super::render`]), encoded to MP4, decoded and tracked, and every frame
//! is compared with the pose that was drawn — position error (mm), orientation error (°),
//! frames lost — binned by distance and speed; the recognizer reads both logs and the
//! actions are compared.

use std::path::Path;

use glam::{DQuat, DVec3};

use super::body::Body;
use super::detect::{tag_pattern, Detector, DetectorSettings, Family};
use super::pose::{angle_between_deg, camera_tilt, intrinsics_from_fov, project, FLIP_YZ};
use super::render::{Faults, Scene};
use super::rig::{BoxSize, Rig};
use super::tracker::{track_reader, Tracker};
use super::video::{FrameReader, Mp4Writer, Source};
use super::TrackError;
use crate::poselog::{PoseLog, PoseSample};

/// How the test videos are made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setup {
    /// Frame width, pixels.
    pub width: usize,
    /// Frame height, pixels.
    pub height: usize,
    /// Horizontal field of view, degrees.
    pub fov_deg: f64,
    /// Frames per second.
    pub fps: f64,
    /// Edge of the tag's black square, metres.
    pub tag_size: f64,
    /// Distance from the camera to the doodle's first pose, metres.
    pub distance: f64,
    /// The webcam's faults.
    pub faults: Faults,
    /// Seed of the picture's noise, light and occlusion.
    pub seed: u64,
    /// A box rig of four tags (ids from the tag id on: front, left, back, right) instead of
    /// one tag on the chest.
    pub rig_box: Option<BoxSize>,
    /// How far the camera looks down, degrees (0: level; a laptop's webcam looking at a toy
    /// on the desk, 20–40).
    pub camera_tilt_deg: f64,
}

impl Setup {
    /// The camera's frame in the world ([`camera_tilt`]).
    pub fn camera(&self) -> DQuat {
        camera_tilt(self.camera_tilt_deg)
    }
}

impl Default for Setup {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            fov_deg: 60.0,
            fps: 30.0,
            tag_size: 0.04,
            distance: 0.7,
            faults: Faults::default(),
            seed: 0,
            rig_box: None,
            camera_tilt_deg: 0.0,
        }
    }
}

/// A sample's orientation as a unit quaternion.
pub fn quat(s: &PoseSample) -> DQuat {
    DQuat::from_xyzw(s.quat[1], s.quat[2], s.quat[3], s.quat[0]).normalize()
}

/// Moves a doodle in front of the camera (its frame in the world `camera`,
/// [`Setup::camera`]): its first pose `distance` metres along the line of sight, turned about
/// the vertical so that its first front faces the camera (the tag in view).
pub fn place(log: &PoseLog, distance: f64, camera: DQuat) -> PoseLog {
    let Some(first) = log.samples.first() else {
        return log.clone();
    };
    let front = quat(first) * DVec3::Z;
    let yaw = front.x.atan2(front.z);
    let turn = DQuat::from_rotation_y(-yaw);
    let p0 = DVec3::from_array(first.pos);
    let target = camera * DVec3::new(0.0, 0.0, -distance);
    PoseLog {
        samples: log
            .samples
            .iter()
            .map(|s| {
                let p = turn * (DVec3::from_array(s.pos) - p0) + target;
                let q = turn * quat(s);
                PoseSample {
                    t: s.t,
                    pos: p.to_array(),
                    quat: [q.w, q.x, q.y, q.z],
                }
            })
            .collect(),
    }
}

/// The pose at `t`, interpolated between the log's samples (linear, spherical); `None`
/// outside the log.
pub fn pose_at(log: &PoseLog, t: f64) -> Option<PoseSample> {
    let s = &log.samples;
    let i = s.partition_point(|p| p.t <= t);
    if i == 0 || (i == s.len() && s.last()?.t < t) {
        return (s.first()?.t == t).then(|| s[0]);
    }
    if i == s.len() {
        return s.last().copied();
    }
    let (a, b) = (&s[i - 1], &s[i]);
    let f = if b.t > a.t {
        (t - a.t) / (b.t - a.t)
    } else {
        0.0
    };
    let p = DVec3::from_array(a.pos).lerp(DVec3::from_array(b.pos), f);
    let (qa, mut qb) = (quat(a), quat(b));
    if qa.dot(qb) < 0.0 {
        qb = -qb;
    }
    let q = qa.slerp(qb, f);
    Some(PoseSample {
        t,
        pos: p.to_array(),
        quat: [q.w, q.x, q.y, q.z],
    })
}

/// What one rendered frame showed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameTruth {
    /// Frame time on the video's clock (the log's clock minus its first sample's), seconds.
    pub t: f64,
    /// The figurine's true pose (time on the log's clock).
    pub pose: PoseSample,
    /// The figurine's speed, m/s.
    pub speed: f64,
    /// Whether every tag was out of sight: a finger covered part of it, it was turned more
    /// than [`MAX_VIEW_DEG`] from the camera (for one tag on the chest, the back of a turn or
    /// spin), or part of it was outside the picture.
    pub hidden: bool,
}

/// How fast each frame's tags move, m/s: the fastest corner of any of the body's tags, from
/// the frames either side (one-sided at the ends). A turning figurine's tags move faster than
/// its centre ([`FrameTruth::speed`]), and that motion is what smears their picture.
pub fn tag_speeds(body: &Body, truths: &[FrameTruth]) -> Vec<f64> {
    let half = body.tag_size / 2.0;
    let corners = |pose: &PoseSample| -> Vec<DVec3> {
        let (pos, q) = (DVec3::from_array(pose.pos), quat(pose));
        body.panels
            .iter()
            .filter(|p| p.tag.is_some())
            .flat_map(|p| {
                let (centre, pq) = body.panel_pose(p, pos, q);
                [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                    .map(|(u, v)| centre + pq * DVec3::new(u * half, v * half, 0.0))
            })
            .collect()
    };
    let at: Vec<Vec<DVec3>> = truths.iter().map(|f| corners(&f.pose)).collect();
    let last = truths.len().saturating_sub(1);
    (0..truths.len())
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(last));
            let dt = truths[b].t - truths[a].t;
            if dt <= 0.0 {
                return 0.0;
            }
            at[a]
                .iter()
                .zip(&at[b])
                .map(|(p, q)| (*q - *p).length() / dt)
                .fold(0.0, f64::max)
        })
        .collect()
}

/// A tag turned further than this from the camera (degrees between its normal and the line
/// of sight) is out of sight: seen that edge-on, 4 cm is a sliver.
pub const MAX_VIEW_DEG: f64 = 70.0;

/// Angle between the figurine's front and the direction from it to the camera, degrees.
pub fn facing_deg(pose: &PoseSample) -> f64 {
    let front = quat(pose) * DVec3::Z;
    let to_camera = -DVec3::from_array(pose.pos);
    front.angle_between(to_camera).to_degrees()
}

/// How many of the body's tags are in sight at `pose`: facing the camera within
/// [`MAX_VIEW_DEG`], and whole inside the picture (a tag cut by the frame's edge cannot be
/// read, however well it faces the camera).
pub fn tags_in_sight(scene: &Scene, pose: &PoseSample) -> usize {
    let (pos, q) = scene.in_camera(pose);
    let body = &scene.body;
    let half = body.tag_size / 2.0;
    let inside = |p: DVec3| {
        project(&scene.intrinsics, FLIP_YZ * p).is_some_and(|[x, y]| {
            x >= 0.0 && y >= 0.0 && x <= scene.width as f64 && y <= scene.height as f64
        })
    };
    body.panels
        .iter()
        .filter(|p| p.tag.is_some())
        .filter(|p| {
            let (centre, pq) = body.panel_pose(p, pos, q);
            let angle = (pq * DVec3::Z).angle_between(-centre).to_degrees();
            angle <= MAX_VIEW_DEG
                && [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                    .iter()
                    .all(|&(u, v)| inside(centre + pq * DVec3::new(u * half, v * half, 0.0)))
        })
        .count()
}

/// The rig of `setup`: its box, or tag `id` alone on the chest.
pub fn rig(setup: &Setup, family: Family, id: u32) -> Result<Rig, TrackError> {
    match setup.rig_box {
        Some(b) => Rig::checked_box(family, id, setup.tag_size, b),
        None => {
            tag_pattern(family, id)?;
            Ok(Rig::single(id, setup.tag_size))
        }
    }
}

/// The scene of `setup` with tag `id` of `family` on the chest, or its box rig from `id` on.
pub fn scene(setup: &Setup, family: Family, id: u32) -> Result<Scene, TrackError> {
    let body = match setup.rig_box {
        Some(b) => {
            let rig = rig(setup, family, id)?;
            let patterns = rig
                .faces
                .iter()
                .map(|f| tag_pattern(family, f.id))
                .collect::<Result<_, _>>()?;
            Body::rig_box(&rig, patterns, b.width, b.depth)
        }
        None => Body::chest(tag_pattern(family, id)?, setup.tag_size),
    };
    Ok(Scene {
        width: setup.width,
        height: setup.height,
        intrinsics: intrinsics_from_fov(setup.width, setup.height, setup.fov_deg),
        body,
        faults: setup.faults,
        seed: setup.seed,
        camera: setup.camera(),
    })
}

/// Renders a placed log to an MP4 at `setup.fps`, one frame per period from its first to its
/// last sample, and returns what each frame showed.
pub fn render_video(
    setup: &Setup,
    scene: &Scene,
    truth: &PoseLog,
    path: &Path,
) -> Result<Vec<FrameTruth>, TrackError> {
    let (Some(first), Some(last)) = (truth.samples.first(), truth.samples.last()) else {
        return Err(TrackError::BadArgument("the pose log is empty".into()));
    };
    let (t0, t1) = (first.t, last.t);
    let frames = ((t1 - t0) * setup.fps).floor() as u64 + 1;
    let background = scene.background();
    let mut out = Mp4Writer::create(path, setup.width, setup.height, setup.fps)?;
    let mut truths = Vec::with_capacity(frames as usize);
    let at = |t: f64| pose_at(truth, t.clamp(t0, t1));
    for i in 0..frames {
        let tv = i as f64 / setup.fps;
        let t = t0 + tv;
        let Some(pose) = at(t) else { continue };
        let r = scene.render(&background, i, t, at);
        out.push(&r.frame)?;
        let h = 0.005;
        let speed = match (at(t - h), at(t + h)) {
            (Some(a), Some(b)) => {
                (DVec3::from_array(b.pos) - DVec3::from_array(a.pos)).length() / (b.t - a.t)
            }
            _ => 0.0,
        };
        truths.push(FrameTruth {
            t: tv,
            pose,
            speed: if speed.is_finite() { speed } else { 0.0 },
            hidden: tags_in_sight(scene, &pose) <= usize::from(r.occluded),
        });
    }
    out.finish()?;
    Ok(truths)
}

/// The tracker's switches a test run sets (those of `figurine track`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tracking {
    /// Smooth the orientation ([`super::smooth`]; `figurine track --raw` turns it off).
    pub smooth: bool,
    /// Search near the tag's last place first ([`Tracker::with_region_search`]).
    pub region_search: bool,
    /// The exposure the tracker assumes, seconds ([`Tracker::with_exposure`]): its guess, not
    /// necessarily the exposure the video was rendered with.
    pub exposure_s: f64,
    /// How far the tracker is told the camera looks down, degrees
    /// ([`Tracker::with_camera_tilt`]): its guess, not necessarily the video's.
    pub camera_tilt_deg: f64,
}

impl Default for Tracking {
    fn default() -> Self {
        Self {
            smooth: true,
            region_search: true,
            exposure_s: super::tracker::DEFAULT_EXPOSURE_S,
            camera_tilt_deg: 0.0,
        }
    }
}

/// Tracks a video file with the setup's camera (its field of view known exactly).
pub fn track_video(
    setup: &Setup,
    family: Family,
    id: u32,
    path: &Path,
    how: Tracking,
) -> Result<super::tracker::TrackRun, TrackError> {
    let mut reader = FrameReader::open(Source::File(path.to_path_buf()))?;
    let k = intrinsics_from_fov(reader.width(), reader.height(), setup.fov_deg);
    let detector = Detector::new(family, DetectorSettings::default())?;
    let mut tracker = Tracker::with_rig(detector, rig(setup, family, id)?, k)
        .with_smoothing(how.smooth)
        .with_region_search(how.region_search)
        .with_exposure(how.exposure_s)
        .with_camera_tilt(how.camera_tilt_deg);
    track_reader(&mut reader, &mut tracker, |_| Ok(()))
}

/// One frame compared.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameError {
    /// What was drawn.
    pub truth: FrameTruth,
    /// Position error, mm, and orientation error, degrees; `None` for a lost frame.
    pub error: Option<(f64, f64)>,
    /// Error vector tracked − true, metres, in the camera's axes (x across, y up the picture,
    /// z depth).
    pub delta: Option<DVec3>,
    /// The tracked sample.
    pub tracked: Option<PoseSample>,
}

/// Pairs each rendered frame with the sample tracked at its time (both in the world, the
/// camera's frame in it `camera`: [`Setup::camera`]).
pub fn compare(truth: &[FrameTruth], tracked: &PoseLog, camera: DQuat) -> Vec<FrameError> {
    let to_camera = camera.inverse();
    truth
        .iter()
        .map(|f| {
            let found = tracked
                .samples
                .iter()
                .find(|s| (s.t - f.t).abs() < 1e-6)
                .copied();
            let delta = found
                .map(|s| to_camera * (DVec3::from_array(s.pos) - DVec3::from_array(f.pose.pos)));
            let error = found.map(|s| {
                (
                    (DVec3::from_array(s.pos) - DVec3::from_array(f.pose.pos)).length() * 1000.0,
                    angle_between_deg(quat(&s), quat(&f.pose)),
                )
            });
            FrameError {
                truth: *f,
                error,
                delta,
                tracked: found,
            }
        })
        .collect()
}

/// Errors over a set of frames.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Summary {
    /// Frames.
    pub frames: usize,
    /// Frames without a sample.
    pub lost: usize,
    /// Frames without a sample where the tag was in sight.
    pub lost_visible: usize,
    /// Frames where the tag was out of sight ([`FrameTruth::hidden`]).
    pub hidden: usize,
    /// Median position error, mm.
    pub pos_median_mm: f64,
    /// 90th percentile of position error, mm.
    pub pos_p90_mm: f64,
    /// Median orientation error, degrees.
    pub ori_median_deg: f64,
    /// 90th percentile of orientation error, degrees.
    pub ori_p90_deg: f64,
}

impl Summary {
    /// Share of the frames with the tag in sight that were lost.
    pub fn lost_visible_share(&self) -> f64 {
        let clear = self.frames - self.hidden;
        if clear == 0 {
            0.0
        } else {
            self.lost_visible as f64 / clear as f64
        }
    }
}

/// The `q` quantile of `v` (sorted in place); NaN when empty.
pub fn quantile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// Summarises the frames that `keep` selects.
pub fn summarize<'a>(frames: impl IntoIterator<Item = &'a FrameError>) -> Summary {
    let mut s = Summary::default();
    let (mut pos, mut ori) = (Vec::new(), Vec::new());
    for f in frames {
        s.frames += 1;
        s.hidden += usize::from(f.truth.hidden);
        match f.error {
            Some((p, o)) => {
                pos.push(p);
                ori.push(o);
            }
            None => {
                s.lost += 1;
                s.lost_visible += usize::from(!f.truth.hidden);
            }
        }
    }
    s.pos_median_mm = quantile(&mut pos, 0.5);
    s.pos_p90_mm = quantile(&mut pos, 0.9);
    s.ori_median_deg = quantile(&mut ori, 0.5);
    s.ori_p90_deg = quantile(&mut ori, 0.9);
    s
}

/// Jitter of the tracked pose where the figurine is still: σ of the frame-to-frame change
/// of the error over consecutive still frames, /√2 (a slow bias cancels out).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Noise {
    /// Position σ across the view (mean of x and y), mm.
    pub across_mm: f64,
    /// Position σ in depth (z), mm.
    pub depth_mm: f64,
    /// Orientation σ, degrees.
    pub ori_deg: f64,
    /// Still frame pairs measured.
    pub pairs: usize,
}

/// Measures [`Noise`] over pairs of consecutive frames between which the figurine did not
/// move (by under 0.01 mm and 0.01°: the generator's pauses).
pub fn still_noise(frames: &[FrameError]) -> Noise {
    let (mut dx, mut dz, mut da) = (Vec::new(), Vec::new(), Vec::new());
    for w in frames.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let moved = (DVec3::from_array(a.truth.pose.pos) - DVec3::from_array(b.truth.pose.pos))
            .length()
            > 1e-5
            || angle_between_deg(quat(&a.truth.pose), quat(&b.truth.pose)) > 0.01;
        if moved || (b.truth.t - a.truth.t) > 0.05 {
            continue;
        }
        if let (Some(ea), Some(eb)) = (a.delta, b.delta) {
            let d = eb - ea;
            dx.push(d.x);
            dx.push(d.y);
            dz.push(d.z);
        }
        if let (Some(sa), Some(sb)) = (a.tracked, b.tracked) {
            // The truth does not turn between still frames: all the turn is jitter.
            da.push(angle_between_deg(quat(&sa), quat(&sb)));
        }
    }
    let rms = |v: &[f64]| {
        if v.is_empty() {
            f64::NAN
        } else {
            (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
        }
    };
    Noise {
        across_mm: rms(&dx) / 2f64.sqrt() * 1000.0,
        depth_mm: rms(&dz) / 2f64.sqrt() * 1000.0,
        ori_deg: rms(&da) / 2f64.sqrt(),
        pairs: dz.len(),
    }
}

/// The truth at the camera's frame times, as a pose log on the video's clock (what a perfect
/// tracker would have written), for reading the actions from.
pub fn truth_log(frames: &[FrameTruth]) -> PoseLog {
    PoseLog {
        samples: frames
            .iter()
            .map(|f| PoseSample { t: f.t, ..f.pose })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log(n: usize) -> PoseLog {
        PoseLog {
            samples: (0..n)
                .map(|i| {
                    let q = DQuat::from_rotation_y(0.1 * i as f64);
                    PoseSample {
                        t: i as f64 * 0.1,
                        pos: [1.0 + i as f64, 2.0, 3.0],
                        quat: [q.w, q.x, q.y, q.z],
                    }
                })
                .collect(),
        }
    }

    #[test]
    fn interpolation_is_exact_at_samples_and_between() {
        let l = log(5);
        let p = pose_at(&l, 0.2).unwrap();
        assert!((p.pos[0] - 3.0).abs() < 1e-9);
        let m = pose_at(&l, 0.25).unwrap();
        assert!((m.pos[0] - 3.5).abs() < 1e-9);
        let expect = DQuat::from_rotation_y(0.25);
        assert!(angle_between_deg(quat(&m), expect) < 1e-6);
        assert!(pose_at(&l, -1.0).is_none() && pose_at(&l, 9.0).is_none());
    }

    #[test]
    fn placing_puts_the_first_pose_ahead_facing_the_camera() {
        let placed = place(&log(4), 0.8, DQuat::IDENTITY);
        let first = &placed.samples[0];
        assert!((DVec3::from_array(first.pos) - DVec3::new(0.0, 0.0, -0.8)).length() < 1e-9);
        assert!((quat(first) * DVec3::Z - DVec3::Z).length() < 1e-9);
        // The path keeps its shape: consecutive steps are still 1 m long.
        let step = DVec3::from_array(placed.samples[1].pos) - DVec3::from_array(first.pos);
        assert!((step.length() - 1.0).abs() < 1e-9);
        // A camera looking down 30°: 0.8 m along its line of sight, 0.4 m below it, upright
        // in the world and facing the camera across the floor.
        let setup = Setup {
            camera_tilt_deg: 30.0,
            ..Setup::default()
        };
        let placed = place(&log(4), 0.8, setup.camera());
        let first = &placed.samples[0];
        let p = DVec3::from_array(first.pos);
        assert!(
            (p.y + 0.4).abs() < 1e-9 && p.z < -0.69 && p.x.abs() < 1e-9,
            "{p}"
        );
        assert!((quat(first) * DVec3::Z - DVec3::Z).length() < 1e-9);
        // In sight, the tag seen from 30° above.
        let sc = scene(&setup, Family::Tag36h11, 0).unwrap();
        assert_eq!(tags_in_sight(&sc, first), 1);
        let (in_cam, q) = sc.in_camera(first);
        assert!((in_cam - DVec3::new(0.0, 0.0, -0.8)).length() < 1e-9);
        assert!(((q * DVec3::Z).angle_between(DVec3::Z).to_degrees() - 30.0).abs() < 1e-9);
    }

    #[test]
    fn a_tag_is_in_sight_facing_the_camera_and_whole_inside_the_picture() {
        let sc = scene(&Setup::default(), Family::Tag36h11, 0).unwrap();
        let at = |x: f64, yaw_deg: f64| {
            let q = DQuat::from_rotation_y(yaw_deg.to_radians());
            PoseSample {
                t: 0.0,
                pos: [x, 0.0, -0.7],
                quat: [q.w, q.x, q.y, q.z],
            }
        };
        assert_eq!(tags_in_sight(&sc, &at(0.0, 0.0)), 1);
        assert_eq!(tags_in_sight(&sc, &at(0.0, 60.0)), 1);
        assert_eq!(tags_in_sight(&sc, &at(0.0, 80.0)), 0, "turned away");
        // The frame's edge is 0.404 m off-centre at 0.7 m: the tag's half (2 cm) crosses it.
        assert_eq!(tags_in_sight(&sc, &at(0.37, 0.0)), 1);
        assert_eq!(tags_in_sight(&sc, &at(0.395, 0.0)), 0, "cut by the edge");
    }

    #[test]
    fn a_turning_figurine_s_tags_outrun_its_centre() {
        let sc = scene(&Setup::default(), Family::Tag36h11, 0).unwrap();
        let frame = |i: u32, x: f64, yaw: f64| {
            let q = DQuat::from_rotation_y(yaw);
            let t = f64::from(i) / 30.0;
            FrameTruth {
                t,
                pose: PoseSample {
                    t: 10.0 + t,
                    pos: [x, 0.0, -0.7],
                    quat: [q.w, q.x, q.y, q.z],
                },
                speed: 0.0,
                hidden: false,
            }
        };
        // Gliding at 0.3 m/s: every corner moves as the centre does.
        let glide: Vec<_> = (0..5)
            .map(|i| frame(i, 0.3 * f64::from(i) / 30.0, 0.0))
            .collect();
        for v in tag_speeds(&sc.body, &glide) {
            assert!((v - 0.3).abs() < 1e-9, "{v}");
        }
        // Spinning in place at 10 rad/s: the corner farthest from the axis, over the chord
        // between the frames either side (one-sided, a single step, at the ends).
        let spin: Vec<_> = (0..5)
            .map(|i| frame(i, 0.0, 10.0 * f64::from(i) / 30.0))
            .collect();
        let panel = sc.body.panels.iter().find(|p| p.tag.is_some()).unwrap();
        let half = sc.body.tag_size / 2.0;
        let reach = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(u, v)| {
                let c = panel.centre + panel.rotation * DVec3::new(u * half, v * half, 0.0);
                c.x.hypot(c.z)
            })
            .fold(0.0, f64::max);
        let chord = |turn: f64, dt: f64| 2.0 * reach * (turn / 2.0).sin() / dt;
        let speeds = tag_speeds(&sc.body, &spin);
        assert!(
            (speeds[2] - chord(20.0 / 30.0, 2.0 / 30.0)).abs() < 1e-9,
            "{speeds:?}"
        );
        assert!(
            (speeds[0] - chord(10.0 / 30.0, 1.0 / 30.0)).abs() < 1e-9,
            "{speeds:?}"
        );
        assert!(speeds[2] > 9.0 * reach, "{speeds:?}");
        assert_eq!(tag_speeds(&sc.body, &[]), Vec::<f64>::new());
    }

    #[test]
    fn summaries_count_lost_frames_and_take_medians() {
        let t = FrameTruth {
            t: 0.0,
            pose: log(1).samples[0],
            speed: 0.0,
            hidden: false,
        };
        let frames = [
            FrameError {
                truth: t,
                error: Some((1.0, 0.5)),
                delta: None,
                tracked: None,
            },
            FrameError {
                truth: t,
                error: Some((3.0, 1.5)),
                delta: None,
                tracked: None,
            },
            FrameError {
                truth: t,
                error: None,
                delta: None,
                tracked: None,
            },
            FrameError {
                truth: FrameTruth { hidden: true, ..t },
                error: None,
                delta: None,
                tracked: None,
            },
        ];
        let s = summarize(&frames);
        assert_eq!((s.frames, s.lost, s.lost_visible, s.hidden), (4, 2, 1, 1));
        assert!((s.lost_visible_share() - 1.0 / 3.0).abs() < 1e-12);
        assert!(s.pos_median_mm == 1.0 || s.pos_median_mm == 3.0);
    }
}
