//! Glue from motion data to the renderer's [`Scene`]: a [`Clip`] (e.g. an imported BVH)
//! becomes per-frame bone segments in metres, +Y up; a pose log becomes the doodle path; an
//! event file becomes the timeline.
//!
//! Motion files do not say their units or up axis, so both are inferred from the skeleton:
//! - **up axis**: from the feet to the head (joint names), +Y or +Z (Z-up files are rotated);
//! - **unit**: the rest pose's largest extent is compared with a 1.7 m person, choosing
//!   metres, centimetres, inches or millimetres (whichever is closest in ratio).
//!
//! The camera never relies on either guess (it frames the scene's own extent); they only make
//! the scene honest about being in metres. Body sides come from joint names (`Left…`,
//! `…_l`, `.L`, `L…` with a capital next letter, …).

use std::path::Path;

use glam::Vec3;

use super::scene::{pose_bounds, BoneSegment, DoodlePoint, FramePose, Scene, Side, TimelineSpan};
use crate::events::ActionRecord;
use crate::motion::{Clip, Skeleton};
use crate::poselog::PoseLog;

/// Height of the reference person the unit guess compares against, metres.
const REFERENCE_HEIGHT_M: f32 = 1.7;
/// Candidate units: metres per file unit.
const UNITS: [(f32, &str); 4] = [(1.0, "m"), (0.01, "cm"), (0.0254, "in"), (0.001, "mm")];

/// The body side a joint name denotes, or [`Side::Centre`].
pub fn side_of(name: &str) -> Side {
    let lower = name.to_ascii_lowercase();
    if lower.contains("left") {
        return Side::Left;
    }
    if lower.contains("right") {
        return Side::Right;
    }
    // Split into words at separators and lower→upper case changes: "LHipJoint" → L, Hip,
    // Joint; "shoulder.L" → shoulder, L; "Bip01 R Thigh" → Bip01, R, Thigh.
    let mut words: Vec<String> = Vec::new();
    let mut cur = String::new();
    let mut prev_lower = false;
    for ch in name.chars() {
        if !ch.is_ascii_alphanumeric() {
            if !cur.is_empty() {
                words.push(std::mem::take(&mut cur));
            }
            prev_lower = false;
            continue;
        }
        let starts_word = ch.is_ascii_uppercase() && (prev_lower || cur == "L" || cur == "R");
        if starts_word && !cur.is_empty() {
            words.push(std::mem::take(&mut cur));
        }
        cur.push(ch);
        prev_lower = ch.is_ascii_lowercase() || ch.is_ascii_digit();
    }
    if !cur.is_empty() {
        words.push(cur);
    }
    // A leading lower-case "l"/"r" glued to a capitalised word ("lShldr", "rKnee").
    let glued = |c: char| {
        let mut it = name.chars();
        it.next() == Some(c) && it.next().is_some_and(|n| n.is_ascii_uppercase())
    };
    let has = |w: &str| words.iter().any(|x| x.eq_ignore_ascii_case(w));
    if has("l") || glued('l') {
        Side::Left
    } else if has("r") || glued('r') {
        Side::Right
    } else {
        Side::Centre
    }
}

/// How a clip's coordinates map to the scene's metres, +Y up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Units {
    /// Metres per file unit.
    pub metres_per_unit: f32,
    /// Short unit name (`m`, `cm`, `in`, `mm`).
    pub name: &'static str,
    /// True when the file is Z-up and gets rotated to Y-up.
    pub z_up: bool,
}

impl Units {
    /// Maps a file-space point to scene metres, +Y up.
    pub fn apply(&self, p: Vec3) -> Vec3 {
        let p = p * self.metres_per_unit;
        if self.z_up {
            Vec3::new(p.x, p.z, -p.y)
        } else {
            p
        }
    }
}

fn joints_named<'a>(skeleton: &'a Skeleton, words: &'a [&str]) -> impl Iterator<Item = usize> + 'a {
    skeleton
        .joints
        .iter()
        .enumerate()
        .filter_map(move |(i, j)| {
            let n = j.name.to_ascii_lowercase();
            words.iter().any(|w| n.contains(w)).then_some(i)
        })
}

