//! From the detector's camera-frame pose to the pose log's frames, and back (for rendering).
//!
//! * Camera frame (the detector's): x right, y down, z forward, metres.
//! * World frame of a tracked log: origin at the camera, +X the camera's right, +Y up, +Z from
//!   the scene toward the camera — the camera frame turned 180° about x, so a level camera
//!   gives a level world (DESIGN.md: +Y up).
//! * Figurine frame: +Z front, +Y up, +X left. The tag is stuck on the figurine's front,
//!   printed side out and upright: its outward normal is the figurine's front, the printed
//!   top its up, and the printed right edge (seen from the front) the figurine's left. The
//!   tag frame (x right, y down as printed, z into the tag) turned 180° about x is therefore
//!   the figurine frame, and the tag's centre is the figurine's origin.

use std::path::Path;

use glam::{DMat3, DQuat, DVec3};
use serde::{Deserialize, Serialize};

use super::detect::{CameraPose, Intrinsics};
use super::TrackError;

/// The 180° turn about x that maps the camera frame to the world frame and the tag frame to
/// the figurine frame (its own inverse).
pub const FLIP_YZ: DMat3 = DMat3::from_cols(DVec3::X, DVec3::NEG_Y, DVec3::NEG_Z);

/// Horizontal field of view assumed without a calibration, degrees: a typical webcam's.
pub const DEFAULT_FOV_DEG: f64 = 60.0;

/// Pinhole intrinsics for a `width`×`height` frame from its horizontal field of view (degrees),
/// square pixels and the principal point at the centre.
pub fn intrinsics_from_fov(width: usize, height: usize, hfov_deg: f64) -> Intrinsics {
    let f = width as f64 / 2.0 / (hfov_deg.to_radians() / 2.0).tan();
    Intrinsics {
        fx: f,
        fy: f,
        cx: width as f64 / 2.0,
        cy: height as f64 / 2.0,
    }
}

/// A camera calibration file (`figurine track calibrate` writes it): pinhole intrinsics in
/// pixels for frames of `width`×`height`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// Frame width the intrinsics were measured at, pixels.
    pub width: usize,
    /// Frame height, pixels.
    pub height: usize,
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
    /// RMS reprojection error of the calibration, pixels (informative).
    #[serde(default)]
    pub rms_px: Option<f64>,
}

impl Calibration {
    /// Reads and checks a calibration file.
    pub fn read(path: &Path) -> Result<Self, TrackError> {
        let bad = |reason: String| TrackError::BadCalibration {
            path: path.to_path_buf(),
            reason,
        };
        let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
        Self::from_json(&text, path)
    }

    /// Parses and checks the text of calibration file `path` (named in errors).
    pub fn from_json(text: &str, path: &Path) -> Result<Self, TrackError> {
        let bad = |reason: String| TrackError::BadCalibration {
            path: path.to_path_buf(),
            reason,
        };
        let cal: Calibration = serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
        cal.check().map_err(bad)?;
        Ok(cal)
    }

    /// Why the numbers cannot be a camera, if they cannot.
    pub fn check(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 {
            return Err("width and height must be positive".into());
        }
        for (name, v) in [("fx", self.fx), ("fy", self.fy)] {
            if !v.is_finite() || v <= 0.0 {
                return Err(format!(
                    "{name} must be a positive number of pixels, not {v}"
                ));
            }
        }
        for (name, v, lim) in [("cx", self.cx, self.width), ("cy", self.cy, self.height)] {
            if !v.is_finite() || v < 0.0 || v > lim as f64 {
                return Err(format!("{name} = {v} lies outside the frame (0..{lim})"));
            }
        }
        Ok(())
    }

    /// The intrinsics for frames of `width`×`height`: scaled when the camera delivers another
    /// size of the same aspect, an error when the aspect differs (a cropped mode).
    pub fn intrinsics_for(&self, width: usize, height: usize) -> Result<Intrinsics, String> {
        let sx = width as f64 / self.width as f64;
        let sy = height as f64 / self.height as f64;
        if (sx - sy).abs() > 0.01 * sx {
            return Err(format!(
                "calibrated at {}×{}, but the video is {width}×{height} (another aspect: \
                 calibrate at this size)",
                self.width, self.height
            ));
        }
        Ok(Intrinsics {
            fx: self.fx * sx,
            fy: self.fy * sy,
            cx: self.cx * sx,
            cy: self.cy * sy,
        })
    }
}

/// A rotation matrix as a unit quaternion with w ≥ 0 (one of the two signs).
pub fn quat_from_mat(m: DMat3) -> DQuat {
    let q = DQuat::from_mat3(&m).normalize();
    if q.w < 0.0 {
        -q
    } else {
        q
    }
}

