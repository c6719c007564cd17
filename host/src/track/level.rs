//! How far the camera looks down, measured from the figurine standing upright in view.
//!
//! The tracker measures poses in the camera's frame; the log's world must have +Y up, as the
//! recognizer reads heights and rises along it. A camera held level needs nothing; one that
//! looks down at a toy on a desk (a laptop's webcam: 20–40°) tilts every pose by as much, and
//! a stroke along the desk reads partly as a rise. `figurine track --level` tracks a few
//! seconds of the figurine standing still and upright, and reads the camera's tilt from the
//! figurine's own up: in a camera that looks down θ, the world's up is (0, cos θ, sin θ).
//! `--camera-tilt θ` then turns every pose back into the world ([`super::pose::camera_tilt`]).
//!
//! | step | what |
//! |---|---|
//! | still | a sample is still when every sample within [`STILL_WINDOW_S`] of it lies within [`STILL_MM`] and [`STILL_DEG`] of it |
//! | up | the mean of the still samples' up axes, in the camera's frame |
//! | tilt, roll | the up's lean toward the camera (the tilt) and sideways (the roll, reported: `--camera-tilt` corrects the tilt only) |

use glam::DVec3;

use super::eval::quat;
use super::pose::angle_between_deg;
use super::TrackError;
use crate::poselog::PoseSample;

/// Seconds of samples a live camera's level is measured over (from its first sample on).
pub const LIVE_S: f64 = 4.0;
/// Half-width of the window a still sample's neighbours lie in, seconds.
pub const STILL_WINDOW_S: f64 = 0.25;
/// Farthest a still sample's neighbours lie from it, millimetres.
pub const STILL_MM: f64 = 3.0;
/// Most a still sample's neighbours are turned from it, degrees.
pub const STILL_DEG: f64 = 1.5;
/// Still samples the measure needs at least (a second at 30 fps, give or take).
pub const MIN_STILL: usize = 20;
/// Most the still samples' up axes may spread (RMS angle from their mean, degrees): more, and
/// the figurine was set down in different ways, or was not standing.
pub const MAX_SPREAD_DEG: f64 = 3.0;

/// The camera's tilt and roll, measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    /// How far the camera looks down, degrees (negative: up).
    pub tilt_deg: f64,
    /// How far it is rolled about its line of sight, degrees (positive: the world's up leans
    /// toward the picture's left).
    pub roll_deg: f64,
    /// Still samples it was measured from.
    pub still: usize,
    /// RMS angle of their up axes from the mean, degrees.
    pub spread_deg: f64,
}

/// The figurine's up axis in the camera's frame at `s`.
fn up_of(s: &PoseSample) -> DVec3 {
    quat(s) * DVec3::Y
}

/// Whether every sample within [`STILL_WINDOW_S`] of `samples[i]` (in time order, as the
/// tracker writes them) lies within [`STILL_MM`] and [`STILL_DEG`] of it, and the window is
/// covered on both sides.
fn is_still(samples: &[PoseSample], i: usize) -> bool {
    let s = &samples[i];
    let (p, q) = (DVec3::from_array(s.pos), quat(s));
    let from = samples.partition_point(|o| o.t < s.t - STILL_WINDOW_S);
    let to = samples.partition_point(|o| o.t <= s.t + STILL_WINDOW_S);
    let window = &samples[from..to.max(from)];
    let covered = window
        .first()
        .is_some_and(|a| a.t <= s.t - 0.8 * STILL_WINDOW_S)
        && window
            .last()
            .is_some_and(|b| b.t >= s.t + 0.8 * STILL_WINDOW_S);
    covered
        && window.iter().all(|o| {
            (DVec3::from_array(o.pos) - p).length() * 1000.0 <= STILL_MM
                && angle_between_deg(q, quat(o)) <= STILL_DEG
        })
}

