//! Posture distance (seed 003 eq. 1, after Kovar et al.): the weighted squared distance between
//! two windows' point clouds after the best rotation about the vertical and floor translation.
//!
//! With uniform weights, centring both clouds horizontally removes the translation, and the best
//! rotation θ about +y maximises `a cos θ + b sin θ`, where
//! `a = Σ (x x' + z z') − W (x̄ x̄' + z̄ z̄')` and `b = Σ (x z' − z x') − W (x̄ z̄' − z̄ x̄')`,
//! so the minimum is closed-form without any trigonometry:
//!
//! `d = (S + S' − 2 (Σ y y' + √(a² + b²))) / W`, with `S = Σ ‖p‖² − W (x̄² + z̄²)`,
//!
//! W = number of points (35 frames × 16 role points). `d` is a mean squared distance per point
//! in m² (analysis metres). θ = atan2(b, a) and `(x₀, z₀) = (x̄, z̄) − R_θ (x̄', z̄')` are only
//! evaluated for the transitions kept. The build stage ([`super::build`]) computes the sums
//! Σ x x' … for all window pairs as tiled dot products; this module holds the per-window terms
//! and the reference implementation the tests check it against.

use glam::Vec3;

use super::roles::Role;
use super::WINDOW;

/// Number of points in one window's cloud.
pub const POINTS: usize = WINDOW * Role::COUNT;

/// A rotation about +y followed by a floor translation (x₀, z₀).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Alignment {
    /// Rotation about +y, radians (right-handed: +x turns towards −z).
    pub theta: f32,
    /// Translation along x, in the unit of the points it was computed from.
    pub x0: f32,
    /// Translation along z, same unit.
    pub z0: f32,
}

impl Alignment {
    /// Applies the rotation and translation to a point.
    pub fn apply(&self, p: Vec3) -> Vec3 {
        let (s, c) = self.theta.sin_cos();
        Vec3::new(
            c * p.x + s * p.z + self.x0,
            p.y,
            -s * p.x + c * p.z + self.z0,
        )
    }

    /// The rotation as a quaternion (to pre-multiply a root orientation).
    pub fn rotation(&self) -> glam::Quat {
        glam::Quat::from_rotation_y(self.theta)
    }
}

/// Per-window terms of the closed form: horizontal means and centred squared norm.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WindowTerms {
    /// Mean x of the window's points, m.
    pub mx: f32,
    /// Mean z of the window's points, m.
    pub mz: f32,
    /// Σ‖p‖² − W (x̄² + z̄²), m².
    pub sq: f32,
}

/// Window terms for every window of a frame sequence (window `w` covers frames `w..w+WINDOW`).
pub fn window_terms(frames: &[[Vec3; Role::COUNT]]) -> Vec<WindowTerms> {
    if frames.len() < WINDOW {
        return Vec::new();
    }
    // Per-frame sums, then sliding window sums in f64 (no drift).
    let per: Vec<[f64; 3]> = frames
        .iter()
        .map(|f| {
            let mut s = [0.0f64; 3];
            for p in f {
                s[0] += p.x as f64;
                s[1] += p.z as f64;
                s[2] += p.length_squared() as f64;
            }
            s
        })
        .collect();
    let mut acc = [0.0f64; 3];
    for s in &per[..WINDOW] {
        for k in 0..3 {
            acc[k] += s[k];
        }
    }
    let w = POINTS as f64;
    let mut out = Vec::with_capacity(frames.len() - WINDOW + 1);
    for start in 0..=frames.len() - WINDOW {
        if start > 0 {
            for k in 0..3 {
                acc[k] += per[start + WINDOW - 1][k] - per[start - 1][k];
            }
        }
        let mx = acc[0] / w;
        let mz = acc[1] / w;
        out.push(WindowTerms {
            mx: mx as f32,
            mz: mz as f32,
            sq: (acc[2] - w * (mx * mx + mz * mz)).max(0.0) as f32,
        });
    }
    out
}

/// Closed-form distance from the cross sums of two windows (see the module doc).
///
/// `sa = Σ (x x' + z z')`, `sb = Σ (x z' − z x')`, `syy = Σ y y'` over the W point pairs.
/// Returns the mean squared distance per point (m²) and the optimal θ's (cos-part, sin-part).
#[inline]
pub fn closed_form(
    t: &WindowTerms,
    u: &WindowTerms,
    sa: f32,
    sb: f32,
    syy: f32,
) -> (f32, f32, f32) {
    let w = POINTS as f32;
    let a = sa - w * (t.mx * u.mx + t.mz * u.mz);
    let b = sb - w * (t.mx * u.mz - t.mz * u.mx);
    let d = (t.sq + u.sq - 2.0 * (syy + (a * a + b * b).sqrt())) / w;
    (d.max(0.0), a, b)
}

