//! Transitions between consecutive actions: the best pair of frames by windowed posture
//! distance (seed 003 eq. 1, after Kovar et al.), and the blend between them.
//!
//! The distance between frame i of A and frame j of B is the sum, over a window of
//! `2·half + 1` frames centred on them, of squared distances between corresponding joint
//! positions, after the rigid 2-D alignment (rotation about +Y, translation in the ground
//! plane) that minimises it — closed form from Kovar's motion graphs. Joints weigh equally.

use glam::Vec3;

use crate::motion::{slerp_short, Pose};

/// Half window of the posture distance, frames (11-frame windows, ~0.37 s at 30 fps).
pub const WINDOW_HALF: usize = 5;

/// The optimal ground alignment (θ about +Y, then translation x0, z0) of cloud `b` onto `a`,
/// and the remaining sum of squared distances. Clouds must have equal length.
pub fn aligned_distance(a: &[Vec3], b: &[Vec3]) -> (f32, f32, f32, f32) {
    let n = a.len().min(b.len());
    if n == 0 {
        return (0.0, 0.0, 0.0, 0.0);
    }
    let w = 1.0 / n as f32;
    let (mut xa, mut za, mut xb, mut zb) = (0.0, 0.0, 0.0, 0.0);
    for (p, q) in a.iter().zip(b) {
        xa += w * p.x;
        za += w * p.z;
        xb += w * q.x;
        zb += w * q.z;
    }
    let (mut num, mut den) = (0.0f32, 0.0f32);
    for (p, q) in a.iter().zip(b) {
        num += w * (p.x * q.z - q.x * p.z);
        den += w * (p.x * q.x + p.z * q.z);
    }
    num -= xa * zb - xb * za;
    den -= xa * xb + za * zb;
    let theta = num.atan2(den);
    let (s, c) = theta.sin_cos();
    let x0 = xa - xb * c - zb * s;
    let z0 = za + xb * s - zb * c;
    let d: f32 = a
        .iter()
        .zip(b)
        .map(|(p, q)| {
            let x = q.x * c + q.z * s + x0;
            let z = -q.x * s + q.z * c + z0;
            (p.x - x).powi(2) + (p.y - q.y).powi(2) + (p.z - z).powi(2)
        })
        .sum();
    (d, theta, x0, z0)
}

/// Windowed posture distance between frame `i` of `a` and frame `j` of `b` (frames × joints
/// world positions); windows are clamped at the clip ends.
pub fn window_distance(a: &[Vec<Vec3>], i: usize, b: &[Vec<Vec3>], j: usize, half: usize) -> f32 {
    let mut ca = Vec::new();
    let mut cb = Vec::new();
    for k in -(half as isize)..=(half as isize) {
        let fa = (i as isize + k).clamp(0, a.len() as isize - 1) as usize;
        let fb = (j as isize + k).clamp(0, b.len() as isize - 1) as usize;
        if let (Some(pa), Some(pb)) = (a.get(fa), b.get(fb)) {
            ca.extend_from_slice(pa);
            cb.extend_from_slice(pb);
        }
    }
    aligned_distance(&ca, &cb).0
}

/// The pair (i among `range_a`, j among `range_b`) with the least windowed posture distance.
pub fn best_pair<A, B>(
    a: &[Vec<Vec3>],
    range_a: A,
    b: &[Vec<Vec3>],
    range_b: B,
) -> Option<(usize, usize, f32)>
where
    A: IntoIterator<Item = usize>,
    B: IntoIterator<Item = usize> + Clone,
{
    let mut best: Option<(usize, usize, f32)> = None;
    for i in range_a {
        if i >= a.len() {
            continue;
        }
        for j in range_b.clone() {
            if j >= b.len() {
                continue;
            }
            let d = window_distance(a, i, b, j, WINDOW_HALF);
            if best.is_none_or(|(_, _, bd)| d < bd) {
                best = Some((i, j, d));
            }
        }
    }
    best
}

/// Smooth blend weight: 0 at u ≤ 0, 1 at u ≥ 1, zero slope at both ends.
pub fn smoothstep(u: f32) -> f32 {
    let u = u.clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
}

/// Half-width (seconds) of the window over which [`ease_root`] spreads a change of the root's
/// velocity at a join: a root that stood still and runs at 4 m/s in the next frame (a clip
/// starting mid-stride after a held pose, a blend ending where the next action's root already
/// moves) accelerates over ≈ 0.33 s instead, about 12 m/s², as a person does when they set
/// off (the real takes' 95th percentiles lie at 1–42 m/s², `figurine check --reference`).
pub const ROOT_EASE_S: f32 = 0.18;

