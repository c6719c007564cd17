//! Trajectory transfer (seed 000 §6.2): the doodle, projected to the ground and mapped from toy
//! scale to the character's world, cut into one path per action.
//!
//! The figurine's position (metres, +Y up) is projected onto the ground plane (x, z), taken
//! relative to the first sample and multiplied by the world scale (default
//! [`DEFAULT_WORLD_SCALE`]: a 15 cm figurine stands for a 1.7 m character, so toy metres ×
//! 10 ≈ character metres; `--world-scale` overrides it). The scale sets the path's size
//! wherever a person can cover it in the doodle's time: a moving action whose path would need
//! a faster pace than its gait allows has its path shrunk about its start (the assembler's
//! `pace`), the doodle's shape and timing kept. Each action's path starts where the
//! character stands: the doodle's displacement during in-place actions and between actions
//! is dropped, which is the seed's spatial offset `s_off`.

use glam::{Quat, Vec2, Vec3};

use crate::poselog::PoseLog;

/// Toy metres → character metres.
pub const DEFAULT_WORLD_SCALE: f32 = 10.0;
/// Moving-average half window (samples) applied to the projected doodle against tremor.
pub const SMOOTH_HALF: usize = 2;

/// The projected, scaled doodle: times (seconds, log clock) and ground points (x, z metres).
#[derive(Debug, Clone, Default)]
pub struct GroundPath {
    /// Sample times, strictly increasing.
    pub t: Vec<f32>,
    /// Ground points (x, z) in character metres, relative to the first sample.
    pub p: Vec<Vec2>,
}

impl GroundPath {
    /// Projects a pose log; samples with non-finite values or non-increasing time are dropped.
    pub fn from_log(log: &PoseLog, world_scale: f32) -> GroundPath {
        let mut t: Vec<f32> = Vec::with_capacity(log.samples.len());
        let mut raw: Vec<Vec2> = Vec::with_capacity(log.samples.len());
        for s in &log.samples {
            let ok = s.t.is_finite() && s.pos.iter().all(|v| v.is_finite());
            if !ok || t.last().is_some_and(|&last| s.t as f32 <= last) {
                continue;
            }
            t.push(s.t as f32);
            raw.push(Vec2::new(s.pos[0] as f32, s.pos[2] as f32));
        }
        let origin = raw.first().copied().unwrap_or(Vec2::ZERO);
        let n = raw.len();
        let p = (0..n)
            .map(|i| {
                let a = i.saturating_sub(SMOOTH_HALF);
                let b = (i + SMOOTH_HALF).min(n - 1);
                let s: Vec2 = raw[a..=b].iter().copied().sum();
                (s / (b - a + 1) as f32 - origin) * world_scale
            })
            .collect();
        GroundPath { t, p }
    }

    /// Ground point at time `t` (linear between samples, clamped at the ends).
    pub fn at(&self, t: f32) -> Vec2 {
        let n = self.t.len();
        if n == 0 {
            return Vec2::ZERO;
        }
        if t <= self.t[0] || !t.is_finite() {
            return self.p[0];
        }
        if t >= self.t[n - 1] {
            return self.p[n - 1];
        }
        let i = self.t.partition_point(|&x| x <= t).clamp(1, n - 1);
        let u = (t - self.t[i - 1]) / (self.t[i] - self.t[i - 1]);
        self.p[i - 1].lerp(self.p[i], u)
    }

    /// The doodle between two times as a polyline (endpoints included), relative to its start.
    pub fn chunk(&self, t0: f32, t1: f32) -> Polyline {
        let start = self.at(t0);
        let mut pts = vec![Vec2::ZERO];
        for (t, p) in self.t.iter().zip(&self.p) {
            if *t > t0 && *t < t1 {
                pts.push(*p - start);
            }
        }
        pts.push(self.at(t1) - start);
        Polyline::new(pts)
    }
}

/// A ground polyline parametrised by arc length (metres).
#[derive(Debug, Clone, Default)]
pub struct Polyline {
    /// The points.
    pub pts: Vec<Vec2>,
    /// Cumulative arc length at each point.
    pub cum: Vec<f32>,
}

impl Polyline {
    /// Builds a polyline, dropping repeated points.
    pub fn new(points: Vec<Vec2>) -> Polyline {
        let mut pts: Vec<Vec2> = Vec::with_capacity(points.len());
        for p in points {
            if pts.last().is_none_or(|l: &Vec2| (*l - p).length() > 1e-6) {
                pts.push(p);
            }
        }
        if pts.is_empty() {
            pts.push(Vec2::ZERO);
        }
        let mut cum = vec![0.0];
        for w in pts.windows(2) {
            let last = cum.last().copied().unwrap_or(0.0);
            cum.push(last + (w[1] - w[0]).length());
        }
        Polyline { pts, cum }
    }

