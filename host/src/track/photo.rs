//! Which of a lone tag's two mirror poses its picture favours, judged on every pixel of the tag.
//!
//! A lone tag's two poses ([`super::pnp::solve_candidates`]) fit its four corners almost
//! equally, and under motion blur the wrong one often fits them better: at 1 m a kick that
//! pitched the toy 18° was reported pitched the other way for 0.6 s, its centre 2.5 cm off.
//! The tag's picture holds far more than its corners — every edge of its printed code is a
//! ruler of the perspective — so each pose is refined on the pixels themselves, and the
//! refined misfits say which side of the line of sight the tag faces:
//!
//! | step | what |
//! |---|---|
//! | 1 | the pixels whose centres fall on the tag (its white margin included, half a cell in) under the first pose: one set for both poses |
//! | 2 | the printed pattern drawn under a pose: up to [`SAMPLES`]² rays a pixel meet the tag's plane, each reads its cell, blended with the next over [`RAMP_CELLS`] at a cell's edge (so the drawing moves smoothly with the pose) |
//! | 3 | grey levels fitted as gain × drawing + offset (light and exposure are unknown); the misfit is the residuals' sum of squares |
//! | 4 | each pose refined by [`STEPS`] Levenberg–Marquardt steps on that misfit, from its own side of the mirror |
//! | 5 | the evidence against a pose: its misfit less the best, over twice the residual's variance (nats) |
//!
//! Unrefined, the verdict follows whatever the corner fit got wrong: a half-pixel shift of the
//! sampling grid flips it on a tag at rest. Refined, it is steady: on the track bench's kick
//! 3 nats for the true side at rest, 8–57 nats for it from 10° of pitch on. Near face-on the
//! two poses are alike and the picture's verdict swings from frame to frame (a jump at 1 m
//! read as a crouch, its face-on tilt swapped back and forth), so within [`MIN_APART_DEG`] the
//! corners' fit judges alone; switching from one to the other at a single angle left a tag held
//! near it swinging between them (five bows in five minutes at 1 m), so between
//! [`MIN_APART_DEG`] and [`TRUSTED_APART_DEG`] the two verdicts are blended
//! ([`super::mirror`]):
//!
//! | the two poses apart by | the frame's evidence |
//! |---|---|
//! | under 8° | the corners' |
//! | 8–16° | both, the picture's share rising from 0 to 1 |
//! | 16° and more | the picture's |

use glam::{DQuat, DVec3};

use super::detect::{CameraPose, GrayFrame, Intrinsics, TagPattern};
use super::pnp::{least_squares, Search};

/// Least angle between the two poses, degrees, for the picture to judge them at all (see the
/// module text).
pub const MIN_APART_DEG: f64 = 8.0;
/// Angle between the two poses, degrees, from which the picture's verdict stands alone; from
/// [`MIN_APART_DEG`] up to it, it shares the frame's evidence with the corners' in proportion.
pub const TRUSTED_APART_DEG: f64 = 16.0;

/// The picture's verdict on a lone tag's poses.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    /// The evidence against each pose, nats: 0 for the pose the picture favours.
    pub nats: Vec<f64>,
    /// Its share of the frame's evidence, 0–1 (the corners' fit weighs the rest): rising from
    /// 0 at [`MIN_APART_DEG`] to 1 at [`TRUSTED_APART_DEG`].
    pub weight: f64,
}
/// Rays per pixel side when drawing the pattern (at most: see [`MAX_RAYS`]).
pub const SAMPLES: usize = 3;
/// Width of the blend across a cell's edge, cells: a few tenths of a pixel at 0.5–1 m, so the
/// drawing is smooth in the pose without blurring the code away.
pub const RAMP_CELLS: f64 = 0.35;
/// Levenberg–Marquardt steps per pose.
pub const STEPS: usize = 5;
/// How a pose is refined on the picture: [`STEPS`] steps, a fiftieth of a degree and of a
/// millimetre for the Jacobian (the drawing is smooth over a few tenths of a pixel).
const PICTURE_SEARCH: Search = Search {
    steps: STEPS,
    tries: 6,
    damping: (1e-2, 1e-6),
    h: (2e-4, 2e-5),
    min_gain: 0.0,
};
/// Fewest pixels on the tag for a verdict.
const MIN_PIXELS: usize = 16;
/// Most rays drawn for one look at the tag: a nearer, larger tag is drawn with fewer rays a
/// pixel (down to one), which keeps a frame's cost near that of a tag at 1 m (~800 pixels of 9
/// rays). Judging only every other pixel instead loses what the picture gains at 0.5–0.75 m
/// (gestures with a pose 15° off somewhere on the track bench: 21, against 13 with every pixel).
pub const MAX_RAYS: usize = 8_000;
/// Pose parameters plus the two grey-level ones: the misfit's lost degrees of freedom.
const PARAMETERS: usize = 8;