/// Eq. 1 for two windows given directly as frames: the alignment taking `b` onto `a` and the
/// mean squared distance per point after it (m²). Reference implementation (f64 sums).
pub fn align_windows(a: &[[Vec3; Role::COUNT]], b: &[[Vec3; Role::COUNT]]) -> (Alignment, f32) {
    let n = a.len().min(b.len()) * Role::COUNT;
    if n == 0 {
        return (Alignment::default(), 0.0);
    }
    let pairs = a
        .iter()
        .zip(b)
        .flat_map(|(fa, fb)| fa.iter().zip(fb.iter()));
    let (mut sx, mut sz, mut sx2, mut sz2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (mut sa, mut sb, mut syy, mut s1, mut s2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (p, q) in pairs {
        let (x, y, z) = (p.x as f64, p.y as f64, p.z as f64);
        let (x2, y2, z2) = (q.x as f64, q.y as f64, q.z as f64);
        sx += x;
        sz += z;
        sx2 += x2;
        sz2 += z2;
        sa += x * x2 + z * z2;
        sb += x * z2 - z * x2;
        syy += y * y2;
        s1 += x * x + y * y + z * z;
        s2 += x2 * x2 + y2 * y2 + z2 * z2;
    }
    let w = n as f64;
    let (mx, mz, mx2, mz2) = (sx / w, sz / w, sx2 / w, sz2 / w);
    let ca = sa - w * (mx * mx2 + mz * mz2);
    let cb = sb - w * (mx * mz2 - mz * mx2);
    let c1 = s1 - w * (mx * mx + mz * mz);
    let c2 = s2 - w * (mx2 * mx2 + mz2 * mz2);
    let d = ((c1 + c2 - 2.0 * (syy + (ca * ca + cb * cb).sqrt())) / w).max(0.0);
    let theta = cb.atan2(ca);
    let (s, c) = theta.sin_cos();
    let x0 = mx - (c * mx2 + s * mz2);
    let z0 = mz - (-s * mx2 + c * mz2);
    (
        Alignment {
            theta: theta as f32,
            x0: x0 as f32,
            z0: z0 as f32,
        },
        d as f32,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud(seed: u32, frames: usize) -> Vec<[Vec3; Role::COUNT]> {
        let mut s = seed.wrapping_mul(2654435761).wrapping_add(1);
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s as f32 / u32::MAX as f32) - 0.5
        };
        (0..frames)
            .map(|_| {
                let mut f = [Vec3::ZERO; Role::COUNT];
                for v in &mut f {
                    *v = Vec3::new(rnd() * 2.0, rnd() + 1.0, rnd() * 2.0);
                }
                f
            })
            .collect()
    }

    #[test]
    fn rigidly_moved_window_has_zero_distance_and_recovers_transform() {
        let a = cloud(1, WINDOW);
        let t = Alignment {
            theta: 0.7,
            x0: 3.0,
            z0: -1.5,
        };
        let b: Vec<_> = a.iter().map(|f| f.map(|p| t.apply(p))).collect();
        let (al, d) = align_windows(&a, &b);
        assert!(d < 1e-6, "{d}");
        for (fa, fb) in a.iter().zip(&b) {
            for (p, q) in fa.iter().zip(fb) {
                assert!((al.apply(*q) - *p).length() < 1e-3);
            }
        }
    }

    #[test]
    fn closed_form_is_the_minimum_over_a_grid_of_rotations() {
        let a = cloud(2, WINDOW);
        let b = cloud(3, WINDOW);
        let (al, d) = align_windows(&a, &b);
        let cost = |theta: f32| {
            let mut t = Alignment {
                theta,
                x0: 0.0,
                z0: 0.0,
            };
            let ma: Vec3 = a.iter().flatten().copied().sum::<Vec3>() / POINTS as f32;
            let mb: Vec3 = b.iter().flatten().map(|p| t.apply(*p)).sum::<Vec3>() / POINTS as f32;
            t.x0 = ma.x - mb.x;
            t.z0 = ma.z - mb.z;
            a.iter()
                .flatten()
                .zip(b.iter().flatten())
                .map(|(p, q)| (t.apply(*q) - *p).length_squared())
                .sum::<f32>()
                / POINTS as f32
        };
        let best = (0..3600)
            .map(|k| cost(k as f32 * std::f32::consts::TAU / 3600.0))
            .fold(f32::INFINITY, f32::min);
        assert!((best - d).abs() < 1e-3 * best.max(1.0), "{best} vs {d}");
        assert!((cost(al.theta) - d).abs() < 1e-3 * d.max(1.0));
    }

    #[test]
    fn window_terms_and_closed_form_match_reference() {
        let a = cloud(4, WINDOW + 3);
        let b = cloud(5, WINDOW + 2);
        let ta = window_terms(&a);
        let tb = window_terms(&b);
        assert_eq!(ta.len(), 4);
        for (i, t) in ta.iter().enumerate() {
            for (j, u) in tb.iter().enumerate() {
                let (mut sa, mut sb, mut syy) = (0.0f32, 0.0f32, 0.0f32);
                for k in 0..WINDOW {
                    for (p, q) in a[i + k].iter().zip(&b[j + k]) {
                        sa += p.x * q.x + p.z * q.z;
                        sb += p.x * q.z - p.z * q.x;
                        syy += p.y * q.y;
                    }
                }
                let (d, _, _) = closed_form(t, u, sa, sb, syy);
                let (_, r) = align_windows(&a[i..i + WINDOW], &b[j..j + WINDOW]);
                assert!((d - r).abs() < 1e-3 * r.max(1.0), "{d} vs {r}");
            }
        }
    }
}
