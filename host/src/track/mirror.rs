//! Which of a lone tag's two mirror poses to report, decided over time.
//!
//! A flat square seen from afar admits two poses — tilted toward or away from the line of
//! sight — whose corners differ by hundredths of a pixel. One frame's fit cannot tell them
//! apart reliably, but the true pose keeps fitting a little better frame after frame (on the
//! track bench at 1 m: 0.05 px RMS against 0.11 px, over a dozen frames). So both are followed
//! as branches, each carrying the cost of its best path so far: the evidence against every
//! pose on it — its corners' misfit (the negative log-likelihood under the corner noise,
//! measured as the fits go) or, on a small tag, its picture's (the table below) — plus the
//! cost of the turns between its poses (a toy does not turn by tens of degrees in a
//! thirtieth of a second). A frame's fit counts in full only when the tag has moved since the
//! last (a still tag shows the same biased picture again and again). The costs come from a
//! forward Viterbi pass over the two branches. Near face-on the two poses are close, every
//! path can reach both cheaply, and the costs merge; as they part, evidence builds up on the
//! true side while the tag moves, and the report follows it instead of holding the wrong tilt
//! by continuity alone. A tag that tilts and then holds still gives little evidence, and may
//! keep the wrong tilt until it moves again.
//!
//! Each frame reports the branches' posterior mean, each weighed e^−cost: the pose ending the
//! cheapest path, turned toward the other branch's by the other's share. While the evidence
//! is weak the report sits between the two poses, so noise that carries the cheaper path
//! across (far away a small tag's tilt estimate passes near face-on from frame to frame, where
//! the branches merge) moves it a little, not by the poses' whole separation: at 1 m a tag 5°
//! from square swapped 10° back and forth, which the recognizer reads as bows. A few nats of
//! evidence give the likelier branch the whole weight.
//!
//! | branch costs differ by | the report |
//! |---|---|
//! | 0 nats | halfway between the two poses |
//! | 1 nat | 27 % of the way to the other |
//! | 3 nats | 5 % |
//!
//! A frame's evidence comes from one source, chosen by how large the tag is and how far apart
//! its two poses stand:
//!
//! | the tag, the two poses | the frame's evidence |
//! |---|---|
//! | [`SMALL_TAG_PX`] or larger | the corners' fit |
//! | smaller, within [`MIN_APART_DEG`] | none: the report sits between the two, at most half their angle from either |
//! | smaller, further apart | the tag's whole picture ([`super::photo`]: each pose refined on every pixel of the tag); the corners' fit where it cannot be drawn |
//!
//! The corners' verdict rests on hundredths of a pixel. On a tag 0.5 m away (44 px) it holds —
//! it reads a face-on box's 3° pitch right, where the picture says little — but on a small tag
//! the corners' own bias outweighs the mirror's mark: at 1 m a hand holding the box still had
//! its corners favour the wrong pose in 7,935 of 8,731 frames, reported 10° off for minutes,
//! and under motion blur a kick pitched 18° one way was reported 18° the other. The picture
//! favours the true pose in both. Counting both sources at once left a held tag swinging
//! between their verdicts (bows read from a still hand), and so did the corners judging where
//! the picture did not, near face-on.
//!
//! When several tags are in sight the pose has no mirror ([`super::fuse`]) and the branches
//! collapse onto it ([`MirrorChooser::settle`]).

use glam::{DMat3, DQuat, DVec3};

use super::detect::CameraPose;

/// Fastest turn expected of a toy in a child's hand, rad/s: sets how costly a jump between
/// branches is (a jump of this rate times the frame interval costs half a nat).
pub const TURN_RAD_S: f64 = 3.0;

/// Corner noise assumed before any fit measured it: RMS per corner, pixels.
pub const START_NOISE_PX: f64 = 0.1;

/// Least corner noise assumed, RMS per corner, pixels: below it, a fit's error says more about
/// the detector's rounding than about the pose.
pub const MIN_NOISE_PX: f64 = 0.03;

