//! One figurine pose from every tag of the rig in sight.
//!
//! Each tag found is solved on its own — both of its mirror poses
//! ([`super::pnp::solve_candidates`]) — and carried to the body through its face's fixed place
//! ([`super::rig::Face::body_from_tag`]). With one trusted tag those are the candidates, and
//! [`super::mirror`] picks one over time. With two or more, one pose is refined on all their corners together:
//! points on two planes at an angle admit no mirror pose, and the steeper tag — whose
//! foreshortening shows its tilt by whole pixels — pins the orientation that a face-on tag
//! reads only from hundredths of a pixel. The refinement starts from each tag's poses, mirrors
//! included, and keeps the best fit; when even that fits badly (the tags disagree: a misread, a rig measured
//! wrong) the largest tag in the picture is trusted alone.

use glam::{DVec2, DVec3};

use super::detect::{CameraPose, Detection, Intrinsics};
use super::pnp::{refine, solve_candidates};
use super::rig::Rig;

/// RMS corner reprojection error (pixels) above which a pose is not trusted: corners that no
/// flat square explains — a finger over a corner, whose edge the detector takes for the
/// border's, a misread, a frame smeared by fast motion. Found corners fit within 0.3 px in
/// 99.97 % of the track bench's 45,508 tracked frames (seeds 0–5, box rig); a corner pulled
/// 2–5 px by a finger gives 0.5–1.3 px, and a pose centimetres and tens of degrees off, which
/// at 2 px (until 2026-12-05) a held figurine's log took as a jolt and read as a kick. A
/// lens's distortion mostly tilts the fitted square rather than leaving corners unexplained.
pub const MAX_POSE_ERROR_PX: f64 = 0.5;

/// One tag of the rig found in a frame and solved.
#[derive(Debug, Clone, PartialEq)]
pub struct TagSeen {
    /// What the detector found.
    pub detection: Detection,
    /// The tag's own camera-frame pose that fits its corners best (trusted or not: see its
    /// error).
    pub tag: CameraPose,
    /// The body's camera-frame pose this tag alone gives (from [`Self::tag`]).
    pub body: CameraPose,
    /// Every body pose the tag admits — its best fit and, when it differs, its mirror — each
    /// with the tag's RMS corner error (pixels), the best first.
    pub candidates: Vec<CameraPose>,
    /// The tag's own camera-frame poses behind [`Self::candidates`], in the same order.
    pub tag_candidates: Vec<CameraPose>,
}

impl TagSeen {
    /// The tag's area in the picture, square pixels.
    pub fn area_px(&self) -> f64 {
        let c = &self.detection.corners;
        let twice: f64 = (0..4)
            .map(|i| {
                let (a, b) = (c[i], c[(i + 1) % 4]);
                a[0] * b[1] - b[0] * a[1]
            })
            .sum();
        twice.abs() / 2.0
    }

    /// Whether its corners fit a flat square well enough to trust.
    pub fn trusted(&self) -> bool {
        self.tag.error <= MAX_POSE_ERROR_PX
    }
}

/// Solves every detection of a rig tag: both of its mirror poses, carried to the body.
pub fn solve_tags(rig: &Rig, found: Vec<Detection>, k: &Intrinsics) -> Vec<TagSeen> {
    found
        .into_iter()
        .filter_map(|d| {
            let face = rig.face(d.id)?;
            let tags = solve_candidates(&d.corners, rig.tag_size, k);
            let tag = *tags.first()?;
            let tag_candidates: Vec<CameraPose> = tags
                .into_iter()
                .filter(|c| c.error <= MAX_POSE_ERROR_PX || c.error == tag.error)
                .collect();
            let candidates: Vec<CameraPose> = tag_candidates
                .iter()
                .map(|c| face.body_from_tag(c))
                .collect();
            Some(TagSeen {
                detection: d,
                tag,
                body: candidates[0],
                candidates,
                tag_candidates,
            })
        })
        .collect()
}

/// The body's pose from one frame's tags.
#[derive(Debug, Clone, PartialEq)]
pub enum Fused {
    /// Two or more tags agreed on one pose: points on two planes admit no mirror.
    Settled(CameraPose),
    /// One tag is trusted (or the tags disagree and the largest is trusted alone): the body
    /// poses it admits, the best fit first; which to report is decided over time
    /// ([`super::mirror`]).
    Lone {
        /// The body poses, each with the tag's RMS corner error (pixels).
        candidates: Vec<CameraPose>,
        /// The tag's corners, pixels.
        corners: [[f64; 2]; 4],
        /// The tag's id.
        id: u32,
        /// The tag's own poses behind `candidates`, in the same order (for
        /// [`super::photo::evidence`]).
        tag_poses: Vec<CameraPose>,
    },
}