/// The camera's tilt read from `samples` (tracked in the camera's own frame, no tilt applied)
/// of a figurine standing upright; an error when it never stood still long enough, or its
/// up axes disagree.
pub fn measure(samples: &[PoseSample]) -> Result<Level, TrackError> {
    let ups: Vec<DVec3> = (0..samples.len())
        .filter(|&i| is_still(samples, i))
        .map(|i| up_of(&samples[i]))
        .filter(|u| u.is_finite())
        .collect();
    if ups.len() < MIN_STILL {
        return Err(TrackError::BadArgument(format!(
            "the figurine stood still for {} samples, {MIN_STILL} are needed: stand it upright \
             in view and keep it still for a second or two",
            ups.len()
        )));
    }
    let up = ups.iter().copied().sum::<DVec3>().normalize();
    let spread = (ups
        .iter()
        .map(|u| u.angle_between(up).to_degrees().powi(2))
        .sum::<f64>()
        / ups.len() as f64)
        .sqrt();
    if spread > MAX_SPREAD_DEG {
        return Err(TrackError::BadArgument(format!(
            "the figurine's up axis varied by {spread:.1}° RMS while still (at most \
             {MAX_SPREAD_DEG}°): stand it upright once, and keep it there"
        )));
    }
    Ok(Level {
        tilt_deg: up.z.atan2(up.y).to_degrees(),
        roll_deg: (-up.x).atan2(up.y.hypot(up.z)).to_degrees(),
        still: ups.len(),
        spread_deg: spread,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::pose::camera_tilt;
    use glam::DQuat;

    /// `n` samples at 30 fps of a figurine at `pos` turned `q` (world), seen by a camera
    /// that looks down `tilt` degrees, in the camera's frame; the first `moving` of them
    /// sliding sideways at 0.3 m/s.
    fn seen(tilt: f64, q: DQuat, n: usize, moving: usize) -> Vec<PoseSample> {
        let to_camera = camera_tilt(tilt).inverse();
        (0..n)
            .map(|i| {
                let t = i as f64 / 30.0;
                let x = 0.3 * t.min(moving as f64 / 30.0);
                let p = to_camera * DVec3::new(x, -0.3, -0.7);
                let qc = to_camera * q;
                PoseSample {
                    t,
                    pos: p.to_array(),
                    quat: [qc.w, qc.x, qc.y, qc.z],
                }
            })
            .collect()
    }

    #[test]
    fn an_upright_figurine_shows_the_cameras_tilt() {
        // Turned to face anywhere about the vertical: its up is the world's all the same.
        let q = DQuat::from_rotation_y(0.7);
        let level = measure(&seen(25.0, q, 60, 20)).unwrap();
        assert!((level.tilt_deg - 25.0).abs() < 1e-6, "{level:?}");
        assert!(level.roll_deg.abs() < 1e-6, "{level:?}");
        // Only the still stretch counts: 40 samples less the window at either end.
        assert!((20..40).contains(&level.still), "{level:?}");
        let up = measure(&seen(-10.0, q, 60, 0)).unwrap();
        assert!((up.tilt_deg + 10.0).abs() < 1e-6, "{up:?}");
    }

    #[test]
    fn a_figurine_never_still_or_not_standing_gives_a_clear_error() {
        let moving = measure(&seen(25.0, DQuat::IDENTITY, 60, 60)).unwrap_err();
        assert!(moving.to_string().contains("stood still for 0"), "{moving}");
        assert!(measure(&[]).is_err());
        // Set down twice, leaning 10° one way and then the other.
        let mut twice = seen(25.0, DQuat::from_rotation_z(0.17), 40, 0);
        let other = seen(25.0, DQuat::from_rotation_z(-0.17), 40, 0);
        twice.extend(other.into_iter().map(|mut s| {
            s.t += 2.0;
            s
        }));
        let spread = measure(&twice).unwrap_err();
        assert!(spread.to_string().contains("varied"), "{spread}");
    }
}
