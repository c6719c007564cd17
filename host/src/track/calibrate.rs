//! `figurine track calibrate`: the camera's focal length from a video of the printed tag
//! turned through different tilts in front of it.
//!
//! A webcam's pixels are square and its principal point sits near the frame's centre, so the
//! one unknown that matters is the focal length: a wrong one scales every depth (see the
//! README). Each frame's tag gives a homography from the tag's plane to the image; for a tilted
//! tag, the two columns of the rotation it hides must be orthogonal and of equal length, and
//! each condition is linear in 1/f² (Zhang's calibration with only f unknown). A least-squares
//! f over all frames starts a golden-section search for the f that minimises the corners'
//! reprojection error over all frames. Lens distortion is not modelled.

use std::path::Path;

use glam::{DMat3, DVec3};

use super::detect::{Detector, DetectorSettings, Family, Intrinsics};
use super::pnp::{object_corners, solve_pose};
use super::pose::Calibration;
use super::video::{FrameReader, Source};
use super::TrackError;

/// Fewest frames with a usefully tilted tag to calibrate from.
pub const MIN_VIEWS: usize = 10;
/// A view counts when its tag is tilted at least this much from facing the camera, degrees:
/// a square seen face-on says nothing about the focal length.
pub const MIN_TILT_DEG: f64 = 15.0;

/// One frame's tag corners, pixels, in the detector's order.
pub type Corners = [[f64; 2]; 4];

/// The homography from the unit-free tag plane (corner coordinates ±1) to pixels centred on
/// the principal point, from four corners; `None` when degenerate.
fn centred_homography(c: &Corners, cx: f64, cy: f64) -> Option<DMat3> {
    let obj = object_corners(2.0);
    let mut a = [[0.0; 8]; 8];
    let mut b = [0.0; 8];
    for i in 0..4 {
        let (x, y) = (obj[i].x, obj[i].y);
        let (u, v) = (c[i][0] - cx, c[i][1] - cy);
        a[2 * i] = [x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y];
        b[2 * i] = u;
        a[2 * i + 1] = [0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y];
        b[2 * i + 1] = v;
    }
    let h = super::pnp::solve_linear(a, b)?;
    Some(DMat3::from_cols(
        DVec3::new(h[0], h[3], h[6]),
        DVec3::new(h[1], h[4], h[7]),
        DVec3::new(h[2], h[5], 1.0),
    ))
}

/// Least-squares focal length (pixels) from the homographies' two constraints each.
fn closed_form(views: &[Corners], cx: f64, cy: f64) -> Option<f64> {
    let (mut saa, mut sab) = (0.0, 0.0);
    for c in views {
        let Some(h) = centred_homography(c, cx, cy) else {
            continue;
        };
        let (h1, h2) = (h.x_axis, h.y_axis);
        // h1ᵀ ω h2 = 0 and h1ᵀ ω h1 = h2ᵀ ω h2, ω = diag(1/f², 1/f², 1): a·(1/f²) + b = 0.
        let pairs = [
            (h1.x * h2.x + h1.y * h2.y, h1.z * h2.z),
            (
                h1.x * h1.x + h1.y * h1.y - h2.x * h2.x - h2.y * h2.y,
                h1.z * h1.z - h2.z * h2.z,
            ),
        ];
        for (a, b) in pairs {
            // Scale-free: normalise each equation by its size so no view dominates.
            let n = (a * a + b * b).sqrt();
            if n > 0.0 && n.is_finite() {
                saa += (a / n) * (a / n);
                sab += (a / n) * (b / n);
            }
        }
    }
    let x = -sab / saa;
    (x.is_finite() && x > 0.0).then(|| 1.0 / x.sqrt())
}

/// Mean RMS corner reprojection error (pixels) over the views with focal length `f`.
fn reprojection(views: &[Corners], f: f64, cx: f64, cy: f64, size: f64) -> f64 {
    let k = Intrinsics {
        fx: f,
        fy: f,
        cx,
        cy,
    };
    let errs: Vec<f64> = views
        .iter()
        .filter_map(|c| solve_pose(c, size, &k, None).map(|p| p.error))
        .collect();
    if errs.is_empty() {
        f64::INFINITY
    } else {
        errs.iter().sum::<f64>() / errs.len() as f64
    }
}

/// Tilt of a view's tag from facing the camera, degrees, under a rough focal length.
fn tilt_deg(c: &Corners, k: &Intrinsics) -> Option<f64> {
    let pose = solve_pose(c, 1.0, k, None)?;
    let q = pose.quat();
    let t = DVec3::from_array(pose.translation);
    Some((q * DVec3::Z).angle_between(t).to_degrees())
}

