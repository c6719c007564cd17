//! Feet and the ground: leg chains found automatically, foot contacts detected, and ground
//! penetration removed with two-bone IK (hip–knee–ankle), raising the root only when a leg
//! cannot reach.
//!
//! Legs: the two leaves lowest in the first frame are the toes; up each toe's chain, the
//! hip–knee–ankle triple is the pair of consecutive bones with the largest shorter bone (thigh
//! and shin are the long ones). A foot's points are its ankle and everything below it.
//! A foot is in contact when its lowest point is within [`CONTACT_HEIGHT`] of the ground and
//! it moves slower than [`CONTACT_SPEED`] horizontally. After effort transfer, whose rescaling
//! of the root's height would otherwise lift a strong action off the ground, the frames in
//! which the source clip stood are put back on the ground ([`keep_source_contacts`]).

use glam::{Quat, Vec3};

use crate::motion::{Clip, Skeleton};

/// Height above the ground (metres) under which a foot can be in contact.
pub const CONTACT_HEIGHT: f32 = 0.05;
/// Horizontal foot speed (m/s) under which a low foot is in contact.
pub const CONTACT_SPEED: f32 = 0.5;
/// Ground height, metres.
pub const GROUND_Y: f32 = 0.0;

/// One leg: joint indices, and the foot's points (ankle and its descendants).
#[derive(Debug, Clone, PartialEq)]
pub struct Leg {
    /// Hip joint (top of the thigh).
    pub hip: usize,
    /// Knee joint.
    pub knee: usize,
    /// Ankle joint.
    pub ankle: usize,
    /// The ankle and every joint below it.
    pub foot: Vec<usize>,
}

impl Leg {
    /// The height (m) of the lowest point of the foot among world positions `world` (∞ when
    /// none of its joints is there).
    pub fn lowest_y(&self, world: &[Vec3]) -> f32 {
        self.foot
            .iter()
            .filter_map(|&j| world.get(j).map(|p| p.y))
            .fold(f32::INFINITY, f32::min)
    }
}

/// Finds the legs of a skeleton from a clip's first frame (empty if none are found).
pub fn find_legs(clip: &Clip) -> Vec<Leg> {
    let sk = &clip.skeleton;
    let p = clip.joint_positions(0);
    if p.is_empty() {
        return Vec::new();
    }
    let mut leaves: Vec<usize> = (0..sk.len())
        .filter(|&j| sk.children(j).is_empty())
        .collect();
    leaves.sort_by(|&a, &b| p[a].y.total_cmp(&p[b].y));
    let mut legs: Vec<Leg> = Vec::new();
    for leaf in leaves {
        if legs.len() == 2 {
            break;
        }
        let chain = sk.chain_to(leaf);
        // chain: root … leaf. Candidate triples (hip, knee, ankle) = chain[k], [k+1], [k+2].
        let mut best: Option<(usize, f32)> = None;
        for k in 1..chain.len().saturating_sub(2) {
            let (a, b, c) = (chain[k], chain[k + 1], chain[k + 2]);
            let l = (p[b] - p[a]).length().min((p[c] - p[b]).length());
            if best.is_none_or(|(_, bl)| l > bl) {
                best = Some((k, l));
            }
        }
        let Some((k, l)) = best else { continue };
        if l <= 1e-6 {
            continue;
        }
        let (hip, knee, ankle) = (chain[k], chain[k + 1], chain[k + 2]);
        if legs.iter().any(|g| g.hip == hip || g.ankle == ankle) {
            continue;
        }
        let foot = descendants(sk, ankle);
        legs.push(Leg {
            hip,
            knee,
            ankle,
            foot,
        });
    }
    legs
}

fn descendants(sk: &Skeleton, j: usize) -> Vec<usize> {
    let mut out = vec![j];
    let mut i = 0;
    while i < out.len() {
        out.extend(sk.children(out[i]));
        i += 1;
    }
    out
}

/// Per leg, per frame: whether the foot is in contact with the ground.
pub fn detect_contacts(clip: &Clip, legs: &[Leg]) -> Vec<Vec<bool>> {
    let pos = clip.all_positions();
    let dt = clip.frame_time.max(1e-6);
    legs.iter()
        .map(|leg| {
            (0..pos.len())
                .map(|f| {
                    let low = leg.lowest_y(&pos[f]);
                    let (a, b) = (f.saturating_sub(1), (f + 1).min(pos.len() - 1));
                    let d = pos[b][leg.ankle] - pos[a][leg.ankle];
                    let v = Vec3::new(d.x, 0.0, d.z).length() / ((b - a).max(1) as f32 * dt);
                    low < GROUND_Y + CONTACT_HEIGHT && v < CONTACT_SPEED
                })
                .collect()
        })
        .collect()
}

