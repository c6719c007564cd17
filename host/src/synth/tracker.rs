//! Trackers: the classes of real tracker a figurine may be seen by ([`TRACKER_LEVELS`]), and
//! the measurement errors one lays over the true pose ([`TrackerNoise`]): white noise, worse
//! along a single camera's viewing axis than across it, and slow drift in position and heading.

use std::f64::consts::TAU;

use glam::{DQuat, DVec3};

use super::knobs::Range;
use super::noise::peak;
use super::noise::{eval3, partials, Partial};
use super::rng::SynthRng;

/// A class of real tracker: its noise, drift and sample rate. Position σ is per axis; a tracker
/// seen by one camera has a worse σ along the camera's viewing axis (depth) than across it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerLevel {
    /// Name used by `--tracker`.
    pub name: &'static str,
    /// The real trackers it stands for.
    pub stands_for: &'static str,
    /// White position noise σ across the viewing axis (every axis when there is no single
    /// view), millimetres.
    pub pos_sigma_mm: Range,
    /// White position noise σ along the viewing axis (depth), millimetres; drawn at the same
    /// point of its range as `pos_sigma_mm`, so it is never the smaller.
    pub depth_sigma_mm: Range,
    /// White orientation noise σ per axis (small-angle rotation vector), degrees.
    pub rot_sigma_deg: Range,
    /// Slow (0.005–0.05 Hz) position drift, peak per axis, millimetres.
    pub drift_mm: Range,
    /// Slow heading (yaw) drift, peak, degrees.
    pub yaw_drift_deg: Range,
    /// Sample rate, Hz.
    pub rate_hz: Range,
}

/// The tracker levels, best first. Figures are typical published/measured jitter of a static
/// target, not worst cases; together they span position σ 0.1–5 mm, orientation σ 0.02–0.5° and
/// 30–1000 Hz.
pub const TRACKER_LEVELS: [TrackerLevel; 4] = [
    // Lighthouse sweeps and multi-camera mocap triangulate from many directions: isotropic.
    TrackerLevel {
        name: "lighthouse",
        stands_for: "SteamVR Lighthouse (Vive Tracker) or optical mocap (OptiTrack, Vicon)",
        pos_sigma_mm: Range::new(0.1, 0.3),
        depth_sigma_mm: Range::new(0.1, 0.3),
        rot_sigma_deg: Range::new(0.02, 0.05),
        drift_mm: Range::new(0.05, 0.2),
        yaw_drift_deg: Range::new(0.0, 0.05),
        rate_hz: Range::new(120.0, 1000.0),
    },
    // The IMU smooths jitter but wanders between optical/UWB fixes: more drift.
    TrackerLevel {
        name: "imu-fusion",
        stands_for: "IMU fused with optical or UWB fixes (inside-out VR controllers, UWB tags)",
        pos_sigma_mm: Range::new(0.5, 1.0),
        depth_sigma_mm: Range::new(0.5, 1.0),
        rot_sigma_deg: Range::new(0.1, 0.2),
        drift_mm: Range::new(0.5, 2.0),
        yaw_drift_deg: Range::new(0.1, 0.5),
        rate_hz: Range::new(100.0, 400.0),
    },
    // One camera: a tag's distance comes from its apparent size, ~2× worse than across.
    TrackerLevel {
        name: "webcam-near",
        stands_for: "printed fiducial tag (ArUco, AprilTag) seen by a webcam at ~0.5 m",
        pos_sigma_mm: Range::new(0.5, 1.0),
        depth_sigma_mm: Range::new(1.0, 2.0),
        rot_sigma_deg: Range::new(0.2, 0.3),
        drift_mm: Range::new(0.1, 0.5),
        yaw_drift_deg: Range::new(0.0, 0.1),
        rate_hz: Range::new(30.0, 60.0),
    },
    // Twice as far: the tag spans a quarter of the pixels; depth suffers most.
    TrackerLevel {
        name: "webcam-far",
        stands_for: "printed fiducial tag seen by a webcam at ~1 m",
        pos_sigma_mm: Range::new(1.0, 2.0),
        depth_sigma_mm: Range::new(2.5, 5.0),
        rot_sigma_deg: Range::new(0.3, 0.5),
        drift_mm: Range::new(0.2, 1.0),
        yaw_drift_deg: Range::new(0.0, 0.2),
        rate_hz: Range::fixed(30.0),
    },
];