/// The figurine's world pose (position, metres; orientation figurine→world) from the tag's
/// camera-frame pose.
pub fn figurine_pose(cam: &CameraPose) -> (DVec3, DQuat) {
    let r = cam.rotation;
    let r_ct = DMat3::from_cols(
        DVec3::new(r[0][0], r[1][0], r[2][0]),
        DVec3::new(r[0][1], r[1][1], r[2][1]),
        DVec3::new(r[0][2], r[1][2], r[2][2]),
    );
    let pos = FLIP_YZ * DVec3::from_array(cam.translation);
    (pos, quat_from_mat(FLIP_YZ * r_ct * FLIP_YZ))
}

/// The inverse of [`figurine_pose`]: the tag's camera-frame rotation (tag→camera) and centre
/// for a figurine world pose. The renderer uses it.
pub fn camera_pose(pos: DVec3, q: DQuat) -> (DMat3, DVec3) {
    let r_wf = DMat3::from_quat(q.normalize());
    (FLIP_YZ * r_wf * FLIP_YZ, FLIP_YZ * pos)
}

/// The rotation from the camera's frame (+X right, +Y up, +Z toward the viewer, as if it
/// were level) to the world (+Y up) of a camera that looks down `deg` degrees (negative: up):
/// a pose the camera measures is `camera_tilt(deg) * pose` in the world.
pub fn camera_tilt(deg: f64) -> DQuat {
    DQuat::from_rotation_x(-deg.to_radians())
}

/// Projects a camera-frame point to pixels; `None` behind or too near the camera.
pub fn project(k: &Intrinsics, p: DVec3) -> Option<[f64; 2]> {
    (p.z > 1e-3).then(|| [k.cx + k.fx * p.x / p.z, k.cy + k.fy * p.y / p.z])
}

/// Angle between two orientations, degrees (q and −q are the same).
pub fn angle_between_deg(a: DQuat, b: DQuat) -> f64 {
    let d = a.normalize().dot(b.normalize()).abs().min(1.0);
    (2.0 * d.acos()).to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_pose_and_figurine_pose_are_inverse() {
        let q = DQuat::from_euler(glam::EulerRot::YXZ, 0.4, -0.3, 0.2);
        let p = DVec3::new(0.1, -0.05, -0.7);
        let (r, t) = camera_pose(p, q);
        let rows = [
            r.row(0).to_array(),
            r.row(1).to_array(),
            r.row(2).to_array(),
        ];
        let cam = CameraPose {
            rotation: rows,
            translation: t.to_array(),
            error: 0.0,
        };
        let (p2, q2) = figurine_pose(&cam);
        assert!((p2 - p).length() < 1e-12);
        assert!(angle_between_deg(q, q2) < 1e-6);
    }

    #[test]
    fn a_tag_facing_the_camera_is_a_figurine_facing_it_upright() {
        // Tag square to the camera, printed top up, 0.5 m ahead: tag frame = camera frame.
        let cam = CameraPose {
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            translation: [0.0, 0.0, 0.5],
            error: 0.0,
        };
        let (p, q) = figurine_pose(&cam);
        assert!(
            (p - DVec3::new(0.0, 0.0, -0.5)).length() < 1e-12,
            "in front"
        );
        // Front (+Z) toward the camera (world +Z), up is up, left is the camera's right.
        assert!((q * DVec3::Z - DVec3::Z).length() < 1e-12);
        assert!((q * DVec3::Y - DVec3::Y).length() < 1e-12);
        assert!((q * DVec3::X - DVec3::X).length() < 1e-12);
    }

    #[test]
    fn fov_gives_the_focal_length() {
        let k = intrinsics_from_fov(640, 480, 90.0);
        assert!((k.fx - 320.0).abs() < 1e-9 && k.cx == 320.0 && k.cy == 240.0);
    }

    #[test]
    fn bad_calibrations_say_why() {
        let mut c = Calibration {
            width: 640,
            height: 480,
            fx: 500.0,
            fy: 500.0,
            cx: 320.0,
            cy: 240.0,
            rms_px: None,
        };
        assert!(c.check().is_ok());
        assert!(c.intrinsics_for(1280, 960).unwrap().fx == 1000.0);
        assert!(c.intrinsics_for(1280, 720).is_err());
        c.fx = -1.0;
        assert!(c.check().unwrap_err().contains("fx"));
        c.fx = 500.0;
        c.cy = 900.0;
        assert!(c.check().unwrap_err().contains("cy"));
    }
}