/// Frames over which a pinned foot eases in and out of its pin.
pub const PIN_EASE_FRAMES: usize = 3;

/// Pins planted feet: for every run of contact frames of a leg, the foot's contact point (its
/// lowest in the run's middle frame) is held (in the ground plane) where it was in that
/// frame, by two-bone IK, easing in and out over [`PIN_EASE_FRAMES`] frames; its height stays
/// the animation's. Unreachable pins are approached as far as the leg allows.
pub fn pin_feet(clip: &mut Clip, legs: &[Leg], contacts: &[Vec<bool>]) {
    let sk = clip.skeleton.clone();
    let n = clip.len();
    for (leg, flags) in legs.iter().zip(contacts) {
        let mut f = 0;
        while f < n {
            if !flags.get(f).copied().unwrap_or(false) {
                f += 1;
                continue;
            }
            let a = f;
            while f < n && flags.get(f).copied().unwrap_or(false) {
                f += 1;
            }
            let b = f - 1;
            if b == a {
                continue;
            }
            let mid = (a + b) / 2;
            // The point the foot stands on (its lowest in the run's middle frame) is held,
            // not the ankle: a foot that pivots about its toes on a pinned ankle still slides
            // its toes across the floor. IK keeps the foot's orientation, so moving the ankle
            // by the contact point's slip puts the contact point back.
            let mid_pos = sk.positions(&clip.frames[mid]);
            let point = leg
                .foot
                .iter()
                .copied()
                .min_by(|&i, &j| mid_pos[i].y.total_cmp(&mid_pos[j].y))
                .unwrap_or(leg.ankle);
            let pin = mid_pos[point];
            let lo = a.saturating_sub(PIN_EASE_FRAMES);
            let hi = (b + PIN_EASE_FRAMES).min(n - 1);
            for g in lo..=hi {
                let w = if g < a {
                    (g + 1 - lo) as f32 / (a + 1 - lo) as f32
                } else if g > b {
                    (hi + 1 - g) as f32 / (hi + 1 - b) as f32
                } else {
                    1.0
                };
                let pose = &mut clip.frames[g];
                let world = sk.positions(pose);
                let (own, at) = (world[leg.ankle], world[point]);
                let target = Vec3::new(
                    own.x + (pin.x - at.x) * w,
                    own.y,
                    own.z + (pin.z - at.z) * w,
                );
                if (target - own).length() > 1e-5 {
                    two_bone_ik(&sk, pose, leg, target);
                }
            }
        }
    }
}

/// Per frame of `clip`, per leg: the height of the foot's lowest point (∞ without points).
fn foot_heights(clip: &Clip, legs: &[Leg]) -> Vec<Vec<f32>> {
    clip.frames
        .iter()
        .map(|p| {
            let world = clip.skeleton.positions(p);
            legs.iter().map(|l| l.lowest_y(&world)).collect()
        })
        .collect()
}

