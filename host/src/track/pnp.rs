//! The tag's pose from its four corners: a homography from the tag's plane to the image,
//! decomposed into a first pose, then refined (Levenberg–Marquardt on the 8 reprojection
//! residuals). A flat square seen from afar has two poses that explain its corners almost
//! equally — tilted toward or away from the line of sight — so both are refined, and a near
//! tie goes to the one nearer the previous frame's orientation.

use glam::{DMat3, DQuat, DVec2, DVec3};

use super::detect::{CameraPose, Intrinsics};

/// Two poses whose reprojection errors are within this factor (and [`TIE_PX`]) are a tie:
/// near face-on, sensor noise alone reorders them from frame to frame, and taking the lower
/// one each time flips the tilt by degrees between still frames.
const TIE_FACTOR: f64 = 3.0;
/// Absolute slack of a tie, pixels RMS.
const TIE_PX: f64 = 0.3;

/// The corners' positions on the tag plane (metres, tag frame: x right, y down as printed),
/// in the detector's order: counter-clockwise in the image from the printed bottom-left.
pub fn object_corners(size: f64) -> [DVec3; 4] {
    let s = size / 2.0;
    [
        DVec3::new(-s, s, 0.0),
        DVec3::new(s, s, 0.0),
        DVec3::new(s, -s, 0.0),
        DVec3::new(-s, -s, 0.0),
    ]
}