/// Infers unit and up axis from the skeleton's rest pose.
pub fn infer_units(skeleton: &Skeleton) -> Units {
    let rest = skeleton.rest_positions();
    let (lo, hi) = rest.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let extent = (hi - lo).max_element();
    let (metres_per_unit, name) = if extent.is_finite() && extent > 0.0 {
        UNITS
            .iter()
            .copied()
            .min_by(|a, b| {
                let da = (extent * a.0 / REFERENCE_HEIGHT_M).ln().abs();
                let db = (extent * b.0 / REFERENCE_HEIGHT_M).ln().abs();
                da.total_cmp(&db)
            })
            .unwrap_or((1.0, "m"))
    } else {
        (1.0, "m")
    };
    let mean = |ids: Vec<usize>| -> Option<Vec3> {
        let pts: Vec<Vec3> = ids.iter().filter_map(|&i| rest.get(i).copied()).collect();
        (!pts.is_empty()).then(|| pts.iter().sum::<Vec3>() / pts.len() as f32)
    };
    let head = mean(joints_named(skeleton, &["head"]).collect());
    let feet = mean(joints_named(skeleton, &["foot", "ankle", "toe"]).collect());
    let z_up = match (head, feet) {
        (Some(h), Some(f)) => {
            let up = h - f;
            up.z > up.y.abs() && up.z > up.x.abs()
        }
        _ => false,
    };
    Units {
        metres_per_unit,
        name,
        z_up,
    }
}

/// How each joint is drawn, decided once per skeleton.
struct BonePlan {
    /// (parent, child, side, radius) per drawn segment; radius `None` = proportional default.
    segments: Vec<(usize, usize, Side, f32)>,
    /// Head joints without a real child: (head, parent, lift in head radii) drawn as a ball.
    head_balls: Vec<(usize, usize, f32)>,
    head_radius: f32,
    left: Vec<usize>,
    right: Vec<usize>,
}

fn plan_bones(skeleton: &Skeleton, rest_m: &[Vec3], height_m: f32) -> BonePlan {
    let base = 0.028 * height_m;
    let head_radius = 0.06 * height_m;
    // The head joint: named "head" (not a head-top end site); rigs without one (e.g. Blender's
    // basic rig) name the skull "face" or "skull".
    let named = |i: usize, words: &[&str]| {
        skeleton.joints.get(i).is_some_and(|j| {
            let n = j.name.to_ascii_lowercase();
            words.iter().any(|w| n.contains(w)) && !n.contains("end") && !n.contains("top")
        })
    };
    let has_head = (0..skeleton.len()).any(|i| named(i, &["head"]));
    let head_words: &[&str] = if has_head {
        &["head"]
    } else {
        &["face", "skull"]
    };
    let is_head = |i: usize| named(i, head_words);
    let min_head_child = 0.03 * height_m;
    let mut segments = Vec::new();
    let mut head_balls = Vec::new();
    for (j, joint) in skeleton.joints.iter().enumerate() {
        let Some(p) = joint.parent else { continue };
        let len = match (rest_m.get(p), rest_m.get(j)) {
            (Some(a), Some(b)) => (*b - *a).length(),
            _ => continue,
        };
        if len < 1e-4 * height_m {
            continue;
        }
        if is_head(p) {
            // Only the longest child of the head carries the head; eyes etc. hide inside it.
            let child_len = |c: usize| rest_m.get(c).map_or(0.0, |x| (*x - rest_m[p]).length());
            let longest = skeleton
                .children(p)
                .into_iter()
                .max_by(|&a, &b| child_len(a).total_cmp(&child_len(b)));
            if longest == Some(j) && len >= min_head_child {
                segments.push((p, j, Side::Centre, head_radius));
            }
            continue;
        }
        let side = side_of(&joint.name);
        let r = base.min(0.35 * len).max(0.15 * base);
        segments.push((p, j, side, r));
    }
    for (h, joint) in skeleton.joints.iter().enumerate() {
        let longest_child = skeleton
            .children(h)
            .into_iter()
            .filter_map(|c| Some((*rest_m.get(c)? - *rest_m.get(h)?).length()))
            .fold(0.0f32, f32::max);
        if is_head(h) && longest_child < min_head_child {
            if let Some(p) = joint.parent {
                // A "head" joint sits at the skull base: the ball goes above it. A "face"
                // joint is already inside the skull.
                let lift = if has_head { 0.8 } else { 0.2 };
                head_balls.push((h, p, lift));
            }
        }
    }
    let side_joints = |want: Side| -> Vec<usize> {
        let ids: Vec<usize> = (0..skeleton.len())
            .filter(|&i| side_of(&skeleton.joints[i].name) == want)
            .collect();
        let min_depth = ids.iter().map(|&i| skeleton.depth(i)).min();
        ids.into_iter()
            .filter(|&i| Some(skeleton.depth(i)) == min_depth)
            .collect()
    };
    BonePlan {
        segments,
        head_balls,
        head_radius,
        left: side_joints(Side::Left),
        right: side_joints(Side::Right),
    }
}