/// The body's pose from the tags seen: `None` when no tag is trusted.
pub fn fuse(rig: &Rig, seen: &[TagSeen], k: &Intrinsics) -> Option<Fused> {
    let trusted: Vec<&TagSeen> = seen.iter().filter(|s| s.trusted()).collect();
    let largest = trusted
        .iter()
        .max_by(|a, b| a.area_px().total_cmp(&b.area_px()))
        .map(|s| Fused::Lone {
            candidates: s.candidates.clone(),
            corners: s.detection.corners,
            id: s.detection.id,
            tag_poses: s.tag_candidates.clone(),
        })?;
    if trusted.len() < 2 {
        return Some(largest);
    }
    let (mut obj, mut px) = (Vec::new(), Vec::new());
    for s in &trusted {
        let face = rig.face(s.detection.id)?;
        obj.extend(face.corners_in_body(rig.tag_size));
        px.extend(s.detection.corners.map(|c| DVec2::new(c[0], c[1])));
    }
    // Every tag's poses, mirrors included, as starting points: the joint fit has one
    // minimum worth having, and one of them lies in its basin.
    let best = trusted
        .iter()
        .flat_map(|s| &s.candidates)
        .map(|c| {
            let (q, t) = (c.quat(), DVec3::from_array(c.translation));
            refine(q, t, &obj, &px, k)
        })
        .filter(|(q, t, err)| q.is_finite() && t.is_finite() && err.is_finite())
        .min_by(|a, b| a.2.total_cmp(&b.2));
    match best {
        Some((q, t, err)) if err <= MAX_POSE_ERROR_PX => Some(Fused::Settled(
            CameraPose::from_parts(glam::DMat3::from_quat(q), t, err),
        )),
        _ => Some(largest),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::pose::{angle_between_deg, camera_pose, figurine_pose, intrinsics_from_fov};
    use glam::DQuat;

    /// The detections a perfect detector would give of the rig's tags turned toward the
    /// camera (more than 10° from edge-on), the corners shifted by `jitter(i)` pixels.
    fn seen(
        rig: &Rig,
        p: DVec3,
        q: DQuat,
        k: &Intrinsics,
        jitter: impl Fn(usize) -> f64,
    ) -> Vec<Detection> {
        let (r, t) = camera_pose(p, q);
        let mut n = 0;
        let mut out = Vec::new();
        for f in &rig.faces {
            let c = f.corners_in_body(rig.tag_size).map(|o| r * o + t);
            // Its printed x crossed with its printed up: the tag's outward normal.
            let outward = (c[1] - c[0]).cross(c[3] - c[0]).normalize();
            let to_camera = -(c[0] + c[2]) / 2.0;
            if outward.dot(to_camera.normalize()) < 10f64.to_radians().sin() {
                continue;
            }
            let corners = c.map(|v| {
                n += 1;
                let j = jitter(n);
                [k.cx + k.fx * v.x / v.z + j, k.cy + k.fy * v.y / v.z - j]
            });
            out.push(Detection {
                id: f.id,
                hamming: 0,
                margin: 50.0,
                corners,
                center: [0.0; 2],
            });
        }
        out
    }

    #[test]
    fn two_faces_in_sight_give_one_pose_no_worse_than_either() {
        let k = intrinsics_from_fov(640, 480, 60.0);
        let rig = Rig::boxed(0, 0.04, 0.08, 0.08);
        let p = DVec3::new(0.03, 0.01, -0.9);
        // Turned 40° to its right (its left shoulder toward the camera): the front and the
        // left face both in sight.
        let q = DQuat::from_euler(glam::EulerRot::YXZ, -40f64.to_radians(), 0.05, 0.0);
        let jitter = |i: usize| 0.15 * ((i * 7919 % 13) as f64 / 6.0 - 1.0);
        let found = seen(&rig, p, q, &k, jitter);
        assert_eq!(found.iter().map(|d| d.id).collect::<Vec<_>>(), [0, 1]);
        let tags = solve_tags(&rig, found, &k);
        let err = |c: &CameraPose| {
            let (p2, q2) = figurine_pose(c);
            ((p2 - p).length() * 1000.0, angle_between_deg(q, q2))
        };
        let Some(Fused::Settled(both)) = fuse(&rig, &tags, &k) else {
            panic!("two tags in sight give one settled pose");
        };
        let fused = err(&both);
        for t in &tags {
            let one = err(&t.body);
            assert!(
                fused.1 <= one.1 + 0.05,
                "fused {fused:?}, tag {}: {one:?}",
                t.detection.id
            );
        }
        assert!(fused.0 < 3.0 && fused.1 < 0.5, "{fused:?}");
        // No tag trusted, no pose: a tag whose corners no square explains.
        let mut bad = tags[0].clone();
        bad.tag.error = MAX_POSE_ERROR_PX * 2.0;
        assert!(fuse(&rig, &[bad], &k).is_none());
    }

    #[test]
    fn a_corner_pulled_by_a_finger_is_not_trusted() {
        // A held tag at 0.75 m (about 30 px across): with its corners found within a tenth of
        // a pixel, its pose is trusted; with one corner pulled 3 px along the border by a
        // finger over it (the detector fits the border's edge to the finger's), the best
        // square misses the corners by 0.7 px RMS, and its pose would put the toy millimetres
        // away and tilted by tens of degrees: a jolt from nowhere in a figurine at rest.
        let k = intrinsics_from_fov(640, 480, 60.0);
        let rig = Rig::single(0, 0.04);
        let (p, q) = (DVec3::new(0.0, 0.0, -0.75), DQuat::from_rotation_x(0.02));
        let jitter = |i: usize| 0.08 * ((i * 7919 % 13) as f64 / 6.0 - 1.0);
        let clean = seen(&rig, p, q, &k, jitter);
        let tags = solve_tags(&rig, clean.clone(), &k);
        assert!(tags[0].trusted(), "error {:.3} px", tags[0].tag.error);
        assert!(fuse(&rig, &tags, &k).is_some());
        let mut pulled = clean;
        pulled[0].corners[0][0] += 3.0;
        let tags = solve_tags(&rig, pulled, &k);
        let (p2, q2) = figurine_pose(&tags[0].body);
        let (mm, deg) = ((p2 - p).length() * 1000.0, angle_between_deg(q, q2));
        assert!(
            mm > 5.0 && deg > 10.0,
            "the pulled pose is off: {mm:.1} mm, {deg:.1}°"
        );
        assert!(!tags[0].trusted(), "error {:.3} px", tags[0].tag.error);
        assert!(fuse(&rig, &tags, &k).is_none());
    }
}