/// Solves a small dense linear system `a x = b` by Gaussian elimination with partial
/// pivoting; `None` when singular.
pub fn solve_linear<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> Option<[f64; N]> {
    for col in 0..N {
        let piv = (col..N).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-14 {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        let pivot_row = a[col];
        for row in col + 1..N {
            let f = a[row][col] / pivot_row[col];
            for (v, p) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *v -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; N];
    for row in (0..N).rev() {
        let mut s = b[row];
        for k in row + 1..N {
            s -= a[row][k] * x[k];
        }
        x[row] = s / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The homography taking plane points (x, y, 1) to normalised image points, from four
/// correspondences.
fn homography(plane: &[DVec3; 4], image: &[DVec2; 4]) -> Option<DMat3> {
    let mut a = [[0.0; 8]; 8];
    let mut b = [0.0; 8];
    for i in 0..4 {
        let (x, y) = (plane[i].x, plane[i].y);
        let (u, v) = (image[i].x, image[i].y);
        a[2 * i] = [x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y];
        b[2 * i] = u;
        a[2 * i + 1] = [0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y];
        b[2 * i + 1] = v;
    }
    let h = solve_linear(a, b)?;
    Some(DMat3::from_cols(
        DVec3::new(h[0], h[3], h[6]),
        DVec3::new(h[1], h[4], h[7]),
        DVec3::new(h[2], h[5], 1.0),
    ))
}

/// A rotation and translation from a plane homography `H = λ [r1 r2 t]`.
fn pose_from_homography(h: DMat3) -> Option<(DQuat, DVec3)> {
    let scale = 2.0 / (h.x_axis.length() + h.y_axis.length());
    // The tag is in front of the camera: t.z > 0 fixes λ's sign.
    let sign = if h.z_axis.z < 0.0 { -1.0 } else { 1.0 };
    let (r1, r2, t) = (
        h.x_axis * scale * sign,
        h.y_axis * scale * sign,
        h.z_axis * scale * sign,
    );
    let r1n = r1.try_normalize()?;
    let r2n = (r2 - r1n * r1n.dot(r2)).try_normalize()?;
    let r = DMat3::from_cols(r1n, r2n, r1n.cross(r2n));
    Some((DQuat::from_mat3(&r).normalize(), t))
}

/// Reprojection residuals (pixels) of the points under pose (q, t): x and y per point.
fn residuals(q: DQuat, t: DVec3, obj: &[DVec3], px: &[DVec2], k: &Intrinsics) -> Vec<f64> {
    let mut r = Vec::with_capacity(2 * obj.len());
    for (o, p) in obj.iter().zip(px) {
        let c = q * *o + t;
        let z = c.z.max(1e-6);
        r.push(k.cx + k.fx * c.x / z - p.x);
        r.push(k.cy + k.fy * c.y / z - p.y);
    }
    r
}

/// RMS reprojection error per point, pixels.
fn rms(r: &[f64]) -> f64 {
    (r.iter().map(|v| v * v).sum::<f64>() / (r.len() / 2).max(1) as f64).sqrt()
}

/// How [`least_squares`] searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Search {
    /// Most Levenberg–Marquardt steps.
    pub steps: usize,
    /// Tries per step, the damping ten times larger after each that did not lower the cost.
    pub tries: usize,
    /// Damping at the start, and the least it falls to (×0.3 after each step taken).
    pub damping: (f64, f64),
    /// Least fall in cost for a step to count as progress: below it the search stops.
    pub min_gain: f64,
}

/// The residuals' derivatives by each of a pose's six parameters — a rotation vector on the
/// left (radians), then the translation (metres) — one column each.
pub type Jacobian = [Vec<f64>; 6];

/// [`Jacobian`] by forward differences from the residuals `r` at (q, t): steps of `h.0`
/// radians and `h.1` metres. `None` when a stepped pose has no residuals.
pub fn numerical_jacobian(
    residuals: &impl Fn(DQuat, DVec3) -> Option<Vec<f64>>,
    q: DQuat,
    t: DVec3,
    r: &[f64],
    h: (f64, f64),
) -> Option<Jacobian> {
    let mut jac: Jacobian = Default::default();
    for (j, col) in jac.iter_mut().enumerate() {
        let h = if j < 3 { h.0 } else { h.1 };
        let mut d = [0.0; 6];
        d[j] = h;
        let (q1, t1) = step(q, t, &d);
        let r1 = residuals(q1, t1)?;
        *col = r1.iter().zip(r).map(|(a, b)| (a - b) / h).collect();
    }
    Some(jac)
}

/// Levenberg–Marquardt on a pose — a rotation-vector step on the left, and the translation:
/// lowers `cost` of the `residuals` a pose gives, the `jacobian` of them at a pose (given its
/// residuals) guiding each step, taking a step only where they exist, the cost falls and
/// `accept` takes the new translation. Returns the pose and its residuals; `None` when the
/// start or a Jacobian cannot be had.
pub fn least_squares(
    mut q: DQuat,
    mut t: DVec3,
    search: &Search,
    residuals: impl Fn(DQuat, DVec3) -> Option<Vec<f64>>,
    jacobian: impl Fn(DQuat, DVec3, &[f64]) -> Option<Jacobian>,
    cost_of: impl Fn(&[f64]) -> f64,
    accept: impl Fn(DVec3) -> bool,
) -> Option<(DQuat, DVec3, Vec<f64>)> {
    let mut r = residuals(q, t)?;
    let mut cost = cost_of(&r);
    let mut mu = search.damping.0;
    for _ in 0..search.steps {
        let jac = jacobian(q, t, &r)?;
        let mut jtj = [[0.0; 6]; 6];
        let mut jtr = [0.0; 6];
        for a in 0..6 {
            for b in 0..6 {
                jtj[a][b] = jac[a].iter().zip(&jac[b]).map(|(x, y)| x * y).sum();
            }
            jtr[a] = -jac[a].iter().zip(&r).map(|(x, y)| x * y).sum::<f64>();
        }
        let mut improved = false;
        for _ in 0..search.tries {
            let mut damped = jtj;
            for (a, row) in damped.iter_mut().enumerate() {
                row[a] += mu * jtj[a][a].max(1e-9);
            }
            let Some(d) = solve_linear(damped, jtr) else {
                mu *= 10.0;
                continue;
            };
            let (q1, t1) = step(q, t, &d);
            if let Some(r1) = residuals(q1, t1) {
                let c1 = cost_of(&r1);
                if c1 < cost && accept(t1) {
                    improved = cost - c1 > search.min_gain;
                    (q, t, r, cost) = (q1, t1, r1, c1);
                    mu = (mu * 0.3).max(search.damping.1);
                    break;
                }
            }
            mu *= 10.0;
        }
        if !improved {
            break;
        }
    }
    Some((q, t, r))
}

/// Pose (q, t) moved by a rotation vector `d[0..3]` (on the left) and a translation `d[3..6]`.
fn step(q: DQuat, t: DVec3, d: &[f64; 6]) -> (DQuat, DVec3) {
    let w = DVec3::new(d[0], d[1], d[2]);
    let dq = if w.length() > 0.0 {
        DQuat::from_scaled_axis(w)
    } else {
        DQuat::IDENTITY
    };
    ((dq * q).normalize(), t + DVec3::new(d[3], d[4], d[5]))
}

/// How [`refine`] searches: up to 30 steps from a corner fit's pose.
const CORNER_SEARCH: Search = Search {
    steps: 30,
    tries: 8,
    damping: (1e-3, 1e-9),
    min_gain: 1e-9,
};
/// Forward-difference steps of [`refine`]'s Jacobian: a microradian, a tenth of a micrometre.
const CORNER_H: (f64, f64) = (1e-6, 1e-7);

/// Levenberg–Marquardt on a pose that takes object points `obj` (metres) to pixels `px`
/// ([`least_squares`] on the reprojection error); returns the refined pose and its RMS point
/// error in pixels. Four corners of one tag, or the corners of every tag of a rig in sight
/// (points on several planes: no mirror pose to confuse).
pub fn refine(
    q: DQuat,
    t: DVec3,
    obj: &[DVec3],
    px: &[DVec2],
    k: &Intrinsics,
) -> (DQuat, DVec3, f64) {
    let misfit = |q, t| Some(residuals(q, t, obj, px, k));
    let fit = least_squares(
        q,
        t,
        &CORNER_SEARCH,
        misfit,
        |q, t, r: &[f64]| numerical_jacobian(&misfit, q, t, r, CORNER_H),
        rms,
        |t| t.z > 0.0,
    );
    match fit {
        Some((q, t, r)) => (q, t, rms(&r)),
        None => (q, t, f64::INFINITY),
    }
}

/// The other pose a flat square nearly equally explains: its normal mirrored about the line
/// of sight.
fn mirrored(q: DQuat, t: DVec3) -> Option<DQuat> {
    let v = t.try_normalize()?;
    let n = q * DVec3::Z;
    let n2 = 2.0 * n.dot(v) * v - n;
    let turn = DQuat::from_rotation_arc(n, n2.try_normalize()?);
    Some((turn * q).normalize())
}

/// Both poses a flat square's corners admit (pixels, detector order; edge `size` metres): the
/// homography's, refined, and its mirror about the line of sight, refined — the better fit
/// first, each with its RMS corner reprojection error in pixels. When both refinements settle
/// in one pose, the mirror is kept unrefined, with its own error: near face-on a frame's
/// noise can leave one basin where the next frame has two, and the pose across the line of
/// sight stays the other answer to weigh over time ([`super::mirror`]). One pose when the
/// mirror does not exist (a tag square to the line of sight through its centre) or failed.
pub fn solve_candidates(corners: &[[f64; 2]; 4], size: f64, k: &Intrinsics) -> Vec<CameraPose> {
    let obj = object_corners(size);
    let px: [DVec2; 4] = corners.map(|c| DVec2::new(c[0], c[1]));
    let norm = px.map(|p| DVec2::new((p.x - k.cx) / k.fx, (p.y - k.cy) / k.fy));
    let Some((q0, t0)) = homography(&obj, &norm).and_then(pose_from_homography) else {
        return Vec::new();
    };
    let first = refine(q0, t0, &obj, &px, k);
    let mirror = mirrored(first.0, first.1);
    let (first, second) = match mirror.map(|qm| refine(qm, first.1, &obj, &px, k)) {
        // Both refinements may settle in the same pose (the mirror's basin drained into the
        // other's): the better of the two, and the mirror itself, unrefined, as the second.
        Some(r) if r.0.dot(first.0).abs() > 1.0 - 1e-9 => (
            if r.2 < first.2 { r } else { first },
            mirror.map(|qm| (qm, first.1, rms(&residuals(qm, first.1, &obj, &px, k)))),
        ),
        other => (first, other),
    };
    let mut out: Vec<CameraPose> = [Some(first), second]
        .into_iter()
        .flatten()
        .filter(|(q, t, err)| err.is_finite() && t.is_finite() && q.is_finite())
        .map(|(q, t, err)| CameraPose::from_parts(DMat3::from_quat(q), t, err))
        .collect();
    out.sort_by(|a, b| a.error.total_cmp(&b.error));
    out
}

/// The tag's pose from its corners (pixels, detector order), its edge `size` (metres) and the
/// camera; `previous` (the last tag→camera rotation) breaks near ties. The error is the RMS
/// corner reprojection error in pixels.
pub fn solve_pose(
    corners: &[[f64; 2]; 4],
    size: f64,
    k: &Intrinsics,
    previous: Option<DQuat>,
) -> Option<CameraPose> {
    let both = solve_candidates(corners, size, k);
    let (lo, hi) = (both.first()?, both.get(1));
    match (hi, previous) {
        (Some(hi), Some(prev))
            if hi.error <= lo.error * TIE_FACTOR + TIE_PX
                && hi.quat().dot(prev).abs() > lo.quat().dot(prev).abs() =>
        {
            Some(*hi)
        }
        _ => Some(*lo),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::pose::intrinsics_from_fov;

    fn corners(q: DQuat, t: DVec3, size: f64, k: &Intrinsics) -> [[f64; 2]; 4] {
        object_corners(size).map(|p| {
            let c = q * p + t;
            [k.cx + k.fx * c.x / c.z, k.cy + k.fy * c.y / c.z]
        })
    }

    #[test]
    fn exact_corners_give_the_exact_pose() {
        let k = intrinsics_from_fov(640, 480, 60.0);
        for (q, t) in [
            (
                DQuat::from_euler(glam::EulerRot::YXZ, 0.5, -0.4, 0.3),
                DVec3::new(0.05, -0.02, 0.6),
            ),
            (DQuat::from_rotation_y(1.0), DVec3::new(-0.1, 0.05, 1.0)),
            (DQuat::IDENTITY, DVec3::new(0.0, 0.0, 0.3)),
        ] {
            let c = corners(q, t, 0.04, &k);
            let p = solve_pose(&c, 0.04, &k, Some(q)).unwrap();
            let t2 = DVec3::from_array(p.translation);
            assert!((t2 - t).length() < 1e-6, "{t2} vs {t}");
            let r = p.rotation;
            let m = DMat3::from_cols(
                DVec3::new(r[0][0], r[1][0], r[2][0]),
                DVec3::new(r[0][1], r[1][1], r[2][1]),
                DVec3::new(r[0][2], r[1][2], r[2][2]),
            );
            let q2 = DQuat::from_mat3(&m);
            assert!(q2.dot(q).abs() > 1.0 - 1e-9);
            assert!(p.error < 1e-6);
        }
    }

    #[test]
    fn degenerate_corners_give_no_pose() {
        let k = intrinsics_from_fov(640, 480, 60.0);
        assert!(solve_pose(&[[10.0, 10.0]; 4], 0.04, &k, None).is_none());
    }
}