/// Facing from the left→right joint pairs: up × (right − left), horizontal.
fn facing(points: &[Vec3], left: &[usize], right: &[usize]) -> Option<Vec3> {
    let mean = |ids: &[usize]| -> Option<Vec3> {
        let pts: Vec<Vec3> = ids.iter().filter_map(|&i| points.get(i).copied()).collect();
        (!pts.is_empty()).then(|| pts.iter().sum::<Vec3>() / pts.len() as f32)
    };
    let across = mean(right)? - mean(left)?;
    let f = Vec3::Y.cross(across);
    let f = Vec3::new(f.x, 0.0, f.z);
    (f.length() > 1e-6 && f.is_finite()).then(|| f.normalize())
}

/// Typical figure height (metres) for limb thickness: the median bounding-box diagonal of up
/// to 64 frames spread over the clip (a standing person's diagonal is about 1.05 × height),
/// else the rest pose's largest extent, else 1.7 m.
fn figure_height(frames: &[Vec<Vec3>], rest: &[Vec3]) -> f32 {
    let extent = |pts: &[Vec3]| -> Option<Vec3> {
        let (lo, hi) = pts.iter().filter(|p| p.is_finite()).fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let e = hi - lo;
        (e.is_finite() && e.max_element() > 0.0).then_some(e)
    };
    let step = (frames.len() / 64).max(1);
    let mut diags: Vec<f32> = frames
        .iter()
        .step_by(step)
        .filter_map(|f| extent(f).map(|e| e.length() / 1.05))
        .collect();
    diags.sort_by(f32::total_cmp);
    diags
        .get(diags.len() / 2)
        .copied()
        .or_else(|| extent(rest).map(|e| e.max_element()))
        .unwrap_or(REFERENCE_HEIGHT_M)
}

/// Converts a clip to a scene (metres, +Y up), inferring units and up axis.
pub fn scene_from_clip(clip: &Clip) -> Scene {
    let units = infer_units(&clip.skeleton);
    let rest_m: Vec<Vec3> = clip
        .skeleton
        .rest_positions()
        .into_iter()
        .map(|p| units.apply(p))
        .collect();
    let all_pts: Vec<Vec<Vec3>> = clip
        .frames
        .iter()
        .map(|pose| {
            clip.skeleton
                .positions(pose)
                .into_iter()
                .map(|p| units.apply(p))
                .collect()
        })
        .collect();
    let height_m = figure_height(&all_pts, &rest_m);
    let plan = plan_bones(&clip.skeleton, &rest_m, height_m);
    let frames = all_pts
        .iter()
        .map(|pts| {
            let mut segments: Vec<BoneSegment> = plan
                .segments
                .iter()
                .filter_map(|&(p, c, side, r)| {
                    let (a, b) = (*pts.get(p)?, *pts.get(c)?);
                    if r == plan.head_radius && side == Side::Centre {
                        // The head: a ball filling the skull segment, not a long capsule.
                        let m = (a + b) * 0.5;
                        let r = ((b - a).length() * 0.55).clamp(r * 0.8, r * 1.4);
                        return Some(BoneSegment {
                            start: m,
                            end: m,
                            radius: Some(r),
                            side,
                            character: 0,
                        });
                    }
                    Some(BoneSegment {
                        start: a,
                        end: b,
                        radius: Some(r),
                        side,
                        character: 0,
                    })
                })
                .collect();
            for &(h, p, lift) in &plan.head_balls {
                if let (Some(hp), Some(pp)) = (pts.get(h), pts.get(p)) {
                    let c = *hp + (*hp - *pp).normalize_or(Vec3::Y) * plan.head_radius * lift;
                    segments.push(BoneSegment {
                        start: c,
                        end: c,
                        radius: Some(plan.head_radius),
                        side: Side::Centre,
                        character: 0,
                    });
                }
            }
            FramePose {
                segments,
                facing: facing(pts, &plan.left, &plan.right),
            }
        })
        .collect();
    let fps = if clip.frame_time.is_finite() && clip.frame_time > 0.0 {
        1.0 / clip.frame_time
    } else {
        30.0
    };
    Scene {
        title: format!("{} ({})", clip.name, units.name),
        fps,
        frames,
        doodle: Vec::new(),
        timeline: Vec::new(),
    }
}