/// The picture's verdict on `poses` (tag poses in the camera frame, the tag's edge `size`
/// metres, printed as `pattern`) in `frame`. `None` when it cannot judge: fewer than two
/// poses, poses within [`MIN_APART_DEG`], a tag too small or behind the camera.
pub fn evidence(
    frame: &GrayFrame,
    k: &Intrinsics,
    pattern: &TagPattern,
    size: f64,
    poses: &[CameraPose],
) -> Option<Picture> {
    let (a, b) = (poses.first()?, poses.get(1)?);
    let apart = 2.0 * a.quat().dot(b.quat()).abs().min(1.0).acos();
    // A NaN angle (a broken pose) judges nothing either.
    if apart.to_degrees().is_nan()
        || apart.to_degrees() < MIN_APART_DEG
        || pattern.border_width == 0
    {
        return None;
    }
    let problem = Problem::new(frame, *k, pattern, size, a)?;
    let misfits = poses
        .iter()
        .map(|p| {
            let (q, t) = problem.refine(p.quat(), DVec3::from_array(p.translation))?;
            Some(sum_sq(&problem.residuals(q, t)?))
        })
        .collect::<Option<Vec<f64>>>()?;
    let best = misfits.iter().copied().fold(f64::INFINITY, f64::min);
    let dof = problem.pixels.len().saturating_sub(PARAMETERS).max(1) as f64;
    let variance = (best / dof).max(1e-6);
    let nats: Vec<f64> = misfits
        .iter()
        .map(|m| (m - best) / (2.0 * variance))
        .collect();
    let weight = ((apart.to_degrees() - MIN_APART_DEG) / (TRUSTED_APART_DEG - MIN_APART_DEG))
        .clamp(0.0, 1.0);
    nats.iter()
        .all(|n| n.is_finite())
        .then_some(Picture { nats, weight })
}

/// One frame's tag: the pixels judged and how to draw the pattern on them.
struct Problem<'a> {
    k: Intrinsics,
    pattern: &'a TagPattern,
    /// A cell's edge, metres.
    cell: f64,
    /// Rays per pixel side (at most [`SAMPLES`]; fewer on a large tag, see [`MAX_RAYS`]).
    samples: usize,
    /// (column, row) of each pixel judged.
    pixels: Vec<(usize, usize)>,
    /// Their grey levels.
    observed: Vec<f64>,
}

