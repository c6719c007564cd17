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

/// The pair (i in `range_a`, j in `range_b`) with the least windowed posture distance.
pub fn best_pair(
    a: &[Vec<Vec3>],
    range_a: std::ops::RangeInclusive<usize>,
    b: &[Vec<Vec3>],
    range_b: std::ops::RangeInclusive<usize>,
) -> Option<(usize, usize, f32)> {
    let mut best: Option<(usize, usize, f32)> = None;
    for i in range_a.clone() {
        if i >= a.len() {
            break;
        }
        for j in range_b.clone() {
            if j >= b.len() {
                break;
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
}
