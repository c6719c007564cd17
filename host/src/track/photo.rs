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
//! | 5 | the evidence against a pose: its misfit less the best, over twice the residual's variance, times the share of independent looks (nats; below) |
//!
//! Unrefined, the verdict follows whatever the corner fit got wrong: a half-pixel shift of the
//! sampling grid flips it on a tag at rest. Refined, it is steady: on the track bench's kick
//! the true side is favoured at rest and from 10° of pitch on. Which frames it judges, and
//! what it replaces there, is [`super::mirror`]'s to say.
//!
//! Neighbouring pixels' residuals are not independent — blur and the drawing's ramps make them
//! err together — so the nats are scaled by the share of the pixels that count as independent
//! looks: with the best fit's residuals correlated ρ between neighbours along a row (and along
//! a column), (1 − ρ) / (1 + ρ) on each axis, an AR(1) field's. Without it a weak verdict near
//! face-on counts several nats a frame, and a hand's sway swings the report.

use glam::{DMat3, DQuat, DVec2, DVec3};

use super::detect::{CameraPose, GrayFrame, Intrinsics, TagPattern};
use super::pnp::{least_squares, Jacobian, Search};

/// Rays per pixel side when drawing the pattern (at most: see [`MAX_RAYS`]).
pub const SAMPLES: usize = 3;
/// Width of the blend across a cell's edge, cells: a few tenths of a pixel at 0.5–1 m, so the
/// drawing is smooth in the pose without blurring the code away.
pub const RAMP_CELLS: f64 = 0.35;
/// Levenberg–Marquardt steps per pose.
pub const STEPS: usize = 5;
/// How a pose is refined on the picture: [`STEPS`] steps, the Jacobian drawn with the pattern
/// (each ray's slope on a cell's ramp, carried through where the ray meets the plane) in one
/// pass rather than six more drawings by finite differences.
const PICTURE_SEARCH: Search = Search {
    steps: STEPS,
    tries: 6,
    damping: (1e-2, 1e-6),
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
/// metres, printed as `pattern`) in `frame`: the evidence against each pose, nats, 0 for the
/// pose the picture favours. `None` when it cannot judge: fewer than two poses, a broken
/// pose, a tag too small or behind the camera.
pub fn evidence(
    frame: &GrayFrame,
    k: &Intrinsics,
    pattern: &TagPattern,
    size: f64,
    poses: &[CameraPose],
) -> Option<Vec<f64>> {
    let (a, b) = (poses.first()?, poses.get(1)?);
    let apart = 2.0 * a.quat().dot(b.quat()).abs().min(1.0).acos();
    // A NaN angle (a broken pose) judges nothing either.
    if apart.is_nan() || pattern.border_width == 0 {
        return None;
    }
    let problem = Problem::new(frame, *k, pattern, size, a)?;
    let fits = poses
        .iter()
        .map(|p| {
            let r = problem.refine(p.quat(), DVec3::from_array(p.translation))?;
            Some((sum_sq(&r), r))
        })
        .collect::<Option<Vec<(f64, Vec<f64>)>>>()?;
    let (best, best_r) = fits
        .iter()
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(m, r)| (*m, r))?;
    let dof = problem.pixels.len().saturating_sub(PARAMETERS).max(1) as f64;
    let variance = (best / dof).max(1e-6);
    // Neighbouring pixels' residuals err together (blur, the drawing's ramps): the misfits'
    // difference holds fewer independent looks than pixels.
    let share = problem.independent_share(best_r);
    let nats: Vec<f64> = fits
        .iter()
        .map(|(m, _)| share * (m - best) / (2.0 * variance))
        .collect();
    nats.iter().all(|n| n.is_finite()).then_some(nats)
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
        let view = View::new(&k, q, t);
        let mut pixels = Vec::new();
        let mut observed = Vec::new();
        for y in ya..=yb {
            for x in xa..=xb {
                let Some((p, _)) = view.meet(x as f64 + 0.5, y as f64 + 0.5) else {
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

    /// The share of the judged pixels whose residuals `r` count as independent looks: for
    /// residuals correlated ρ between neighbours along a row (and along a column), an AR(1)
    /// field's (1 − ρ) / (1 + ρ) on each axis.
    fn independent_share(&self, r: &[f64]) -> f64 {
        let at: std::collections::HashMap<(usize, usize), f64> =
            self.pixels.iter().copied().zip(r.iter().copied()).collect();
        let mut share = 1.0;
        for (dx, dy) in [(1, 0), (0, 1)] {
            let (mut xy, mut xx, mut yy) = (0.0, 0.0, 0.0);
            for (&(x, y), &a) in &at {
                if let Some(&b) = at.get(&(x + dx, y + dy)) {
                    xy += a * b;
                    xx += a * a;
                    yy += b * b;
                }
            }
            let rho = if xx > 0.0 && yy > 0.0 {
                (xy / (xx * yy).sqrt()).clamp(0.0, 0.95)
            } else {
                0.0
            };
            share *= (1.0 - rho) / (1.0 + rho);
        }
        share
    }

    /// The pattern drawn on the pixels under pose (q, t), 0 black to 1 white (step 2), and
    /// with `slopes` each pixel's derivatives by the pose ([`Jacobian`] columns; empty
    /// without).
    fn draw(&self, q: DQuat, t: DVec3, slopes: bool) -> Option<(Vec<f64>, Jacobian)> {
        let view = View::new(&self.k, q, t);
        let rot = DMat3::from_quat(q);
        let half = self.pattern.width as f64 / 2.0;
        let m = self.samples;
        let n = (m * m) as f64;
        let mut drawn = Vec::with_capacity(self.pixels.len());
        let mut jac: Jacobian = Default::default();
        if slopes {
            for col in &mut jac {
                col.reserve_exact(self.pixels.len());
            }
        }
        for &(x, y) in &self.pixels {
            let (mut sum, mut turn, mut shift) = (0.0, DVec3::ZERO, DVec3::ZERO);
            for sy in 0..m {
                for sx in 0..m {
                    let px = x as f64 + (sx as f64 + 0.5) / m as f64;
                    let py = y as f64 + (sy as f64 + 0.5) / m as f64;
                    let (p, ray) = view.meet(px, py)?;
                    let (value, du, dv) =
                        shade(self.pattern, p.x / self.cell + half, p.y / self.cell + half);
                    sum += value;
                    if slopes && (du != 0.0 || dv != 0.0) {
                        // How the point where the ray meets the plane moves with the pose,
                        // in the tag's frame: the plane turns and slides under a fixed ray.
                        let (gu, gv) = (du / self.cell, dv / self.cell);
                        let (ax, ay) = (ray.x / ray.z, ray.y / ray.z);
                        turn += DVec3::new(ax * p.y, -ax * p.x, p.y) * gu
                            + DVec3::new(ay * p.y, -ay * p.x, -p.x) * gv;
                        shift += DVec3::new(-gu, -gv, ax * gu + ay * gv);
                    }
                }
            }
            drawn.push(sum / n);
            if slopes {
                // Back to the camera's frame, in which the pose's parameters step.
                let (turn, shift) = (rot * (turn / n), rot * (shift / n));
                for (j, v) in turn
                    .to_array()
                    .into_iter()
                    .chain(shift.to_array())
                    .enumerate()
                {
                    jac[j].push(v);
                }
            }
        }
        Some((drawn, jac))
    }

    /// The observed grey levels less the drawing's, fitted as gain × drawing + offset (step
    /// 3); with `slopes`, also their [`Jacobian`], the gain and offset held.
    fn residuals(&self, q: DQuat, t: DVec3, slopes: bool) -> Option<(Vec<f64>, Jacobian)> {
        let (drawn, mut jac) = self.draw(q, t, slopes)?;
        let n = drawn.len() as f64;
        let md = drawn.iter().sum::<f64>() / n;
        let mo = self.observed.iter().sum::<f64>() / n;
        let (mut dd, mut d_o) = (0.0, 0.0);
        for (d, o) in drawn.iter().zip(&self.observed) {
            dd += (d - md) * (d - md);
            d_o += (d - md) * (o - mo);
        }
        let gain = if dd > 0.0 { d_o / dd } else { 0.0 };
        for col in jac.iter_mut().filter(|c| !c.is_empty()) {
            let mean = col.iter().sum::<f64>() / n;
            for v in col.iter_mut() {
                *v = -gain * (*v - mean);
            }
        }
        let r = drawn
            .iter()
            .zip(&self.observed)
            .map(|(d, o)| o - (mo + gain * (d - md)))
            .collect();
        Some((r, jac))
    }

    /// The misfit's residuals under pose (q, t).
    fn misfit(&self, q: DQuat, t: DVec3) -> Option<Vec<f64>> {
        self.residuals(q, t, false).map(|(r, _)| r)
    }

    /// The residuals of the pose near (q, t) the picture fits best (step 4).
    fn refine(&self, q: DQuat, t: DVec3) -> Option<Vec<f64>> {
        let (_, _, r) = least_squares(
            q,
            t,
            &PICTURE_SEARCH,
            |q, t| self.misfit(q, t),
            |q, t, _| self.residuals(q, t, true).map(|(_, j)| j),
            sum_sq,
            |_| true,
        )?;
        Some(r)
    }
}

/// Where the rays through a camera's pixels meet the tag's plane at one pose.
struct View {
    /// The camera's rotation into the tag's frame.
    inv: DMat3,
    /// The tag's translation in its own frame.
    origin: DVec3,
    /// The pixel grid: (cx, cy) and the reciprocal focal lengths, 1/pixels.
    centre: (f64, f64),
    scale: (f64, f64),
}

impl View {
    fn new(k: &Intrinsics, q: DQuat, t: DVec3) -> Self {
        let inv = DMat3::from_quat(q.inverse());
        Self {
            inv,
            origin: inv * t,
            centre: (k.cx, k.cy),
            scale: (1.0 / k.fx, 1.0 / k.fy),
        }
    }

    /// Where the ray through image point (x, y) meets the plane (tag frame, metres), and the
    /// ray's direction in the tag's frame (unit depth in the camera's); `None` for a ray along
    /// the plane.
    fn meet(&self, x: f64, y: f64) -> Option<(DVec2, DVec3)> {
        let ray = self.inv.x_axis * ((x - self.centre.0) * self.scale.0)
            + self.inv.y_axis * ((y - self.centre.1) * self.scale.1)
            + self.inv.z_axis;
        if ray.z.abs() < 1e-12 {
            return None;
        }
        let s = self.origin.z / ray.z;
        Some((
            DVec2::new(ray.x * s - self.origin.x, ray.y * s - self.origin.y),
            ray,
        ))
    }
}

/// The pattern's shade at (u, v) cells from its top-left, 0 black to 1 white, blended with the
/// neighbouring cell within half of [`RAMP_CELLS`] of an edge; white beyond the pattern. With
/// it, its derivatives by u and by v (non-zero only on a ramp).
fn shade(p: &TagPattern, u: f64, v: f64) -> (f64, f64, f64) {
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
    let (ix, wx, sx) = blend(u);
    let (iy, wy, sy) = blend(v);
    if sx == 0.0 && sy == 0.0 {
        return (white(ix, iy), 0.0, 0.0);
    }
    let (a, b) = (white(ix, iy), white(ix + 1, iy));
    let (c, d) = (white(ix, iy + 1), white(ix + 1, iy + 1));
    let top = a * (1.0 - wx) + b * wx;
    let bottom = c * (1.0 - wx) + d * wx;
    (
        top * (1.0 - wy) + bottom * wy,
        sx * ((b - a) * (1.0 - wy) + (d - c) * wy),
        sy * (bottom - top),
    )
}

/// For a coordinate `f` in cells: the cell to blend from, the weight of the one after it, and
/// that weight's derivative by `f` (0 off a ramp).
fn blend(f: f64) -> (i64, f64, f64) {
    let i = f.floor();
    let within = f - i;
    let i = i as i64;
    if within > 1.0 - RAMP_CELLS / 2.0 {
        (
            i,
            (within - (1.0 - RAMP_CELLS / 2.0)) / RAMP_CELLS,
            1.0 / RAMP_CELLS,
        )
    } else if within < RAMP_CELLS / 2.0 {
        (i - 1, 0.5 + within / RAMP_CELLS, 1.0 / RAMP_CELLS)
    } else {
        (i, 0.0, 0.0)
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
    fn judged(distance: f64, pitch_deg: f64) -> (Option<Vec<f64>>, Vec<f64>) {
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
            let nats = nats.expect("poses far enough apart to judge");
            assert_eq!(nats.len(), 2);
            let truth = if errors[0] < errors[1] { 0 } else { 1 };
            assert!(errors[truth] < 4.0, "{errors:?}");
            assert_eq!(nats[truth], 0.0, "at {distance} m, {pitch}°: {nats:?}");
            assert!(nats[1 - truth] > 1.0, "at {distance} m, {pitch}°: {nats:?}");
        }
    }

    #[test]
    fn the_drawn_jacobian_matches_finite_differences_of_the_drawing() {
        let s = test_scene(
            Faults {
                occlusion_every_s: 0.0,
                ..Faults::default()
            },
            5,
        );
        let q =
            glam::DQuat::from_rotation_x(20f64.to_radians()) * glam::DQuat::from_rotation_y(0.3);
        let truth = PoseSample {
            t: 0.0,
            pos: [0.03, 0.02, -0.8],
            quat: [q.w, q.x, q.y, q.z],
        };
        let frame = s.render(&s.background(), 0, 0.0, |_| Some(truth)).frame;
        let mut d = Detector::new(Family::Tag36h11, DetectorSettings::default()).unwrap();
        let seen = solve_tags(&Rig::single(0, 0.04), d.detect(&frame), &s.intrinsics);
        let pose = &seen.first().expect("the tag is found").tag_candidates[0];
        let pattern = tag_pattern(Family::Tag36h11, 0).unwrap();
        let problem = Problem::new(&frame, s.intrinsics, &pattern, 0.04, pose).unwrap();
        let (q, t) = (pose.quat(), DVec3::from_array(pose.translation));
        let (r, drawn) = problem.residuals(q, t, true).unwrap();
        let misfit = |q, t| problem.misfit(q, t);
        let numeric =
            crate::track::pnp::numerical_jacobian(&misfit, q, t, &r, (1e-5, 1e-6)).unwrap();
        for (j, (a, b)) in drawn.iter().zip(&numeric).enumerate() {
            let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
            let (na, nb) = (sum_sq(a).sqrt(), sum_sq(b).sqrt());
            assert!(nb > 0.0, "column {j} is flat");
            // Rays crossing a ramp's end within the finite step make the two differ a little.
            assert!(
                dot / (na * nb) > 0.99,
                "column {j}: cosine {}",
                dot / (na * nb)
            );
            assert!(
                (na / nb - 1.0).abs() < 0.02,
                "column {j}: {na} against {nb}"
            );
        }
    }

    #[test]
    fn a_face_on_tag_s_picture_says_little_either_way() {
        // Face-on at 1 m the two poses stand about 10° apart and look alike: counted as if every
        // pixel were an independent look, a frame's verdict would be worth several nats.
        for pitch in [0.0, 3.0] {
            let (nats, _) = judged(1.0, pitch);
            let most = nats.iter().flatten().copied().fold(0.0, f64::max);
            assert!(most < 0.5, "at {pitch}°: {nats:?}");
        }
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
