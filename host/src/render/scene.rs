//! The renderer's input: a GPU-agnostic description of what to draw over time.
//!
//! Animation produces poses; rendering only consumes them. Whatever makes the motion (a BVH
//! clip, the animation assembler, a live puppetry feed) turns it into a [`Scene`]: per frame a
//! list of [`BoneSegment`]s in world space (metres, +Y up), plus the doodle path as a timed
//! 3-D polyline and a timeline of recognised actions with their Laban efforts. Nothing here
//! knows about skeleton hierarchies, rotations or the GPU.

use glam::Vec3;

use crate::events::ActionRecord;

/// Which side of the body a bone belongs to; drives its colour so left and right read apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Side {
    /// Spine, neck, head, pelvis: anything on the mid-line.
    #[default]
    Centre,
    /// The character's left limbs.
    Left,
    /// The character's right limbs.
    Right,
}

/// One limb to draw: a capsule from `start` to `end`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoneSegment {
    /// Proximal end, world metres (+Y up).
    pub start: Vec3,
    /// Distal end, world metres (+Y up).
    pub end: Vec3,
    /// Capsule radius in metres; `None` lets the renderer choose one from the figure's size.
    pub radius: Option<f32>,
    /// Body side, for colour.
    pub side: Side,
    /// Which character this bone belongs to (0 for single-character scenes); picks a palette.
    pub character: u16,
}

impl BoneSegment {
    /// A centre-line bone of character 0 with the default radius.
    pub fn new(start: Vec3, end: Vec3) -> Self {
        BoneSegment {
            start,
            end,
            radius: None,
            side: Side::Centre,
            character: 0,
        }
    }

    /// True when both ends (and the radius, if any) are finite numbers.
    pub fn is_finite(&self) -> bool {
        self.start.is_finite() && self.end.is_finite() && self.radius.is_none_or(f32::is_finite)
    }
}

/// The pose of every character at one instant.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FramePose {
    /// Bones to draw.
    pub segments: Vec<BoneSegment>,
    /// Horizontal direction the (first) character faces, if known (unit-ish, world); the
    /// camera uses it to look at the front of the figure.
    pub facing: Option<Vec3>,
}

/// One recognised action on the timeline.
#[derive(Debug, Clone, PartialEq)]
pub struct TimelineSpan {
    /// Action name, e.g. `"jump"`.
    pub action: String,
    /// Start, seconds on the scene clock.
    pub start: f32,
    /// End, seconds on the scene clock.
    pub end: f32,
    /// Laban Time effort Lt in [-1, 1]: > 0 sudden, < 0 sustained.
    pub time: f32,
    /// Laban Weight effort Lw in [-1, 1]: > 0 strong, < 0 light.
    pub weight: f32,
}

impl From<&ActionRecord> for TimelineSpan {
    fn from(r: &ActionRecord) -> Self {
        TimelineSpan {
            action: r.action.clone(),
            start: r.start as f32,
            end: r.end as f32,
            time: r.time as f32,
            weight: r.weight as f32,
        }
    }
}

/// One sample of the doodle path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoodlePoint {
    /// Seconds on the scene clock.
    pub t: f32,
    /// Position, world metres (+Y up).
    pub pos: Vec3,
}

/// Everything the renderer draws for one animation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    /// A short title (e.g. the clip's file name), drawn in the corner.
    pub title: String,
    /// Frames per second of `frames`.
    pub fps: f32,
    /// The poses, frame `i` at time `i / fps` seconds.
    pub frames: Vec<FramePose>,
    /// The doodle path in time order (may be empty).
    pub doodle: Vec<DoodlePoint>,
    /// Recognised actions (may be empty).
    pub timeline: Vec<TimelineSpan>,
}

/// Why a [`Scene`] cannot be rendered.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// No frames at all.
    #[error("the scene has no frames")]
    Empty,
    /// The frame rate is not a positive finite number.
    #[error("invalid frame rate {0} (frames per second must be positive)")]
    BadFps(f32),
    /// No frame has a single finite bone.
    #[error("no frame has a bone with finite coordinates")]
    NoFiniteBones,
}

impl Scene {
    /// Checks that the scene can be drawn (non-empty, positive fps, some finite geometry).
    /// Individual non-finite bones are tolerated: they are skipped when drawing.
    pub fn validate(&self) -> Result<(), SceneError> {
        if self.frames.is_empty() {
            return Err(SceneError::Empty);
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(SceneError::BadFps(self.fps));
        }
        let any = self
            .frames
            .iter()
            .any(|f| f.segments.iter().any(BoneSegment::is_finite));
        if !any {
            return Err(SceneError::NoFiniteBones);
        }
        Ok(())
    }

    /// Length in seconds: the time of the last frame (0 for a single frame), at least the end
    /// of the last timeline span and doodle sample.
    pub fn duration(&self) -> f32 {
        let frames = if self.fps > 0.0 && !self.frames.is_empty() {
            (self.frames.len() - 1) as f32 / self.fps
        } else {
            0.0
        };
        let spans = self.timeline.iter().map(|s| s.end).fold(0.0f32, f32::max);
        let doodle = self.doodle.last().map_or(0.0, |p| p.t);
        frames.max(spans).max(doodle).max(0.0)
    }