    /// Total length, metres.
    pub fn length(&self) -> f32 {
        self.cum.last().copied().unwrap_or(0.0)
    }

    /// Point at arc length `s` (clamped).
    pub fn point_at(&self, s: f32) -> Vec2 {
        let n = self.pts.len();
        if n == 1 || !s.is_finite() || s <= 0.0 {
            return self.pts[0];
        }
        if s >= self.length() {
            return self.pts[n - 1];
        }
        let i = self.cum.partition_point(|&c| c <= s).clamp(1, n - 1);
        let span = self.cum[i] - self.cum[i - 1];
        let u = if span > 0.0 {
            (s - self.cum[i - 1]) / span
        } else {
            0.0
        };
        self.pts[i - 1].lerp(self.pts[i], u)
    }

    /// Unit tangent at arc length `s`, averaged over ±`window` metres; `None` on a point.
    pub fn tangent_at(&self, s: f32, window: f32) -> Option<Vec2> {
        let len = self.length();
        if len < 1e-4 {
            return None;
        }
        let a = (s - window).clamp(0.0, len);
        let b = (s + window).clamp(0.0, len);
        let d = self.point_at(b) - self.point_at(a);
        (d.length() > 1e-6).then(|| d.normalize())
    }

    /// Distance from a point to the polyline.
    pub fn distance(&self, q: Vec2) -> f32 {
        if self.pts.len() == 1 {
            return (q - self.pts[0]).length();
        }
        self.pts
            .windows(2)
            .map(|w| {
                let d = w[1] - w[0];
                let u = ((q - w[0]).dot(d) / d.length_squared().max(1e-12)).clamp(0.0, 1.0);
                (w[0] + d * u - q).length()
            })
            .fold(f32::INFINITY, f32::min)
    }
}

/// Yaw (radians) of a ground direction, such that `Quat::from_rotation_y(yaw(b) − yaw(a))`
/// turns direction `a` onto `b`.
pub fn yaw(d: Vec2) -> f32 {
    (-d.y).atan2(d.x)
}

/// Rotation about +Y turning ground direction `from` onto `to`.
pub fn yaw_between(from: Vec2, to: Vec2) -> Quat {
    Quat::from_rotation_y(yaw(to) - yaw(from))
}

/// Ground (x, z) part of a 3-D point.
pub fn ground(v: Vec3) -> Vec2 {
    Vec2::new(v.x, v.z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::poselog::PoseSample;

    #[test]
    fn yaw_between_turns_directions() {
        let a = Vec2::new(1.0, 0.0);
        for b in [
            Vec2::new(0.0, 1.0),
            Vec2::new(-1.0, 0.2).normalize(),
            Vec2::new(0.3, -0.7).normalize(),
        ] {
            let r = yaw_between(a, b) * Vec3::new(a.x, 0.0, a.y);
            assert!((ground(r) - b).length() < 1e-5, "{b} {r}");
        }
    }

    #[test]
    fn ground_path_projects_scales_and_skips_bad_samples() {
        let s = |t: f64, x: f64, y: f64, z: f64| PoseSample {
            t,
            pos: [x, y, z],
            quat: [1.0, 0.0, 0.0, 0.0],
        };
        let log = PoseLog {
            samples: (0..50)
                .map(|i| {
                    s(
                        i as f64 * 0.02,
                        1.0 + i as f64 * 0.01,
                        5.0 + (i % 3) as f64,
                        2.0,
                    )
                })
                .chain([s(0.5, f64::NAN, 0.0, 0.0), s(0.1, 0.0, 0.0, 0.0)])
                .collect(),
        };
        let g = GroundPath::from_log(&log, 10.0);
        assert_eq!(g.t.len(), 50);
        let c = g.chunk(0.2, 0.6);
        // 0.4 s at 0.5 toy m/s → 0.2 toy m → 2 character metres, straight along +x.
        assert!((c.length() - 2.0).abs() < 0.05, "{}", c.length());
        assert!(c.distance(Vec2::new(1.0, 0.0)) < 1e-4);
        assert!((c.tangent_at(1.0, 0.3).unwrap() - Vec2::X).length() < 1e-4);
    }
}