/// Most evidence one frame can give for a pose over its mirror, nats: a frame smeared by
/// motion misfits both poses by more than noise, and must not decide the branch alone.
pub const MAX_FRAME_NATS: f64 = 4.0;

/// Gap after which the branches are forgotten, seconds (the tag out of sight: on its return
/// it may be turned any way).
pub const MAX_GAP_S: f64 = 0.25;

/// Corner travel since the last frame (pixels, the largest of the four) at which a frame's
/// fit counts as fresh evidence. A still tag shows the same picture frame after frame, and
/// whatever biases its corners (the lens, the light, the pixel grid) favours the same pose
/// every time: summing those frames would count one observation many times over. On the
/// track bench a still tag near face-on fits its wrong pose 2–3× better for tens of frames.
pub const FRESH_PX: f64 = 1.0;

/// Side of a tag, pixels (the mean of its four edges), under which its picture judges the
/// mirror instead of its corners (see the module text): a 4 cm tag is smaller from about
/// 0.75 m through a 60° lens at 640 × 480.
pub const SMALL_TAG_PX: f64 = 30.0;

/// Least angle between a small tag's two poses, degrees, for a frame to say which is true:
/// nearer face-on the two look alike, and the picture's verdict swings from frame to frame
/// (a jump at 1 m read as a crouch, its tilt swapped back and forth).
pub const MIN_APART_DEG: f64 = 8.0;

/// How fast the corner-noise estimate follows the fits, per frame (a mean over ~20 frames).
const NOISE_RATE: f64 = 0.05;

/// One branch: the pose at the end of its cheapest path, and that path's cost in nats
/// (relative: the cheapest branch costs 0).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Branch {
    pose: CameraPose,
    cost: f64,
}

/// Follows a lone tag's mirror poses and reports the likelier (see the module's text).
#[derive(Debug, Clone)]
pub struct MirrorChooser {
    branches: Vec<Branch>,
    last_t: f64,
    /// The last lone tag's corners, pixels.
    last_corners: Option<[[f64; 2]; 4]>,
    /// Mean square corner error of the better fit, pixels² (RMS per corner, squared).
    noise_px2: f64,
}

impl Default for MirrorChooser {
    fn default() -> Self {
        Self {
            branches: Vec::new(),
            last_t: f64::NEG_INFINITY,
            last_corners: None,
            noise_px2: START_NOISE_PX * START_NOISE_PX,
        }
    }
}