/// The calibration from tag corners seen in frames of `width`×`height`.
pub fn calibrate(
    views: &[Corners],
    width: usize,
    height: usize,
) -> Result<Calibration, TrackError> {
    let (cx, cy) = (width as f64 / 2.0, height as f64 / 2.0);
    let rough = super::pose::intrinsics_from_fov(width, height, super::pose::DEFAULT_FOV_DEG);
    let tilted: Vec<Corners> = views
        .iter()
        .filter(|c| tilt_deg(c, &rough).is_some_and(|t| t >= MIN_TILT_DEG))
        .copied()
        .collect();
    if tilted.len() < MIN_VIEWS {
        return Err(TrackError::BadArgument(format!(
            "only {} of {} frames show the tag tilted {MIN_TILT_DEG}° or more; turn it \
             through different tilts (left, right, up, down) in front of the camera",
            tilted.len(),
            views.len()
        )));
    }
    let start = closed_form(&tilted, cx, cy).unwrap_or(rough.fx);
    // Golden-section search for the best f within ±40 % of the closed form (the error is
    // independent of the tag's size, so any size will do).
    let (mut lo, mut hi) = (start * 0.6, start * 1.4);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let cost = |f: f64| reprojection(&tilted, f, cx, cy, 0.04);
    let (mut a, mut b) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut fa, mut fb) = (cost(a), cost(b));
    for _ in 0..40 {
        if fa < fb {
            hi = b;
            (b, fb) = (a, fa);
            a = hi - g * (hi - lo);
            fa = cost(a);
        } else {
            lo = a;
            (a, fa) = (b, fb);
            b = lo + g * (hi - lo);
            fb = cost(b);
        }
    }
    let f = (lo + hi) / 2.0;
    let cal = Calibration {
        width,
        height,
        fx: f,
        fy: f,
        cx,
        cy,
        rms_px: Some(cost(f)),
    };
    cal.check()
        .map_err(|e| TrackError::BadArgument(format!("calibration failed: {e}")))?;
    Ok(cal)
}

/// Collects the corners of tag `id` from every frame of a video.
pub fn corners_from_video(
    path: &Path,
    family: Family,
    id: u32,
) -> Result<(Vec<Corners>, usize, usize), TrackError> {
    let mut reader = FrameReader::open(Source::File(path.to_path_buf()))?;
    let mut detector = Detector::new(family, DetectorSettings::default())?;
    let mut views = Vec::new();
    let mut frames = 0u64;
    while let Some((_, frame)) = reader.next_frame()? {
        frames += 1;
        if let Some(d) = detector.detect(&frame).into_iter().find(|d| d.id == id) {
            views.push(d.corners);
        }
    }
    if views.is_empty() {
        return Err(TrackError::NoTag {
            source_name: path.display().to_string(),
            family: family.name(),
            ids: id.to_string(),
            frames,
        });
    }
    Ok((views, reader.width(), reader.height()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::pose::intrinsics_from_fov;
    use glam::DQuat;

    fn project(q: DQuat, t: DVec3, k: &Intrinsics) -> Corners {
        object_corners(0.04).map(|p| {
            let c = q * p + t;
            [k.cx + k.fx * c.x / c.z, k.cy + k.fy * c.y / c.z]
        })
    }

    #[test]
    fn exact_tilted_views_give_the_focal_length() {
        let k = intrinsics_from_fov(640, 480, 72.0);
        let views: Vec<Corners> = (0..16)
            .map(|i| {
                let a = i as f64 * 0.4;
                let q = DQuat::from_euler(glam::EulerRot::YXZ, 0.5 * a.cos(), 0.5 * a.sin(), 0.1);
                project(
                    q,
                    DVec3::new(0.02 * a.sin(), 0.01, 0.4 + 0.02 * a.cos()),
                    &k,
                )
            })
            .collect();
        let cal = calibrate(&views, 640, 480).unwrap();
        assert!((cal.fx / k.fx - 1.0).abs() < 1e-3, "{} vs {}", cal.fx, k.fx);
        assert!(cal.rms_px.unwrap() < 1e-3);
    }

    #[test]
    fn face_on_views_are_refused() {
        let k = intrinsics_from_fov(640, 480, 60.0);
        let views: Vec<Corners> = (0..20)
            .map(|i| {
                project(
                    DQuat::IDENTITY,
                    DVec3::new(0.0, 0.0, 0.3 + 0.01 * i as f64),
                    &k,
                )
            })
            .collect();
        let err = calibrate(&views, 640, 480).unwrap_err().to_string();
        assert!(err.contains("tilted"), "{err}");
    }
}