/// Keeps on the ground the feet that `src` had on it: `out` (the same frames after effort
/// transfer, which rescales the root's height) is moved up or down, frame by frame, so that
/// the foot the source stood on (its lowest, when within [`CONTACT_HEIGHT`] of the ground) is
/// as high as it was in the source; in the air the correction of the frames around is
/// blended, so an amplified jump flies higher but takes off and lands where the source did.
/// The standing foot, not whichever foot is now lowest, sets the height: an amplified kick
/// swings its free foot through the floor (the ground pass lifts that foot with IK), and
/// lifting the whole body onto it would pop the character a metre up for a frame.
/// Returns the largest correction, metres.
pub fn keep_source_contacts(src: &Clip, out: &mut Clip) -> f32 {
    let legs = find_legs(src);
    if legs.is_empty() || src.len() != out.len() {
        return 0.0;
    }
    let was = foot_heights(src, &legs);
    let now = foot_heights(out, &legs);
    let grounded: Vec<Option<f32>> = was
        .iter()
        .zip(&now)
        .map(|(w, n)| {
            let (leg, &low) = w.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1))?;
            let d = low - n.get(leg)?;
            (low < GROUND_Y + CONTACT_HEIGHT && d.is_finite()).then_some(d)
        })
        .collect();
    let mut corrections = Vec::with_capacity(out.len());
    for f in 0..out.len() {
        let before = grounded[..=f]
            .iter()
            .enumerate()
            .rev()
            .find_map(|(i, c)| c.map(|c| (i, c)));
        let after = grounded[f..]
            .iter()
            .enumerate()
            .find_map(|(i, c)| c.map(|c| (f + i, c)));
        let corr = match (before, after) {
            (Some((a, ca)), Some((b, cb))) if b > a => {
                ca + (cb - ca) * (f - a) as f32 / (b - a) as f32
            }
            (Some((_, c)), _) | (None, Some((_, c))) => c,
            (None, None) => 0.0,
        };
        corrections.push(corr);
    }
    // Which foot the source stood on changes from frame to frame (a step, both feet down);
    // where rescaling left the two at different heights, following each in turn would bounce
    // the body by their difference at every switch. The correction is smoothed over
    // CONTACT_SMOOTH_S either side: the body settles onto the new foot as a person shifts
    // weight (the ground pass then lifts whatever foot would sink).
    let half = (CONTACT_SMOOTH_S / out.frame_time.max(1e-6)).round() as usize;
    let corrections = smooth(&smooth(&corrections, half), half);
    let mut largest = 0.0f32;
    for (pose, corr) in out.frames.iter_mut().zip(corrections) {
        if let Some(t) = pose.translations.first_mut() {
            t.y += corr;
        }
        largest = largest.max(corr.abs());
    }
    largest
}

/// Seconds either side over which [`keep_source_contacts`] smooths its height correction.
pub const CONTACT_SMOOTH_S: f32 = 0.1;

/// The mean of `xs` over `half` samples either side (the ends repeated).
fn smooth(xs: &[f32], half: usize) -> Vec<f32> {
    let n = xs.len() as isize;
    let h = half as isize;
    (0..n)
        .map(|i| {
            (i - h..=i + h)
                .map(|k| xs[k.clamp(0, n - 1) as usize])
                .sum::<f32>()
                / (2 * h + 1) as f32
        })
        .collect()
}

/// Frames either side over which [`keep_feet_above_floor`] spreads a frame's restraint, so
/// that the rescaling eases off and back on rather than snapping.
pub const FLOOR_EASE_FRAMES: usize = 4;
/// Bisection steps of [`keep_feet_above_floor`].
const FLOOR_BISECTIONS: usize = 10;