impl MirrorChooser {
    /// Reports one of `candidates` — the poses one tag admits at `t` seconds (body poses in
    /// the camera frame, each with its tag's RMS corner error in pixels) seen at `corners`
    /// (pixels) — and carries both on as branches; `None` when there is no candidate.
    /// `picture` gives the tag's whole picture's verdict on the candidates
    /// ([`super::photo::evidence`]: nats, one per candidate, `None` when it cannot judge); it is
    /// asked only where the picture judges (see the module text).
    pub fn choose(
        &mut self,
        t: f64,
        candidates: &[CameraPose],
        corners: &[[f64; 2]; 4],
        picture: impl FnOnce() -> Option<Vec<f64>>,
    ) -> Option<CameraPose> {
        let lo = candidates
            .iter()
            .map(|c| c.error)
            .filter(|e| e.is_finite())
            .fold(f64::INFINITY, f64::min);
        if !lo.is_finite() {
            return None;
        }
        let noise = self.noise_px2.max(MIN_NOISE_PX * MIN_NOISE_PX);
        // Negative log-likelihood of each pose's corners beyond the better fit's: with 8
        // coordinates and 6 pose parameters, E[sum of squares] = 2σ², and the RMS per corner
        // squared is a quarter of that sum, so the nats are e² / E[e_lo²] (minus the best).
        let travel = self.last_corners.map_or(f64::INFINITY, |last| {
            (0..4)
                .map(|i| (corners[i][0] - last[i][0]).hypot(corners[i][1] - last[i][1]))
                .fold(0.0, f64::max)
        });
        let dt = t - self.last_t;
        let fresh = self.branches.is_empty() || !(dt > 0.0 && dt <= MAX_GAP_S);
        // After a gap the tag may have turned any way: its first frame is fresh evidence.
        let fresh_share = if fresh {
            1.0
        } else {
            (travel / FRESH_PX).min(1.0)
        };
        let corner_nats = |c: &CameraPose| {
            fresh_share * ((c.error * c.error - lo * lo) / noise).min(MAX_FRAME_NATS)
        };
        let nats: Vec<f64> = if side_px(corners) >= SMALL_TAG_PX {
            candidates.iter().map(corner_nats).collect()
        } else if apart_deg(candidates) < MIN_APART_DEG {
            vec![0.0; candidates.len()]
        } else {
            match picture().filter(|p| p.len() == candidates.len()) {
                Some(p) => p.iter().map(|n| n.min(MAX_FRAME_NATS)).collect(),
                None => candidates.iter().map(corner_nats).collect(),
            }
        };
        let step = TURN_RAD_S * dt.max(1e-3);
        let mut next: Vec<Branch> = candidates
            .iter()
            .enumerate()
            .filter(|(_, c)| c.error.is_finite())
            .map(|(i, c)| {
                let q = c.quat();
                let reach = if fresh {
                    0.0
                } else {
                    self.branches
                        .iter()
                        .map(|b| {
                            let turn = angle_rad(b.pose.quat(), q) / step;
                            b.cost + 0.5 * turn * turn
                        })
                        .fold(f64::INFINITY, f64::min)
                };
                Branch {
                    pose: *c,
                    cost: reach + nats.get(i).copied().unwrap_or(0.0),
                }
            })
            .collect();
        let best = next.iter().map(|b| b.cost).fold(f64::INFINITY, f64::min);
        for b in &mut next {
            b.cost -= best;
        }
        self.noise_px2 += NOISE_RATE * (lo * lo - self.noise_px2);
        self.branches = next;
        self.last_t = t;
        self.last_corners = Some(*corners);
        posterior_mean(&self.branches)
    }

    /// A pose known without the mirror's doubt (several tags in sight) at `t`: every branch
    /// collapses onto it.
    pub fn settle(&mut self, t: f64, pose: &CameraPose) {
        self.branches = vec![Branch {
            pose: *pose,
            cost: 0.0,
        }];
        self.last_t = t;
        self.last_corners = None;
    }
}

/// The branches' posterior mean (see the module's text): the cheapest branch's pose, moved
/// toward the next cheapest by its share e^−Δ / (1 + e^−Δ) of the two, Δ their cost
/// difference in nats; the best fit's corner error is kept. `None` without branches.
fn posterior_mean(branches: &[Branch]) -> Option<CameraPose> {
    let best = cheapest(branches.iter())?;
    let Some(other) = cheapest(branches.iter().filter(|b| !core::ptr::eq(*b, best))) else {
        return Some(best.pose);
    };
    let w = (best.cost - other.cost).exp();
    let share = w / (1.0 + w);
    if !share.is_finite() {
        return Some(best.pose);
    }
    let (qa, qb) = (best.pose.quat(), other.pose.quat());
    let qb = if qa.dot(qb) < 0.0 { -qb } else { qb };
    let (ta, tb) = (
        DVec3::from_array(best.pose.translation),
        DVec3::from_array(other.pose.translation),
    );
    Some(CameraPose::from_parts(
        DMat3::from_quat(qa.slerp(qb, share).normalize()),
        ta.lerp(tb, share),
        best.pose.error.min(other.pose.error),
    ))
}

/// A tag's side, pixels: the mean of its four edges.
fn side_px(corners: &[[f64; 2]; 4]) -> f64 {
    (0..4)
        .map(|i| {
            let (a, b) = (corners[i], corners[(i + 1) % 4]);
            (a[0] - b[0]).hypot(a[1] - b[1])
        })
        .sum::<f64>()
        / 4.0
}