/// The doodle path of a pose log (world metres, +Y up), times shifted by `-t0` seconds.
pub fn doodle_from_log(log: &PoseLog, t0: f64) -> Vec<DoodlePoint> {
    log.samples
        .iter()
        .map(|s| DoodlePoint {
            t: (s.t - t0) as f32,
            pos: Vec3::new(s.pos[0] as f32, s.pos[1] as f32, s.pos[2] as f32),
        })
        .filter(|p| p.t.is_finite() && p.pos.is_finite())
        .collect()
}

/// Default doodle scale: toy metres → character metres, the same default as
/// `figurine animate --world-scale` (a 15 cm figurine stands for a 1.7 m character).
pub const DEFAULT_DOODLE_SCALE: f32 = crate::anim::trajectory::DEFAULT_WORLD_SCALE;

/// Half-width of the window whose lowest toy height is the doodle's local "floor", seconds.
const DOODLE_FLOOR_HALF_S: f32 = 1.5;
/// Heights are drawn at this fraction of the horizontal scale: at 10× a hand gesture of
/// 50 cm would tower 5 m over a 1.7 m character; at 0.3 of it, hops still read as arcs.
pub const DOODLE_HEIGHT_FACTOR: f32 = 0.3;

/// Lowest `y` within ±`half` seconds of each sample (sliding-window minimum, O(n)).
fn local_floor(doodle: &[DoodlePoint], half: f32) -> Vec<f32> {
    let mut out = Vec::with_capacity(doodle.len());
    let mut window: std::collections::VecDeque<usize> = std::collections::VecDeque::new();
    let mut next = 0;
    for p in doodle {
        while next < doodle.len() && doodle[next].t <= p.t + half {
            while window
                .back()
                .is_some_and(|&k| doodle[k].pos.y >= doodle[next].pos.y)
            {
                window.pop_back();
            }
            window.push_back(next);
            next += 1;
        }
        while window.front().is_some_and(|&k| doodle[k].t < p.t - half) {
            window.pop_front();
        }
        out.push(window.front().map_or(p.pos.y, |&k| doodle[k].pos.y));
    }
    out
}

/// Places a toy-scale doodle in the animation's world the way the animation follows it: its
/// first sample over the character's start (`anchor_xz`), horizontal offsets multiplied by
/// `scale` (as `figurine animate` maps the ground path). Heights are taken above the toy's
/// local floor (the lowest height within ±1.5 s), times `scale` × [`DOODLE_HEIGHT_FACTOR`],
/// from the `ground`: hops show as arcs, while the hand slowly raising or lowering the toy
/// between actions (which the animation ignores) does not lift the path into the sky.
pub fn place_doodle(doodle: &mut [DoodlePoint], scale: f32, anchor_xz: (f32, f32), ground: f32) {
    let Some(first) = doodle.first().map(|p| p.pos) else {
        return;
    };
    let floor = local_floor(doodle, DOODLE_FLOOR_HALF_S);
    for (p, low) in doodle.iter_mut().zip(floor) {
        p.pos = Vec3::new(
            anchor_xz.0 + (p.pos.x - first.x) * scale,
            ground + (p.pos.y - low) * scale * DOODLE_HEIGHT_FACTOR,
            anchor_xz.1 + (p.pos.z - first.z) * scale,
        );
    }
}