/// Where rescaling sends a foot through the floor deeper than [`CONTACT_HEIGHT`] (an
/// amplified free leg swung down while the standing leg, folded deeper, lowered the body),
/// draws the legs of `out` back towards `src` (the same frames before effort transfer) just
/// enough that it does not: per frame the largest share of the change (the legs' rotations
/// slerped, the root's height interpolated) that keeps every foot above `−CONTACT_HEIGHT`, the smallest share over
/// [`FLOOR_EASE_FRAMES`] either side applied. The ground pass's IK lifts what a foot may
/// still sink; deeper, it would fold the knee shut. The floor bounds an amplified swing as
/// the joints' ranges do. Returns how many frames it drew back.
pub fn keep_feet_above_floor(src: &Clip, out: &mut Clip) -> usize {
    let legs = find_legs(src);
    if legs.is_empty() || src.len() != out.len() {
        return 0;
    }
    // Only the legs are drawn back (and the root's height): the arms keep their effort.
    let leg_joints: Vec<usize> = legs
        .iter()
        .flat_map(|l| [l.hip, l.knee].into_iter().chain(l.foot.iter().copied()))
        .collect();
    let blend = |a: &crate::motion::Pose, b: &crate::motion::Pose, s: f32| {
        let mut p = b.clone();
        for &j in &leg_joints {
            if let (Some(q), Some(qa), Some(qb)) = (
                p.rotations.get_mut(j),
                a.rotations.get(j),
                b.rotations.get(j),
            ) {
                *q = qa.slerp(*qb, s).normalize();
            }
        }
        if let (Some(t), Some(ta), Some(tb)) = (
            p.translations.first_mut(),
            a.translations.first(),
            b.translations.first(),
        ) {
            t.y = ta.y + (tb.y - ta.y) * s;
        }
        p
    };
    let lowest = |p: &crate::motion::Pose| {
        let w = out.skeleton.positions(p);
        legs.iter()
            .flat_map(|l| l.foot.iter())
            .filter_map(|&j| w.get(j).map(|v| v.y))
            .fold(f32::INFINITY, f32::min)
    };
    let floor = GROUND_Y - CONTACT_HEIGHT;
    let share: Vec<f32> = src
        .frames
        .iter()
        .zip(&out.frames)
        .map(|(a, b)| {
            if lowest(b) >= floor || lowest(a) < floor {
                return 1.0;
            }
            let (mut ok, mut bad) = (0.0f32, 1.0f32);
            for _ in 0..FLOOR_BISECTIONS {
                let mid = 0.5 * (ok + bad);
                if lowest(&blend(a, b, mid)) >= floor {
                    ok = mid;
                } else {
                    bad = mid;
                }
            }
            ok
        })
        .collect();
    let n = share.len();
    // The smallest share within FLOOR_EASE_FRAMES, then its mean over as many frames either
    // side: never more than any frame near needs (each of the minima averaged saw this
    // frame), and changing evenly rather than in steps, which would move the root's height by
    // the step in one frame.
    let window = |f: usize| {
        f.saturating_sub(FLOOR_EASE_FRAMES)..=(f + FLOOR_EASE_FRAMES).min(n.saturating_sub(1))
    };
    let least: Vec<f32> = (0..n)
        .map(|f| share[window(f)].iter().copied().fold(1.0f32, f32::min))
        .collect();
    let mut changed = 0;
    for f in 0..n {
        let s = least[window(f)].iter().sum::<f32>() / window(f).count() as f32;
        if s < 1.0 {
            out.frames[f] = blend(&src.frames[f], &out.frames[f], s);
            changed += 1;
        }
    }
    changed
}

/// Least forward bend (rad) of a knee before IK bends it further: the solver keeps the side
/// a knee is bent to, so a straight or overextended knee is first turned this far forward.
pub const KNEE_FORWARD_RAD: f32 = 0.05;

/// Two-bone IK: rotates hip and knee so the ankle reaches `target` (or as close as the leg
/// allows), keeping the knee's bending plane and the foot's world orientation. A knee bends
/// forward, towards the toes: the solver bends a knee further on the side it is already bent
/// to, so a knee that is straight or overextended (the shin swung forward of the thigh, as
/// rescaling or a blend may leave it) is first turned to [`KNEE_FORWARD_RAD`] forward —
/// else IK would fold it backwards.
pub fn two_bone_ik(sk: &Skeleton, pose: &mut crate::motion::Pose, leg: &Leg, target: Vec3) {
    bend_knee_forward(sk, pose, leg);
    let world = sk.forward(pose);
    let (a, b, c) = (
        world[leg.hip].position,
        world[leg.knee].position,
        world[leg.ankle].position,
    );
    let (a_gr, b_gr, c_gr) = (
        world[leg.hip].rotation,
        world[leg.knee].rotation,
        world[leg.ankle].rotation,
    );
    let lab = (b - a).length();
    let lcb = (b - c).length();
    if lab < 1e-6 || lcb < 1e-6 {
        return;
    }
    let eps = 1e-4;
    let lat = (target - a)
        .length()
        .clamp(eps + (lab - lcb).abs(), lab + lcb - eps);
    let acos = |x: f32| x.clamp(-1.0, 1.0).acos();
    let ac_ab_0 = acos((c - a).normalize_or_zero().dot((b - a).normalize_or_zero()));
    let ba_bc_0 = acos((a - b).normalize_or_zero().dot((c - b).normalize_or_zero()));
    let ac_at_0 = acos(
        (c - a)
            .normalize_or_zero()
            .dot((target - a).normalize_or_zero()),
    );
    let ac_ab_1 = acos((lcb * lcb - lab * lab - lat * lat) / (-2.0 * lab * lat));
    let ba_bc_1 = acos((lat * lat - lab * lab - lcb * lcb) / (-2.0 * lab * lcb));
    let mut axis0 = (c - a).cross(b - a).normalize_or_zero();
    if axis0 == Vec3::ZERO {
        // Straight leg: bend forward, about the hip's own lateral direction.
        axis0 = (a_gr * Vec3::Z).normalize_or_zero();
        if axis0 == Vec3::ZERO {
            return;
        }
    }
    let axis1 = (c - a).cross(target - a).normalize_or_zero();
    let r0 = Quat::from_axis_angle((a_gr.inverse() * axis0).normalize(), ac_ab_1 - ac_ab_0);
    let r1 = Quat::from_axis_angle((b_gr.inverse() * axis0).normalize(), ba_bc_1 - ba_bc_0);
    let r2 = if axis1 == Vec3::ZERO {
        Quat::IDENTITY
    } else {
        Quat::from_axis_angle((a_gr.inverse() * axis1).normalize(), ac_at_0)
    };
    pose.rotations[leg.hip] = (pose.rotations[leg.hip] * (r0 * r2)).normalize();
    pose.rotations[leg.knee] = (pose.rotations[leg.knee] * r1).normalize();
    // Keep the foot's world orientation.
    let knee_world = sk.forward(pose)[leg.knee].rotation;
    pose.rotations[leg.ankle] = (knee_world.inverse() * c_gr).normalize();
}