/// Angle between the first two of `candidates`, degrees (0 with fewer than two).
fn apart_deg(candidates: &[CameraPose]) -> f64 {
    match candidates {
        [a, b, ..] => angle_rad(a.quat(), b.quat()).to_degrees(),
        _ => 0.0,
    }
}

/// The branch ending the cheapest path (the hard choice the posterior mean softens).
fn cheapest<'a>(branches: impl Iterator<Item = &'a Branch>) -> Option<&'a Branch> {
    branches.min_by(|a, b| a.cost.total_cmp(&b.cost))
}

/// Angle between two rotations, radians (q and −q are the same).
fn angle_rad(a: DQuat, b: DQuat) -> f64 {
    2.0 * a.dot(b).abs().min(1.0).acos()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(tilt_deg: f64, error: f64) -> CameraPose {
        let r = DMat3::from_rotation_x(tilt_deg.to_radians());
        CameraPose::from_parts(r, DVec3::new(0.0, 0.0, 1.0), error)
    }

    /// The tilt about x, degrees, signed.
    fn tilt_of(p: &CameraPose) -> f64 {
        let q = p.quat();
        angle_rad(q, DQuat::IDENTITY).to_degrees() * (q.x * q.w).signum()
    }

    /// A square tag's corners, `side` pixels wide, moved `px` pixels to the right.
    fn square(side: f64, px: f64) -> [[f64; 2]; 4] {
        [[0.0, 0.0], [1.0, 0.0], [1.0, -1.0], [0.0, -1.0]]
            .map(|[x, y]| [300.0 + px + side * x, 260.0 + side * y])
    }

    /// A tag's corners (40 px wide, as a 4 cm tag at 0.55 m) moved `px` pixels to the right.
    fn corners(px: f64) -> [[f64; 2]; 4] {
        square(40.0, px)
    }

    /// A small tag's corners (20 px wide, as a 4 cm tag at 1.1 m) moved `px` to the right.
    fn small_corners(px: f64) -> [[f64; 2]; 4] {
        square(20.0, px)
    }

    #[test]
    fn a_small_tag_s_picture_judges_in_place_of_its_corners_and_a_large_tag_s_corners_judge() {
        // The corners favour −12° every frame, the picture (when it can be drawn) +12°, the
        // tag moving 2 px a frame.
        let run = |corners: fn(f64) -> [[f64; 2]; 4], picture: Option<Vec<f64>>| {
            let mut m = MirrorChooser::default();
            let asked = std::cell::Cell::new(0);
            let mut out = None;
            for i in 0..15 {
                out = m.choose(
                    i as f64 / 30.0,
                    &[pose(-12.0, 0.04), pose(12.0, 0.1)],
                    &corners(2.0 * i as f64),
                    || {
                        asked.set(asked.get() + 1);
                        picture.clone()
                    },
                );
            }
            (tilt_of(&out.unwrap()), asked.get())
        };
        let (small, asked) = run(small_corners, Some(vec![3.0, 0.0]));
        assert!(small > 11.0, "{small}");
        assert_eq!(asked, 15);
        let (large, asked) = run(corners, Some(vec![3.0, 0.0]));
        assert!(large < -11.0, "{large}");
        assert_eq!(asked, 0, "a large tag's picture is not drawn");
        // A picture that cannot be drawn leaves the small tag to its corners.
        let (undrawn, _) = run(small_corners, None);
        assert!(undrawn < -11.0, "{undrawn}");
    }

    #[test]
    fn a_small_tag_near_face_on_is_reported_between_its_poses_whatever_its_corners_say() {
        // ±3°: within MIN_APART_DEG. The corners favour −3° by far, frame after frame, as the
        // tag moves; neither they nor the picture judge, and the report stays square.
        let mut m = MirrorChooser::default();
        for i in 0..30 {
            let out = m
                .choose(
                    i as f64 / 30.0,
                    &[pose(-3.0, 0.03), pose(3.0, 0.2)],
                    &small_corners(2.0 * i as f64),
                    || panic!("the picture is not asked within MIN_APART_DEG"),
                )
                .unwrap();
            assert!(tilt_of(&out).abs() < 0.1, "frame {i}: {}", tilt_of(&out));
        }
    }

    #[test]
    fn the_better_fit_wins_over_frames_even_against_a_wrong_start() {
        let mut m = MirrorChooser::default();
        // Face-on: the two poses are one.
        for i in 0..10 {
            let t = i as f64 / 30.0;
            m.choose(
                t,
                &[pose(0.5, 0.05), pose(-0.5, 0.06)],
                &corners(0.0),
                || None,
            );
        }
        // The tag tilts to +20° as it moves 2 px a frame; its mirror sits at −20°. The first
        // frames after the parting favour the mirror, then the true pose fits better by the
        // bench's margin.
        let mut reported = Vec::new();
        for i in 1..=12 {
            let t = (10 + i) as f64 / 30.0;
            let tilt = (2.0 * i as f64).min(20.0);
            let (good, bad) = if i <= 2 { (0.09, 0.04) } else { (0.05, 0.11) };
            let out = m
                .choose(
                    t,
                    &[pose(-tilt, bad), pose(tilt, good)],
                    &corners(2.0 * i as f64),
                    || None,
                )
                .unwrap();
            reported.push(tilt_of(&out));
        }
        let wrong = reported.iter().filter(|&&a| a < 0.0).count();
        assert!(wrong <= 4, "{wrong} frames on the mirror: {reported:?}");
        assert!(reported[6..].iter().all(|&a| a > 0.0), "{reported:?}");
    }

    #[test]
    fn a_still_tag_s_repeated_misfit_is_one_observation() {
        let mut m = MirrorChooser::default();
        m.settle(0.0, &pose(2.0, 0.05));
        // Still, the same picture every frame: the mirror fits 2.5× better each time, but it
        // is one look at one biased picture, and the report stays nearer the pose nearer the
        // last (4°) than the mirror (−8°).
        for i in 1..30 {
            let out = m
                .choose(
                    i as f64 / 30.0,
                    &[pose(-8.0, 0.04), pose(4.0, 0.1)],
                    &corners(0.01 * (i % 2) as f64),
                    || None,
                )
                .unwrap();
            assert!(tilt_of(&out) > -2.0, "frame {i}: {}", tilt_of(&out));
        }
        // The same misfit on a moving tag is fresh each frame: the mirror takes over.
        let out = (30..40)
            .map(|i| {
                m.choose(
                    i as f64 / 30.0,
                    &[pose(-8.0, 0.04), pose(4.0, 0.1)],
                    &corners(3.0 * i as f64),
                    || None,
                )
                .unwrap()
            })
            .last()
            .unwrap();
        assert!(tilt_of(&out) < -7.0, "{}", tilt_of(&out));
    }

    #[test]
    fn the_report_weighs_the_branches_by_their_likelihood() {
        let branch = |tilt: f64, cost: f64| Branch {
            pose: pose(tilt, 0.05),
            cost,
        };
        let mean = |b: &[Branch]| tilt_of(&posterior_mean(b).unwrap());
        assert!(mean(&[branch(6.0, 0.0), branch(-6.0, 0.0)]).abs() < 1e-6);
        // One nat: e^-1 / (1 + e^-1) = 27 % of the way; three nats: 5 %.
        assert!((mean(&[branch(6.0, 0.0), branch(-6.0, 1.0)]) - 2.78).abs() < 0.01);
        assert!((mean(&[branch(-6.0, 3.0), branch(6.0, 0.0)]) - 5.43).abs() < 0.01);
        assert!((mean(&[branch(6.0, 0.0), branch(-6.0, f64::INFINITY)]) - 6.0).abs() < 1e-9);
        assert!((mean(&[branch(6.0, 0.0)]) - 6.0).abs() < 1e-9);
        assert!(posterior_mean(&[]).is_none());
    }

    #[test]
    fn a_far_tag_held_still_does_not_swap_tilts_when_its_estimate_passes_face_on() {
        // A tag 5° from square at a distance, held in a trembling hand (its corners move 0.3 px a
        // frame). Its tilt estimate is noisy, and every seventh frame it passes near face-on,
        // where the mirror fits a little better (the picture's bias). The cheapest path then
        // crosses to the mirror now and then; the report must not jump by the poses' whole
        // separation (10°) when it does.
        let mut m = MirrorChooser::default();
        let mut rng = crate::synth::rng::SynthRng::from_u64(7);
        let mut uniform = || rng.unit();
        let (mut hard_flips, mut last_hard, mut worst) = (0, 5.0, 0.0_f64);
        let mut last: Option<f64> = None;
        for i in 0..600 {
            let tilt = if i % 7 == 0 {
                0.5
            } else {
                5.0 + 2.0 * (uniform() - 0.5)
            };
            let (good, bad) = (0.05 + 0.02 * uniform(), 0.045 + 0.02 * uniform());
            let out = m
                .choose(
                    i as f64 / 30.0,
                    &[pose(tilt, good), pose(-tilt, bad)],
                    &corners(0.3 * (i % 2) as f64),
                    || None,
                )
                .unwrap();
            let hard = tilt_of(&cheapest(m.branches.iter()).unwrap().pose);
            if hard * last_hard < 0.0 && hard.abs() > 3.0 {
                hard_flips += 1;
            }
            if hard.abs() > 3.0 {
                last_hard = hard;
            }
            let now = tilt_of(&out);
            if let Some(before) = last {
                worst = worst.max((now - before).abs());
            }
            last = Some(now);
        }
        assert!(
            hard_flips > 0,
            "the scene must make the cheapest path cross"
        );
        assert!(worst < 6.0, "the report jumped {worst}°");
    }

    #[test]
    fn noise_alone_does_not_flip_a_moving_tilted_tag_from_frame_to_frame() {
        let mut m = MirrorChooser::default();
        let mut sides = Vec::new();
        for i in 0..60 {
            let t = i as f64 / 30.0;
            // The true pose at +12°, its mirror at −12°, the tag moving: noise makes the
            // mirror fit better one frame in four, the true pose the other three.
            let (a, b) = if i % 4 == 0 {
                (0.06, 0.05)
            } else {
                (0.05, 0.06)
            };
            let out = m
                .choose(
                    t,
                    &[pose(12.0, a), pose(-12.0, b)],
                    &corners(i as f64),
                    || None,
                )
                .unwrap();
            sides.push(tilt_of(&out) > 0.0);
        }
        // The evidence settles it within a few frames, and the mirror's better frames do not
        // flip it back.
        assert!(sides[5..].iter().all(|&s| s), "{sides:?}");
    }

    #[test]
    fn a_settled_pose_anchors_the_next_choice_and_a_gap_forgets_it() {
        let mut m = MirrorChooser::default();
        m.settle(0.0, &pose(15.0, 0.1));
        // Next frame: a tie between 15° and its mirror; continuity keeps 15°.
        let c = corners(5.0);
        let out = m.choose(
            1.0 / 30.0,
            &[pose(-15.0, 0.05), pose(15.0, 0.05)],
            &c,
            || None,
        );
        assert!(tilt_of(&out.unwrap()) > 0.0);
        // After a long gap the better fit alone decides.
        let out = m.choose(2.0, &[pose(-15.0, 0.04), pose(15.0, 0.08)], &c, || None);
        assert!(tilt_of(&out.unwrap()) < 0.0);
        // No candidate, no pose.
        assert!(m.choose(2.1, &[], &c, || None).is_none());
    }
}