/// Reads recognised actions: JSON lines of `figurine simulate`, or (a file starting with `[`)
/// the ground-truth labels of `figurine synth`, whose effort classes become ±0.8.
pub fn read_actions(path: &Path) -> anyhow::Result<Vec<ActionRecord>> {
    let text =
        std::fs::read_to_string(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    if text.trim_start().starts_with('[') {
        crate::anim::cli::read_label_events(path)
    } else {
        Ok(crate::events::read_events(text.as_bytes(), path)?)
    }
}

/// Timeline spans of recognised actions, times shifted by `-t0` seconds.
pub fn timeline_from_events(events: &[ActionRecord], t0: f64) -> Vec<TimelineSpan> {
    events
        .iter()
        .map(|e| {
            let mut s = TimelineSpan::from(e);
            s.start = (e.start - t0) as f32;
            s.end = (e.end - t0) as f32;
            s
        })
        .collect()
}

/// Loads a BVH animation with an optional doodle log and event file into a scene. When a
/// doodle is given, its first sample defines time 0 for the doodle and the events (they share
/// the log's clock, and `figurine animate` starts its output there); otherwise event times
/// are used as they are. The doodle is placed with [`place_doodle`] at `doodle_scale`.
pub fn load_scene(
    bvh: &Path,
    doodle: Option<&Path>,
    events: Option<&Path>,
    doodle_scale: f32,
) -> anyhow::Result<Scene> {
    let import = crate::motion::read_bvh_path(bvh)?;
    for note in &import.notes {
        eprintln!("{}: note: {note}", bvh.display());
    }
    let mut scene = scene_from_clip(&import.clip);
    let mut t0 = 0.0;
    if let Some(path) = doodle {
        let log = PoseLog::read_path(path)?;
        t0 = log.samples.first().map_or(0.0, |s| s.t);
        scene.doodle = doodle_from_log(&log, t0);
        let anchor = scene
            .frames
            .first()
            .and_then(pose_bounds)
            .map_or((0.0, 0.0), |(lo, hi)| {
                ((lo.x + hi.x) * 0.5, (lo.z + hi.z) * 0.5)
            });
        let ground = crate::render::camera::SceneMetrics::of(&scene).ground;
        if !(doodle_scale.is_finite() && doodle_scale > 0.0) {
            anyhow::bail!("doodle scale must be positive, got {doodle_scale}");
        }
        place_doodle(&mut scene.doodle, doodle_scale, anchor, ground);
    }
    if let Some(path) = events {
        scene.timeline = timeline_from_events(&read_actions(path)?, t0);
    }
    Ok(scene)
}

/// The part of a scene between `from` and `to` seconds (clamped), re-timed to start at 0.
pub fn slice_scene(scene: &Scene, from: f32, to: f32) -> Scene {
    let fps = scene.fps.max(1e-3);
    let n = scene.frames.len();
    let from = if from.is_finite() { from.max(0.0) } else { 0.0 };
    let a = ((from * fps).floor() as usize).min(n.saturating_sub(1));
    let b = if to.is_finite() {
        ((to * fps).ceil() as usize).clamp(a, n.saturating_sub(1))
    } else {
        n.saturating_sub(1)
    };
    let t0 = a as f32 / fps;
    let t1 = b as f32 / fps;
    Scene {
        title: scene.title.clone(),
        fps: scene.fps,
        frames: scene
            .frames
            .get(a..=b)
            .map(<[_]>::to_vec)
            .unwrap_or_default(),
        doodle: scene
            .doodle
            .iter()
            .filter(|p| p.t >= t0 && p.t <= t1)
            .map(|p| DoodlePoint { t: p.t - t0, ..*p })
            .collect(),
        timeline: scene
            .timeline
            .iter()
            .filter(|s| s.end >= t0 && s.start <= t1)
            .map(|s| TimelineSpan {
                start: s.start - t0,
                end: s.end - t0,
                ..s.clone()
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::read_bvh;

    #[test]
    fn sides_from_common_naming_schemes() {
        for n in [
            "LeftUpLeg",
            "mixamorig:LeftArm",
            "shoulder.L",
            "l_hip",
            "lShldr",
            "LHipJoint",
            "Bip01 L Thigh",
            "thigh_l",
        ] {
            assert_eq!(side_of(n), Side::Left, "{n}");
        }
        for n in [
            "RightFoot",
            "upper_arm.R",
            "r_knee",
            "rKnee",
            "RHipJoint",
            "Bip01 R Calf",
            "foot_r",
        ] {
            assert_eq!(side_of(n), Side::Right, "{n}");
        }
        for n in [
            "Hips",
            "Spine1",
            "Neck",
            "Head",
            "pelvis",
            "LowerBack",
            "Root",
            "Chest2",
        ] {
            assert_eq!(side_of(n), Side::Centre, "{n}");
        }
    }

    const BVH_CM_ZUP: &str = "HIERARCHY
ROOT Hips
{
  OFFSET 0 0 90
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT LeftUpLeg
  {
    OFFSET 10 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT LeftFoot
    {
      OFFSET 0 0 -85
      CHANNELS 3 Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 5 -5
      }
    }
  }
  JOINT RightUpLeg
  {
    OFFSET -10 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT RightFoot
    {
      OFFSET 0 0 -85
      CHANNELS 3 Zrotation Xrotation Yrotation
    }
  }
  JOINT Head
  {
    OFFSET 0 0 75
    CHANNELS 3 Zrotation Xrotation Yrotation
  }
}
MOTION
Frames: 2
Frame Time: 0.1
0 0 90 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
0 10 90 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
";

    #[test]
    fn zup_centimetre_clip_becomes_yup_metres() {
        let clip = read_bvh(BVH_CM_ZUP, Path::new("t.bvh"))
            .expect("parse")
            .clip;
        let u = infer_units(&clip.skeleton);
        assert_eq!(u.name, "cm");
        assert!(u.z_up);
        let scene = scene_from_clip(&clip);
        assert_eq!(scene.frames.len(), 2);
        assert!((scene.fps - 10.0).abs() < 1e-4);
        let f0 = &scene.frames[0];
        // Head ball is the highest point, ~1.65 m + radius above the feet.
        let top = f0
            .segments
            .iter()
            .map(|s| s.start.y.max(s.end.y))
            .fold(f32::MIN, f32::max);
        assert!((1.6..1.9).contains(&top), "top {top}");
        assert!(f0.segments.iter().any(|s| s.side == Side::Left));
        assert!(f0.segments.iter().any(|s| s.side == Side::Right));
        // Left is +X, so the figure faces +Z in Y-up terms... after the Z-up rotation the
        // file's -Y becomes +Z: facing = Y × (right − left) = Y × (−X) = +Z.
        let f = f0.facing.expect("facing");
        assert!(f.z > 0.9, "{f}");
        // Root translation of 10 cm along file Y becomes -0.1 m along scene Z.
        let d = scene.frames[1].segments[0].start - f0.segments[0].start;
        assert!((d - Vec3::new(0.0, 0.0, -0.1)).length() < 1e-4, "{d}");
    }

    #[test]
    fn doodle_placement_keeps_hops_and_drops_drift() {
        // The hand lifts the toy by 1 m over 10 s while making a 0.1 m hop at t = 5 s.
        let mut d: Vec<DoodlePoint> = (0..=1000)
            .map(|i| {
                let t = i as f32 * 0.01;
                let hop = if (4.8..5.2).contains(&t) {
                    0.1 * (1.0 - ((t - 5.0) / 0.2).powi(2))
                } else {
                    0.0
                };
                DoodlePoint {
                    t,
                    pos: Vec3::new(1.0 + t * 0.01, 0.5 + t * 0.1 + hop, 2.0),
                }
            })
            .collect();
        place_doodle(&mut d, 10.0, (3.0, 4.0), -0.5);
        assert!(
            (d[0].pos - Vec3::new(3.0, -0.5, 4.0)).length() < 1e-4,
            "{}",
            d[0].pos
        );
        let top = d.iter().map(|p| p.pos.y).fold(f32::MIN, f32::max);
        // The hop (0.3 m drawn) plus at most the drift within the window.
        assert!(top > -0.3 && top < 0.5, "top {top}");
        assert!((d[1000].pos.x - 4.0).abs() < 1e-3);
        let floor = local_floor(&[], 1.0);
        assert!(floor.is_empty());
    }

    #[test]
    fn slicing_retimes() {
        let clip = read_bvh(BVH_CM_ZUP, Path::new("t.bvh"))
            .expect("parse")
            .clip;
        let mut scene = scene_from_clip(&clip);
        scene.timeline.push(TimelineSpan {
            action: "x".into(),
            start: 0.05,
            end: 0.1,
            time: 0.0,
            weight: 0.0,
        });
        let s = slice_scene(&scene, 0.1, 5.0);
        assert_eq!(s.frames.len(), 1);
        assert!((s.timeline[0].start + 0.05).abs() < 1e-6);
        assert_eq!(slice_scene(&scene, f32::NAN, f32::NAN).frames.len(), 2);
    }
}