/// Makes the root's path C1 about frame `join` of `frames` (root translations in world
/// space): the jump of the root's velocity at `join` (its speed from `join` on less its speed
/// up to it) is spread evenly over the `2·half` frames around, a ramp in place of a step; the
/// rest of the motion (a bob, a turn) is kept as it was, and the root is back on its own path
/// `half` frames after the join (the ramp gains before the join what it loses after). What
/// stood still and runs at 4 m/s in the next frame now sets off over `2·half` frames, and
/// moves at most `|Δv|·half/4` away from its path meanwhile (the feet are re-planted
/// afterwards). No frame of the window is left faster than `top` (distance per frame) or the
/// fastest the root already moved in it: where the full ramp would be, only the share of the
/// step that keeps within is eased.
pub fn ease_root(frames: &mut [Pose], join: usize, half: usize, top: f32) {
    let n = frames.len();
    if half == 0 || join < half || join + half >= n {
        return;
    }
    let root = |f: usize| {
        frames[f]
            .translations
            .first()
            .copied()
            .unwrap_or(Vec3::ZERO)
    };
    // Velocity per frame: v(f) = root(f + 1) − root(f).
    let step = (root(join + 1) - root(join)) - (root(join) - root(join - 1));
    let span = 2 * half;
    // Frame join − half + m moves with v + step·(ramp − [after the join]).
    let change = |m: usize| {
        let ramp = (m as f32 + 0.5) / span as f32;
        let after = if m >= half { 1.0 } else { 0.0 };
        step * (ramp - after)
    };
    // The ramp redistributes a change of velocity, but where the root's own velocity varies
    // within the window (a jump's landing, its squat before it) a full ramp adds the step to
    // speeds already high: the root would outrun a person. The step is eased as far as keeps
    // every frame within `top` (or the fastest the root already moved there): all of it, in
    // the common case.
    let own: Vec<Vec3> = (0..span)
        .map(|m| root(join - half + m + 1) - root(join - half + m))
        .collect();
    let fastest = own.iter().map(|v| v.length()).fold(top, f32::max);
    let within =
        |s: f32| (0..span).all(|m| (own[m] + change(m) * s).length() <= fastest * (1.0 + 1e-4));
    let share = if within(1.0) {
        1.0
    } else {
        let (mut ok, mut bad) = (0.0f32, 1.0f32);
        for _ in 0..EASE_BISECTIONS {
            let mid = 0.5 * (ok + bad);
            if within(mid) {
                ok = mid;
            } else {
                bad = mid;
            }
        }
        ok
    };
    let mut shift = Vec3::ZERO;
    for m in 0..span {
        shift += change(m) * share;
        if let Some(t) = frames[join - half + m + 1].translations.first_mut() {
            *t += shift;
        }
    }
}

/// Frames over which [`calm_root`]'s smoothing fades out beyond the frames it judges.
pub const CALM_FADE: usize = 3;
/// Most smoothing passes [`calm_root`] makes about one join.
pub const CALM_PASSES: usize = 60;

/// Smooths the root's path about frame `join` of `frames` until its acceleration (second
/// difference, distance per frame²) within `reach` frames of the join is at most `most`:
/// each pass moves every root there towards the mean of its neighbours ([1, 2, 1] / 4), fully
/// within `reach + 1` frames of the join and fading out over [`CALM_FADE`] frames beyond. An
/// action cut mid-hop (a sudden turn's bob, a strong jump's squat) no longer shows its sharpest
/// motion at the cut; it settles into the next one as a person's hips do, the rest of it as it
/// was. Returns the passes made.
pub fn calm_root(frames: &mut [Pose], join: usize, reach: usize, most: f32) -> usize {
    let n = frames.len();
    let root = |frames: &[Pose], f: usize| {
        frames[f]
            .translations
            .first()
            .copied()
            .unwrap_or(Vec3::ZERO)
    };
    let accel = |frames: &[Pose], f: usize| {
        (root(frames, f + 1) - 2.0 * root(frames, f) + root(frames, f - 1)).length()
    };
    let judged = join.saturating_sub(reach).max(1)..=(join + reach).min(n.saturating_sub(2));
    let full = reach + 1;
    let lo = join.saturating_sub(full + CALM_FADE).max(1);
    let hi = (join + full + CALM_FADE).min(n.saturating_sub(2));
    if judged.is_empty() || lo > hi {
        return 0;
    }
    let mut passes = 0;
    while passes < CALM_PASSES && judged.clone().any(|f| accel(frames, f) > most) {
        let before: Vec<Vec3> = (lo - 1..=hi + 1).map(|f| root(frames, f)).collect();
        for (f, pose) in frames.iter_mut().enumerate().take(hi + 1).skip(lo) {
            let d = f.abs_diff(join);
            let weight = if d <= full {
                1.0
            } else {
                1.0 - (d - full) as f32 / (CALM_FADE + 1) as f32
            };
            let k = f - (lo - 1);
            let mean = (before[k - 1] + 2.0 * before[k] + before[k + 1]) * 0.25;
            if let Some(t) = pose.translations.first_mut() {
                *t += (mean - before[k]) * weight;
            }
        }
        passes += 1;
    }
    passes
}