/// Turns a straight or overextended knee of `leg` to [`KNEE_FORWARD_RAD`] forward (see
/// [`two_bone_ik`]): in the plane of the thigh and the knee's forward direction, the shin is
/// swung back until it trails the thigh by that angle. The knee's forward direction is the
/// toes' in the rest pose (a straight leg, feet forward), carried by the thigh: a hinge's
/// forward turns with the thigh, not with the foot (pointed toes would say nothing). Legs
/// without a point beyond the ankle are left alone.
fn bend_knee_forward(sk: &Skeleton, pose: &mut crate::motion::Pose, leg: &Leg) {
    let rest = sk.positions(&crate::motion::Pose::rest(sk));
    let Some(toe) = leg
        .foot
        .iter()
        .filter(|&&j| j != leg.ankle)
        .filter_map(|&j| Some(*rest.get(j)? - *rest.get(leg.ankle)?))
        .max_by(|x, y| x.length_squared().total_cmp(&y.length_squared()))
    else {
        return;
    };
    let (Some(&hip0), Some(&knee0)) = (rest.get(leg.hip), rest.get(leg.knee)) else {
        return;
    };
    let Some(u0) = (knee0 - hip0).try_normalize() else {
        return;
    };
    let Some(f0) = (toe - u0 * toe.dot(u0)).try_normalize() else {
        return;
    };
    let world = sk.forward(pose);
    let (a, b, c) = (
        world[leg.hip].position,
        world[leg.knee].position,
        world[leg.ankle].position,
    );
    let Some(u) = (b - a).try_normalize() else {
        return;
    };
    let Some(d) = (c - b).try_normalize() else {
        return;
    };
    let f = world[leg.hip].rotation * f0;
    let Some(f) = (f - u * f.dot(u)).try_normalize() else {
        return;
    };
    // Signed angle of the shin from the thigh towards the toes: > 0 is overextended.
    let beta = d.dot(f).atan2(d.dot(u));
    if beta <= -KNEE_FORWARD_RAD {
        return;
    }
    let Some(axis) = u.cross(-f).try_normalize() else {
        return;
    };
    let b_gr = world[leg.knee].rotation;
    let turn = Quat::from_axis_angle((b_gr.inverse() * axis).normalize(), beta + KNEE_FORWARD_RAD);
    pose.rotations[leg.knee] = (pose.rotations[leg.knee] * turn).normalize();
}

