//! A procedural walking stick figure: a ready-made [`Scene`] for tests, the benchmark and the
//! demo, independent of any data file. It walks along +Z, facing +Z, with a sine gait; the
//! character's left is +X (the object-frame convention of DESIGN.md).

use glam::{Quat, Vec3};

use super::scene::{BoneSegment, DoodlePoint, FramePose, Scene, Side, TimelineSpan};

/// Walking speed, metres per second (before scaling).
const SPEED: f32 = 1.1;
/// Stride frequency, full gait cycles per second.
const CADENCE: f32 = 0.9;

/// Parameters of the procedural figure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FigureParams {
    /// Unit scale: 1 = metres, 100 = centimetres, 39.37 = inches.
    pub scale: f32,
    /// Multiplier of the forward speed (0 walks in place).
    pub travel: f32,
    /// Which character (palette) the bones belong to.
    pub character: u16,
    /// World offset of the figure's start, in output units.
    pub offset: Vec3,
}

impl Default for FigureParams {
    fn default() -> Self {
        FigureParams {
            scale: 1.0,
            travel: 1.0,
            character: 0,
            offset: Vec3::ZERO,
        }
    }
}

/// The figure's bones at time `t` seconds.
pub fn walking_pose(t: f32, p: &FigureParams) -> FramePose {
    let phase = std::f32::consts::TAU * CADENCE * t;
    let root = Vec3::new(
        0.0,
        0.93 + 0.025 * (2.0 * phase).cos(),
        SPEED * p.travel * t,
    );
    let mut segments = Vec::with_capacity(16);
    let mut bone = |a: Vec3, b: Vec3, side: Side, radius: Option<f32>| {
        segments.push(BoneSegment {
            start: p.offset + a * p.scale,
            end: p.offset + b * p.scale,
            radius: radius.map(|r| r * p.scale),
            side,
            character: p.character,
        });
    };
    let chest = root + Vec3::new(0.0, 0.42, 0.03);
    let neck = root + Vec3::new(0.0, 0.57, 0.04);
    bone(root, chest, Side::Centre, Some(0.07));
    bone(chest, neck, Side::Centre, Some(0.05));
    bone(
        neck + Vec3::new(0.0, 0.06, 0.0),
        neck + Vec3::new(0.0, 0.16, 0.01),
        Side::Centre,
        Some(0.1),
    );
    for (side, sx, sign) in [(Side::Left, 0.1f32, 1.0f32), (Side::Right, -0.1, -1.0)] {
        // Legs: the swing of the left leg leads the right by half a cycle.
        let swing = 0.42
            * (phase
                + if sign > 0.0 {
                    0.0
                } else {
                    std::f32::consts::PI
                })
            .sin();
        let lift = (phase
            + if sign > 0.0 {
                0.0
            } else {
                std::f32::consts::PI
            }
            + 1.2)
            .sin()
            .max(0.0);
        let hip = root + Vec3::new(sx, -0.02, 0.0);
        let thigh = Quat::from_rotation_x(-swing) * Vec3::new(0.0, -0.45, 0.0);
        let knee = hip + thigh;
        let shin = Quat::from_rotation_x(-swing + 0.9 * lift + 0.05) * Vec3::new(0.0, -0.44, 0.0);
        let ankle = knee + shin;
        let toe = ankle + Quat::from_rotation_x(0.4 * lift) * Vec3::new(0.0, -0.04, 0.16);
        bone(root, hip, Side::Centre, Some(0.06));
        bone(hip, knee, side, None);
        bone(knee, ankle, side, None);
        bone(ankle, toe, side, Some(0.035));
        // Arms swing against the legs.
        let shoulder = neck + Vec3::new(sx * 1.8, -0.06, -0.01);
        let upper = Quat::from_rotation_x(swing * 0.7) * Vec3::new(sx * 0.25, -0.29, 0.0);
        let elbow = shoulder + upper;
        let fore = Quat::from_rotation_x(swing * 0.7 - 0.35) * Vec3::new(sx * 0.1, -0.26, 0.0);
        let wrist = elbow + fore;
        bone(neck, shoulder, side, Some(0.045));
        bone(shoulder, elbow, side, None);
        bone(elbow, wrist, side, Some(0.035));
    }
    FramePose {
        segments,
        facing: Some(Vec3::Z),
    }
}

/// A scene of the figure walking for `seconds` at `fps`, with a hopping doodle above its path
/// and two timeline spans ("walk" then "hop") so every layer of the renderer shows.
pub fn walking_scene(seconds: f32, fps: f32, p: &FigureParams) -> Scene {
    let fps = if fps.is_finite() && fps > 0.0 {
        fps
    } else {
        30.0
    };
    let seconds = if seconds.is_finite() {
        seconds.max(0.0)
    } else {
        0.0
    };
    let n = (seconds * fps).round() as usize + 1;
    let frames = (0..n).map(|i| walking_pose(i as f32 / fps, p)).collect();
    let doodle = (0..=(seconds * 60.0) as usize)
        .map(|i| {
            let t = i as f32 / 60.0;
            let hop = (std::f32::consts::PI * 1.5 * t).sin().abs() * 0.35;
            DoodlePoint {
                t,
                pos: p.offset + Vec3::new(0.45, 0.25 + hop, SPEED * p.travel * t) * p.scale,
            }
        })
        .collect();
    let half = seconds * 0.5;
    Scene {
        title: "procedural walk".into(),
        fps,
        frames,
        doodle,
        timeline: vec![
            TimelineSpan {
                action: "walk".into(),
                start: 0.0,
                end: half * 0.95,
                time: -0.4,
                weight: -0.3,
            },
            TimelineSpan {
                action: "hop".into(),
                start: half,
                end: seconds,
                time: 0.7,
                weight: 0.5,
            },
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::scene::pose_bounds;

    #[test]
    fn figure_is_person_sized_and_stands_on_the_ground() {
        for t in [0.0f32, 0.3, 0.77] {
            let pose = walking_pose(t, &FigureParams::default());
            let (lo, hi) = pose_bounds(&pose).expect("bones");
            let height = hi.y - lo.y;
            assert!((1.6..1.95).contains(&height), "height {height}");
            assert!(lo.y > -0.1 && lo.y < 0.15, "feet at {}", lo.y);
        }
    }

    #[test]
    fn scale_scales_everything() {
        let a = walking_pose(0.4, &FigureParams::default());
        let b = walking_pose(
            0.4,
            &FigureParams {
                scale: 100.0,
                ..Default::default()
            },
        );
        for (x, y) in a.segments.iter().zip(&b.segments) {
            assert!((x.end * 100.0 - y.end).length() < 1e-2);
        }
    }

    #[test]
    fn scene_has_requested_frames() {
        let s = walking_scene(2.0, 30.0, &FigureParams::default());
        assert_eq!(s.frames.len(), 61);
        assert!(s.validate().is_ok());
        assert!((s.duration() - 2.0).abs() < 1e-4);
    }
}