/// Bisection steps of [`ease_root`]'s share of a step that keeps the root within its speed.
const EASE_BISECTIONS: usize = 12;

/// Blends two world-placed poses (root translation and rotation are world values).
pub fn blend_world(a: &Pose, b: &Pose, w: f32) -> Pose {
    let mut out = a.blend(b, w);
    if let (Some(qa), Some(qb)) = (a.rotations.first(), b.rotations.first()) {
        out.rotations[0] = slerp_short(*qa, *qb, w);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn alignment_recovers_a_rigid_ground_motion() {
        let a: Vec<Vec3> = (0..20)
            .map(|i| {
                Vec3::new(
                    (i as f32 * 0.7).sin(),
                    i as f32 * 0.1,
                    (i as f32 * 1.3).cos() * 2.0,
                )
            })
            .collect();
        let r = Quat::from_rotation_y(0.8);
        let b: Vec<Vec3> = a
            .iter()
            .map(|p| r * *p + Vec3::new(3.0, 0.0, -1.0))
            .collect();
        let (d, theta, _, _) = aligned_distance(&a, &b);
        assert!(d < 1e-6, "{d}");
        assert!((theta + 0.8).abs() < 1e-4, "{theta}");
        // A vertical offset is not forgiven.
        let c: Vec<Vec3> = a.iter().map(|p| *p + Vec3::Y).collect();
        assert!((aligned_distance(&a, &c).0 - 20.0).abs() < 1e-3);
    }

    /// The root's acceleration (finite differences, per frame²) at every inner frame.
    fn accel(frames: &[Pose]) -> Vec<f32> {
        frames
            .windows(3)
            .map(|w| {
                (w[2].translations[0] - 2.0 * w[1].translations[0] + w[0].translations[0]).length()
            })
            .collect()
    }

    #[test]
    fn easing_spreads_a_jump_of_velocity_and_keeps_steady_motion() {
        // Standing for 20 frames, then moving 0.1 per frame.
        let pose = |x: f32| Pose {
            rotations: vec![Quat::IDENTITY],
            translations: vec![Vec3::new(x, 1.0, 0.0)],
        };
        let track: Vec<Pose> = (0..50)
            .map(|f| pose(0.1 * (f as f32 - 20.0).max(0.0)))
            .collect();
        let before = accel(&track).into_iter().fold(0.0f32, f32::max);
        assert!((before - 0.1).abs() < 1e-5, "{before}");
        let mut eased = track.clone();
        ease_root(&mut eased, 20, 5, 0.1);
        let after = accel(&eased).into_iter().fold(0.0f32, f32::max);
        // The 0.1 step is spread over 10 frames.
        assert!(after <= 0.1 / 10.0 + 1e-4, "{after}");
        // Away from the join nothing moves.
        for f in (0..16).chain(26..50) {
            assert!(
                (eased[f].translations[0] - track[f].translations[0]).length() < 1e-5,
                "frame {f}"
            );
        }
        // Nowhere further from the original path than |Δv|·half/4.
        let off = eased
            .iter()
            .zip(&track)
            .map(|(a, b)| (a.translations[0] - b.translations[0]).length())
            .fold(0.0f32, f32::max);
        assert!(off <= 0.1 * 5.0 / 4.0 + 1e-4, "{off}");
        // A bob on top of the step is kept: only the step is eased.
        let bob = |f: usize| 0.05 * (f as f32 * 0.9).sin();
        let mut bobbing = track.clone();
        for (f, p) in bobbing.iter_mut().enumerate() {
            p.translations[0].y += bob(f);
        }
        ease_root(&mut bobbing, 20, 5, 0.1);
        for (f, (a, b)) in bobbing.iter().zip(&eased).enumerate() {
            let d = a.translations[0] - b.translations[0];
            assert!(
                (d.x).abs() < 1e-5 && (d.y - bob(f)).abs() < 0.06,
                "frame {f}: {d}"
            );
        }
    }

    /// The root's fastest speed (per frame) over `frames`.
    fn fastest(frames: &[Pose]) -> f32 {
        frames
            .windows(2)
            .map(|w| (w[1].translations[0] - w[0].translations[0]).length())
            .fold(0.0f32, f32::max)
    }

    #[test]
    fn easing_never_makes_the_root_outrun_its_top_speed() {
        // Rising at 0.1 per frame, a frame's dwell at frame 20, rising again: the stop's step
        // (−0.1) ramped over 10 frames gives back its +0.1 to the frames after the dwell, which
        // already rise at 0.1.
        let pose = |y: f32| Pose {
            rotations: vec![Quat::IDENTITY],
            translations: vec![Vec3::new(0.0, y, 0.0)],
        };
        let track: Vec<Pose> = (0..50)
            .map(|f| {
                let f = f as f32;
                pose(0.1 * f.min(20.0) + 0.1 * (f - 21.0).max(0.0))
            })
            .collect();
        assert!((fastest(&track) - 0.1).abs() < 1e-5);
        // Unbounded, the ramp moves the root faster than 0.12 per frame …
        let mut free = track.clone();
        ease_root(&mut free, 20, 5, f32::INFINITY);
        assert!(fastest(&free) > 0.13, "{}", fastest(&free));
        // … bounded by 0.12, it eases as much of the step as keeps within it.
        let mut held = track.clone();
        ease_root(&mut held, 20, 5, 0.12);
        assert!(fastest(&held) <= 0.12 + 1e-4, "{}", fastest(&held));
        let moved = held
            .iter()
            .zip(&track)
            .map(|(a, b)| (a.translations[0] - b.translations[0]).length())
            .fold(0.0f32, f32::max);
        assert!(moved > 0.01, "{moved}");
    }

    #[test]
    fn best_pair_finds_the_matching_frames() {
        // A: a point moving up then down; B: the same, shifted by 7 frames, elsewhere.
        let f = |t: f32| {
            vec![
                Vec3::new(0.0, (t * 0.3).sin(), 0.0),
                Vec3::new(1.0, (t * 0.2).cos(), 0.5),
            ]
        };
        let a: Vec<Vec<Vec3>> = (0..40).map(|i| f(i as f32)).collect();
        let b: Vec<Vec<Vec3>> = (0..40)
            .map(|i| {
                f(i as f32 + 7.0)
                    .into_iter()
                    .map(|p| p + Vec3::new(5.0, 0.0, 2.0))
                    .collect()
            })
            .collect();
        let (i, j, d) = best_pair(&a, 20..=30, &b, 10..=20).unwrap();
        assert_eq!(i, j + 7, "{i} {j} {d}");
        assert!(d < 1e-4);
    }

    #[test]
    fn a_root_cut_mid_hop_settles_about_the_join_and_is_left_alone_elsewhere() {
        // A root hopping 10 cm every 6 frames: about 1.1 cm per frame² at each turn.
        let mut frames: Vec<Pose> = (0..60)
            .map(|f| {
                let mut p = Pose {
                    rotations: vec![glam::Quat::IDENTITY],
                    translations: vec![Vec3::ZERO],
                };
                let phase = (f % 6) as f32 / 6.0;
                p.translations[0] =
                    Vec3::new(0.0, 0.9 + 0.1 * (1.0 - (2.0 * phase - 1.0).abs()), 0.0);
                p
            })
            .collect();
        let before: Vec<Vec3> = frames.iter().map(|p| p.translations[0]).collect();
        let accel = |fr: &[Pose], f: usize| {
            (fr[f + 1].translations[0] - 2.0 * fr[f].translations[0] + fr[f - 1].translations[0])
                .length()
        };
        assert!(accel(&frames, 30) > 0.03);
        let passes = calm_root(&mut frames, 30, 2, 0.005);
        assert!(passes > 0 && passes < CALM_PASSES, "{passes}");
        for f in 28..=32 {
            assert!(
                accel(&frames, f) <= 0.005,
                "frame {f}: {}",
                accel(&frames, f)
            );
        }
        // Beyond the fade the hop is as it was.
        for f in (0..20).chain(41..60) {
            assert_eq!(frames[f].translations[0], before[f], "frame {f}");
        }
    }
}