impl TrackerLevel {
    /// The level called `name` (case-insensitive).
    pub fn by_name(name: &str) -> Option<TrackerLevel> {
        let name = name.trim().to_ascii_lowercase();
        TRACKER_LEVELS.iter().copied().find(|l| l.name == name)
    }

    /// The names of all levels, for messages.
    pub fn names() -> String {
        TRACKER_LEVELS.map(|l| l.name).join(", ")
    }
}

impl std::str::FromStr for TrackerLevel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        TrackerLevel::by_name(s).ok_or_else(|| {
            format!(
                "unknown tracker level `{}`: expected {}",
                s.trim(),
                TrackerLevel::names()
            )
        })
    }
}

/// Linear interpolation inside `r` at fraction `u` ∈ [0, 1].
fn lerp(r: Range, u: f64) -> f64 {
    r.lo + (r.hi - r.lo) * u
}

/// The tracker's measurement errors: anisotropic white noise and slow drift.
#[derive(Debug, Clone)]
pub(super) struct TrackerNoise {
    /// White position noise σ across the viewing axis, metres.
    pub(super) across: f64,
    /// White position noise σ along the viewing axis, metres.
    pub(super) depth: f64,
    /// The camera's viewing axis (horizontal unit vector).
    pub(super) view: DVec3,
    side: DVec3,
    /// White orientation noise σ, radians.
    pub(super) rot: f64,
    drift: [[Partial; 3]; 3],
    /// Slow heading drift.
    pub(super) yaw_drift: Partial,
    t0: f64,
}

impl TrackerNoise {
    /// Draws σs and drift of `level` (SI units inside).
    pub(super) fn draw(level: &TrackerLevel, rng: &mut SynthRng, t0: f64) -> Self {
        let u = rng.unit();
        let across = lerp(level.pos_sigma_mm, u) * 1e-3;
        let depth = lerp(level.depth_sigma_mm, u) * 1e-3;
        let rot = level.rot_sigma_deg.draw(rng).to_radians();
        let a = rng.uniform(0.0, TAU);
        let view = DVec3::new(a.cos(), 0.0, a.sin());
        let drift_m = level.drift_mm.draw(rng) * 1e-3;
        let drift = partials(rng, drift_m, 0.005, 0.05);
        let yaw_drift = Partial {
            amp: level.yaw_drift_deg.draw(rng).to_radians(),
            freq: rng.uniform(0.005, 0.05),
            phase: rng.uniform(0.0, TAU),
        };
        Self {
            across,
            depth,
            view,
            side: DVec3::Y.cross(view),
            rot,
            drift,
            yaw_drift,
            t0,
        }
    }

    /// Peak drift per axis, metres.
    pub(super) fn drift_peak(&self) -> f64 {
        peak(&self.drift)
    }

    /// The measured pose at `t` of the true pose (`pos` metres, `q` object→world); `white`
    /// supplies the per-sample noise.
    pub(super) fn measure(
        &self,
        t: f64,
        pos: DVec3,
        q: DQuat,
        white: &mut SynthRng,
    ) -> (DVec3, DQuat) {
        let drift = eval3(&self.drift, t) - eval3(&self.drift, self.t0);
        let n = self.view * (self.depth * white.normal())
            + self.side * (self.across * white.normal())
            + DVec3::Y * (self.across * white.normal());
        let rn = DVec3::new(white.normal(), white.normal(), white.normal()) * self.rot;
        let yaw = self.yaw_drift.at(t) - self.yaw_drift.at(self.t0);
        let q = DQuat::from_rotation_y(yaw) * q * DQuat::from_scaled_axis(rn);
        (pos + drift + n, q.normalize())
    }
}