    /// Length in seconds of the pose frames alone.
    pub fn pose_duration(&self) -> f32 {
        if self.fps > 0.0 && self.frames.len() > 1 {
            (self.frames.len() - 1) as f32 / self.fps
        } else {
            0.0
        }
    }

    /// The pose at time `t` seconds: linear blend of the two nearest frames when they have the
    /// same bones, else the nearest frame. Times outside the clip clamp to its ends.
    pub fn pose_at(&self, t: f32) -> FramePose {
        let Some(last) = self.frames.len().checked_sub(1) else {
            return FramePose::default();
        };
        let f = if self.fps > 0.0 && t.is_finite() {
            (t * self.fps).clamp(0.0, last as f32)
        } else {
            0.0
        };
        let i = (f.floor() as usize).min(last);
        let j = (i + 1).min(last);
        let w = f - i as f32;
        let (a, b) = (&self.frames[i], &self.frames[j]);
        if i == j || a.segments.len() != b.segments.len() {
            return if w < 0.5 { a.clone() } else { b.clone() };
        }
        let segments = a
            .segments
            .iter()
            .zip(&b.segments)
            .map(|(sa, sb)| BoneSegment {
                start: sa.start.lerp(sb.start, w),
                end: sa.end.lerp(sb.end, w),
                radius: match (sa.radius, sb.radius) {
                    (Some(ra), Some(rb)) => Some(ra + (rb - ra) * w),
                    (r, _) => r,
                },
                side: sa.side,
                character: sa.character,
            })
            .collect();
        let facing = match (a.facing, b.facing) {
            (Some(fa), Some(fb)) => Some(fa.lerp(fb, w)),
            (f, g) => f.or(g),
        };
        FramePose { segments, facing }
    }

    /// The timeline span active at time `t` (the latest-starting one if they overlap).
    pub fn span_at(&self, t: f32) -> Option<&TimelineSpan> {
        self.timeline
            .iter()
            .filter(|s| s.start <= t && t <= s.end)
            .max_by(|a, b| a.start.total_cmp(&b.start))
    }
}

/// Axis-aligned bounds of the finite bone endpoints of one pose.
pub fn pose_bounds(pose: &FramePose) -> Option<(Vec3, Vec3)> {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    let mut any = false;
    for s in pose.segments.iter().filter(|s| s.is_finite()) {
        lo = lo.min(s.start).min(s.end);
        hi = hi.max(s.start).max(s.end);
        any = true;
    }
    any.then_some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_frame_scene() -> Scene {
        let f0 = FramePose {
            segments: vec![BoneSegment::new(Vec3::ZERO, Vec3::Y)],
            facing: Some(Vec3::Z),
        };
        let f1 = FramePose {
            segments: vec![BoneSegment::new(Vec3::X, Vec3::X + Vec3::Y)],
            facing: Some(Vec3::X),
        };
        Scene {
            fps: 10.0,
            frames: vec![f0, f1],
            ..Scene::default()
        }
    }

    #[test]
    fn pose_at_interpolates_and_clamps() {
        let s = two_frame_scene();
        let mid = s.pose_at(0.05);
        assert!((mid.segments[0].start.x - 0.5).abs() < 1e-5);
        assert_eq!(s.pose_at(-3.0).segments[0].start, Vec3::ZERO);
        assert_eq!(s.pose_at(99.0).segments[0].start, Vec3::X);
        assert_eq!(s.pose_at(f32::NAN).segments[0].start, Vec3::ZERO);
    }

    #[test]
    fn mismatched_frames_pick_nearest() {
        let mut s = two_frame_scene();
        s.frames[1]
            .segments
            .push(BoneSegment::new(Vec3::Y, Vec3::Z));
        assert_eq!(s.pose_at(0.04).segments.len(), 1);
        assert_eq!(s.pose_at(0.06).segments.len(), 2);
    }

    #[test]
    fn validate_rejects_bad_scenes() {
        assert_eq!(Scene::default().validate(), Err(SceneError::Empty));
        let mut s = two_frame_scene();
        s.fps = 0.0;
        assert_eq!(s.validate(), Err(SceneError::BadFps(0.0)));
        let mut s = two_frame_scene();
        for f in &mut s.frames {
            f.segments[0].start = Vec3::NAN;
        }
        assert_eq!(s.validate(), Err(SceneError::NoFiniteBones));
        assert!(two_frame_scene().validate().is_ok());
    }

    #[test]
    fn duration_covers_timeline_and_doodle() {
        let mut s = two_frame_scene();
        assert!((s.duration() - 0.1).abs() < 1e-6);
        s.timeline.push(TimelineSpan {
            action: "hop".into(),
            start: 0.0,
            end: 2.0,
            time: 0.5,
            weight: -0.5,
        });
        assert_eq!(s.duration(), 2.0);
        assert_eq!(s.span_at(1.0).map(|x| x.action.as_str()), Some("hop"));
        assert!(s.span_at(2.5).is_none());
    }

    #[test]
    fn bounds_skip_non_finite() {
        let pose = FramePose {
            segments: vec![
                BoneSegment::new(Vec3::ZERO, Vec3::ONE),
                BoneSegment::new(Vec3::NAN, Vec3::splat(100.0)),
            ],
            facing: None,
        };
        assert_eq!(pose_bounds(&pose), Some((Vec3::ZERO, Vec3::ONE)));
        assert_eq!(pose_bounds(&FramePose::default()), None);
    }
}