/// A pelvis with one leg (hip, knee, ankle, toe pointing +Z) and a head, for tests.
#[cfg(test)]
pub(crate) fn leg_skeleton() -> Skeleton {
    let j = crate::motion::skeleton::Joint::bare;
    Skeleton {
        joints: vec![
            j("pelvis", None, Vec3::ZERO),
            j("hip", Some(0), Vec3::new(0.1, 0.0, 0.0)),
            j("knee", Some(1), Vec3::new(0.0, -0.45, 0.0)),
            j("ankle", Some(2), Vec3::new(0.0, -0.45, 0.0)),
            j("toe", Some(3), Vec3::new(0.0, -0.05, 0.12)),
            j("head", Some(0), Vec3::new(0.0, 0.7, 0.0)),
        ],
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::motion::Pose;

    /// One leg whose toe stands 5 cm under the ground, its knee bent 0.2 rad: two frames.
    pub(crate) fn leg_clip() -> Clip {
        let sk = leg_skeleton();
        let mut p = Pose::rest(&sk);
        p.translations[0] = Vec3::new(0.0, 0.9, 0.0); // toe at y = -0.05: 5 cm under ground
        p.rotations[2] = Quat::from_rotation_x(0.2);
        Clip {
            name: "leg".into(),
            skeleton: sk,
            frame_time: 1.0 / 30.0,
            frames: vec![p.clone(), p],
        }
    }

    #[test]
    fn ik_bends_an_overextended_knee_forward_not_further_back() {
        // The toes point +Z; the shin swung 0.3 rad forward of the thigh (overextended).
        let c = leg_clip();
        let legs = find_legs(&c);
        let mut pose = c.frames[0].clone();
        pose.rotations[2] = Quat::from_rotation_x(-0.3);
        let before = c.skeleton.positions(&pose);
        let target = before[3] + Vec3::Y * 0.15;
        two_bone_ik(&c.skeleton, &mut pose, &legs[0], target);
        let p = c.skeleton.positions(&pose);
        assert!((p[3] - target).length() < 1e-3, "{:?} {target}", p[3]);
        // The knee stands forward (+Z) of the hip–ankle line.
        let n = (p[3] - p[1]).normalize();
        let off = (p[2] - p[1]) - n * (p[2] - p[1]).dot(n);
        assert!(off.z > 0.02, "knee offset {off}");
    }

    #[test]
    fn a_foot_rescaled_through_the_floor_is_drawn_back_and_the_rest_kept() {
        // The source stands on the ground for 20 frames; the rescaled copy sinks 0.3 m in
        // frames 9–10 and nowhere else.
        let base = leg_clip();
        let mut src = base.clone();
        src.frames = vec![base.frames[0].clone(); 20];
        let sink = src.joint_positions(0)[4].y.min(src.joint_positions(0)[3].y);
        for p in &mut src.frames {
            p.translations[0].y -= sink;
        }
        let mut out = src.clone();
        for f in [9, 10] {
            out.frames[f].translations[0].y -= 0.3;
        }
        let changed = keep_feet_above_floor(&src, &mut out);
        // The restraint eases in and out over twice FLOOR_EASE_FRAMES either side.
        assert_eq!(changed, 2 + 4 * FLOOR_EASE_FRAMES, "{changed}");
        for f in 0..20 {
            let p = out.joint_positions(f);
            assert!(
                p[3].y.min(p[4].y) >= -CONTACT_HEIGHT - 1e-3,
                "frame {f}: {p:?}"
            );
        }
        assert_eq!(out.frames[0], src.frames[0]);
        assert_eq!(out.frames[19], src.frames[19]);
    }

    #[test]
    fn feet_the_source_stood_on_stay_on_the_ground_and_a_jump_still_flies() {
        // The source stands with its lowest foot point on the ground, jumps 0.2 m for frames
        // 3–5, and lands; the rescaled copy hovers 0.3 m while standing and jumps 0.4 m.
        let base = leg_clip();
        let lowest = |c: &Clip, f: usize| {
            let p = c.joint_positions(f);
            p[3].y.min(p[4].y)
        };
        let lift = |c: &mut Clip, f: usize, dy: f32| c.frames[f].translations[0].y += dy;
        let mut src = base.clone();
        src.frames = vec![base.frames[0].clone(); 9];
        let sink = lowest(&src, 0);
        for f in 0..9 {
            lift(&mut src, f, -sink);
        }
        for f in 3..6 {
            lift(&mut src, f, 0.2);
        }
        let mut out = src.clone();
        for f in 0..9 {
            lift(&mut out, f, 0.3);
        }
        for f in 3..6 {
            lift(&mut out, f, 0.2);
        }
        let largest = keep_source_contacts(&src, &mut out);
        assert!((largest - 0.3).abs() < 1e-4, "{largest}");
        for f in [0, 1, 2, 6, 7, 8] {
            assert!(
                lowest(&out, f).abs() < 1e-4,
                "frame {f}: {}",
                lowest(&out, f)
            );
        }
        // In the air it flies 0.4 m, twice the source's 0.2.
        for f in 3..6 {
            assert!(
                (lowest(&out, f) - 0.4).abs() < 1e-4,
                "frame {f}: {}",
                lowest(&out, f)
            );
        }
    }
}