impl<'a> Problem<'a> {
    /// The pixels on the tag under `pose` (step 1 of the module text).
    fn new(
        frame: &GrayFrame,
        k: Intrinsics,
        pattern: &'a TagPattern,
        size: f64,
        pose: &CameraPose,
    ) -> Option<Self> {
        let cell = size / pattern.border_width as f64;
        let reach = pattern.width as f64 / 2.0 * cell;
        let (q, t) = (pose.quat(), DVec3::from_array(pose.translation));
        let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
        for (u, v) in [
            (-reach, -reach),
            (reach, -reach),
            (reach, reach),
            (-reach, reach),
        ] {
            let c = q * DVec3::new(u, v, 0.0) + t;
            if c.z.is_nan() || c.z <= 1e-6 {
                return None;
            }
            let (x, y) = (k.cx + k.fx * c.x / c.z, k.cy + k.fy * c.y / c.z);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
        let last_x = frame.width.checked_sub(1)?;
        let last_y = frame.height.checked_sub(1)?;
        // Saturating casts: a box off the frame's left or top starts at 0.
        let (xa, ya) = (x0.floor().max(0.0) as usize, y0.floor().max(0.0) as usize);
        let (xb, yb) = (
            (x1.ceil().max(0.0) as usize).min(last_x),
            (y1.ceil().max(0.0) as usize).min(last_y),
        );
        let inside = reach - cell / 2.0;
        let area = (xb + 1).saturating_sub(xa) * (yb + 1).saturating_sub(ya);
        let samples = (1..=SAMPLES)
            .rev()
            .find(|s| area * s * s <= MAX_RAYS)
            .unwrap_or(1);
        let mut pixels = Vec::new();
        let mut observed = Vec::new();
        for y in ya..=yb {
            for x in xa..=xb {
                let Some(p) = on_plane(&k, q, t, x as f64 + 0.5, y as f64 + 0.5) else {
                    continue;
                };
                if p.x.abs() < inside && p.y.abs() < inside {
                    let Some(&g) = frame.pixels.get(y * frame.width + x) else {
                        continue;
                    };
                    pixels.push((x, y));
                    observed.push(f64::from(g));
                }
            }
        }
        (pixels.len() >= MIN_PIXELS).then_some(Self {
            k,
            samples,
            pattern,
            cell,
            pixels,
            observed,
        })
    }

    /// The pattern drawn on the pixels under pose (q, t), 0 black to 1 white (step 2).
    fn draw(&self, q: DQuat, t: DVec3) -> Option<Vec<f64>> {
        let half = self.pattern.width as f64 / 2.0;
        let m = self.samples;
        let n = (m * m) as f64;
        self.pixels
            .iter()
            .map(|&(x, y)| {
                let mut sum = 0.0;
                for sy in 0..m {
                    for sx in 0..m {
                        let px = x as f64 + (sx as f64 + 0.5) / m as f64;
                        let py = y as f64 + (sy as f64 + 0.5) / m as f64;
                        let p = on_plane(&self.k, q, t, px, py)?;
                        sum += shade(self.pattern, p.x / self.cell + half, p.y / self.cell + half);
                    }
                }
                Some(sum / n)
            })
            .collect()
    }

    /// The observed grey levels less the drawing's, fitted as gain × drawing + offset (step 3).
    fn residuals(&self, q: DQuat, t: DVec3) -> Option<Vec<f64>> {
        let drawn = self.draw(q, t)?;
        let n = drawn.len() as f64;
        let md = drawn.iter().sum::<f64>() / n;
        let mo = self.observed.iter().sum::<f64>() / n;
        let (mut dd, mut d_o) = (0.0, 0.0);
        for (d, o) in drawn.iter().zip(&self.observed) {
            dd += (d - md) * (d - md);
            d_o += (d - md) * (o - mo);
        }
        let gain = if dd > 0.0 { d_o / dd } else { 0.0 };
        Some(
            drawn
                .iter()
                .zip(&self.observed)
                .map(|(d, o)| o - (mo + gain * (d - md)))
                .collect(),
        )
    }

    /// The pose near (q, t) the picture fits best (step 4).
    fn refine(&self, q: DQuat, t: DVec3) -> Option<(DQuat, DVec3)> {
        let fit = least_squares(
            q,
            t,
            &PICTURE_SEARCH,
            |q, t| self.residuals(q, t),
            sum_sq,
            |_| true,
        )?;
        Some((fit.0, fit.1))
    }
}

/// Where the ray through pixel (x, y) meets the plane of the tag at pose (q, t), in the tag's
/// frame (metres); `None` for a ray along the plane.
fn on_plane(k: &Intrinsics, q: DQuat, t: DVec3, x: f64, y: f64) -> Option<DVec3> {
    let inv = q.inverse();
    let ray = inv * DVec3::new((x - k.cx) / k.fx, (y - k.cy) / k.fy, 1.0);
    let origin = inv * t;
    if ray.z.abs() < 1e-12 {
        return None;
    }
    Some(ray * (origin.z / ray.z) - origin)
}

/// The pattern's shade at (u, v) cells from its top-left, 0 black to 1 white, blended with the
/// neighbouring cell within half of [`RAMP_CELLS`] of an edge; white beyond the pattern.
fn shade(p: &TagPattern, u: f64, v: f64) -> f64 {
    let white = |x: i64, y: i64| {
        let black = usize::try_from(x)
            .ok()
            .zip(usize::try_from(y).ok())
            .is_some_and(|(x, y)| p.is_black(x, y));
        if black {
            0.0
        } else {
            1.0
        }
    };
    let (ix, wx) = blend(u);
    let (iy, wy) = blend(v);
    let top = white(ix, iy) * (1.0 - wx) + white(ix + 1, iy) * wx;
    let bottom = white(ix, iy + 1) * (1.0 - wx) + white(ix + 1, iy + 1) * wx;
    top * (1.0 - wy) + bottom * wy
}

/// For a coordinate `f` in cells: the cell to blend from and the weight of the one after it.
fn blend(f: f64) -> (i64, f64) {
    let i = f.floor();
    let within = f - i;
    let i = i as i64;
    if within > 1.0 - RAMP_CELLS / 2.0 {
        (i, (within - (1.0 - RAMP_CELLS / 2.0)) / RAMP_CELLS)
    } else if within < RAMP_CELLS / 2.0 {
        (i - 1, 0.5 + within / RAMP_CELLS)
    } else {
        (i, 0.0)
    }
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::poselog::PoseSample;
    use crate::track::detect::{tag_pattern, Detector, DetectorSettings, Family};
    use crate::track::fuse::solve_tags;
    use crate::track::pose::{angle_between_deg, figurine_pose};
    use crate::track::render::{tests::test_scene, Faults};
    use crate::track::rig::Rig;

    /// A 4 cm tag rendered still at `distance` metres, pitched `pitch_deg`: its two poses,
    /// the evidence against each, and each pose's error against the truth (degrees).
    fn judged(distance: f64, pitch_deg: f64) -> (Option<Picture>, Vec<f64>) {
        let s = test_scene(
            Faults {
                occlusion_every_s: 0.0,
                ..Faults::default()
            },
            5,
        );
        let q = glam::DQuat::from_rotation_x(pitch_deg.to_radians());
        let truth = PoseSample {
            t: 0.0,
            pos: [0.03, 0.02, -distance],
            quat: [q.w, q.x, q.y, q.z],
        };
        let frame = s.render(&s.background(), 0, 0.0, |_| Some(truth)).frame;
        let mut d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        let found = d.detect(&frame);
        let rig = Rig::single(0, 0.04);
        let seen = solve_tags(&rig, found, &s.intrinsics);
        let tag = seen.first().expect("the tag is found");
        let errors = tag
            .candidates
            .iter()
            .map(|c| angle_between_deg(figurine_pose(c).1, q))
            .collect();
        let pattern = tag_pattern(Family::Tag36h11, 0).unwrap();
        let nats = evidence(&frame, &s.intrinsics, &pattern, 0.04, &tag.tag_candidates);
        (nats, errors)
    }

    #[test]
    fn a_pitched_tag_s_picture_favours_its_true_pose_over_its_mirror() {
        for (distance, pitch) in [(1.0, 18.0), (1.0, -18.0), (0.7, 25.0)] {
            let (nats, errors) = judged(distance, pitch);
            let picture = nats.expect("poses far enough apart to judge");
            assert_eq!(picture.weight, 1.0, "at {distance} m, {pitch}°");
            let nats = picture.nats;
            assert_eq!(nats.len(), 2);
            let truth = if errors[0] < errors[1] { 0 } else { 1 };
            assert!(errors[truth] < 4.0, "{errors:?}");
            assert_eq!(nats[truth], 0.0, "at {distance} m, {pitch}°: {nats:?}");
            assert!(nats[1 - truth] > 3.0, "at {distance} m, {pitch}°: {nats:?}");
        }
    }

    #[test]
    fn a_face_on_tag_s_picture_does_not_judge_alone() {
        // Face-on at 1 m the two poses stand about 10° apart: the corners keep most of the say.
        let (picture, _) = judged(1.0, 0.0);
        assert!(
            picture.as_ref().is_none_or(|p| p.weight < 0.5),
            "{picture:?}"
        );
    }

    #[test]
    fn a_tag_off_the_frame_or_behind_the_camera_gets_no_verdict_and_no_panic() {
        let pattern = tag_pattern(Family::Tag36h11, 0).unwrap();
        let k = crate::track::pose::intrinsics_from_fov(64, 48, 60.0);
        let frame = GrayFrame {
            width: 64,
            height: 48,
            pixels: vec![128; 64 * 48],
        };
        let pose = |x: f64, z: f64, tilt: f64| {
            CameraPose::from_parts(
                glam::DMat3::from_rotation_x(tilt.to_radians()),
                DVec3::new(x, 0.0, z),
                0.05,
            )
        };
        for (x, z) in [
            (5.0, 1.0),
            (-5.0, 1.0),
            (0.0, -1.0),
            (0.0, 0.0),
            (f64::NAN, 1.0),
        ] {
            let poses = [pose(x, z, 20.0), pose(x, z, -20.0)];
            assert_eq!(
                evidence(&frame, &k, &pattern, 0.04, &poses),
                None,
                "at {x}, {z}"
            );
        }
        let empty = GrayFrame {
            width: 0,
            height: 0,
            pixels: Vec::new(),
        };
        let poses = [pose(0.0, 0.5, 20.0), pose(0.0, 0.5, -20.0)];
        assert_eq!(evidence(&empty, &k, &pattern, 0.04, &poses), None);
        assert_eq!(evidence(&frame, &k, &pattern, 0.04, &poses[..1]), None);
    }
}
