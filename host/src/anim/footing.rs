//! Footing: a foot on the ground stands, a foot that moves clears the ground.
//!
//! The assembler pins the feet its source clips plant ([`super::contact::pin_feet`]). That
//! leaves two kinds of foot on the floor unpinned, and both skate:
//! - feet the *animation* sets down where its source did not plant them: a held pose's
//!   standing foot after a clip whose last frame had it sliding, a foot that a source take
//!   lets drift (DeepMimic's punch and dances slide their feet a little, 17–57 cm/s), a foot
//!   rescaling brought down to the floor. Where a foot of the assembled animation is low and
//!   slow ([`detect_contacts`]: within [`CONTACT_HEIGHT`] of the ground, moving slower than
//!   [`super::contact::CONTACT_SPEED`]), it is planted as well ([`planted`]);
//! - feet that sweep along the floor fast: a light Weight rescales every joint's swing
//!   towards the stage's reference pose (eq. 7 with `c = 1 / (1 − Lw)`, about half at full
//!   lightness), so a swinging foot that the source lifted a few centimetres now scuffs the
//!   floor at metres a second (a light run's, a light spin's). A person's swinging foot clears
//!   the floor; [`clear_swing_feet`] lifts every foot that is not planted to at least
//!   [`SWING_CLEARANCE_M`] above the ground by two-bone IK (bending hip and knee; the root and
//!   the rest of the body keep their motion), rising to it over [`CLEARANCE_EASE_FRAMES`] frames
//!   after it leaves the ground and lowering as it comes back, as a foot lifts off.
//!
//! Both change only the legs below the hips: the effort (timing, amplitude of the arms and the
//! torso, the root's path) is kept. And where the ground pass must raise the root because a
//! leg cannot reach the ground, [`raise_evenly`] spreads the raise over the frames around
//! rather than popping the body up for one frame.

use glam::Vec3;

use super::contact::{detect_contacts, two_bone_ik, Leg, CONTACT_HEIGHT, GROUND_Y};
use crate::motion::Clip;

/// Least height (m) of a swinging foot's lowest point above the ground: the height under which
/// a foot can be planted ([`CONTACT_HEIGHT`]), so a foot moving too fast to stand is never low
/// enough to be taken for one standing.
pub const SWING_CLEARANCE_M: f32 = CONTACT_HEIGHT;

/// Frames over which a foot leaving the ground rises to [`SWING_CLEARANCE_M`] (and lowers from
/// it as it comes back): its clearance grows by an even share of it per frame away from the
/// nearest planted frame.
pub const CLEARANCE_EASE_FRAMES: usize = 3;

/// Per leg, per frame: the feet `source` plants (the source clips' contacts), and those the
/// assembled `clip` itself holds low and slow on the ground ([`detect_contacts`]).
pub fn planted(clip: &Clip, legs: &[Leg], source: &[Vec<bool>]) -> Vec<Vec<bool>> {
    let own = detect_contacts(clip, legs);
    own.iter()
        .enumerate()
        .map(|(l, flags)| {
            flags
                .iter()
                .enumerate()
                .map(|(f, &c)| c || source.get(l).and_then(|s| s.get(f)).copied() == Some(true))
                .collect()
        })
        .collect()
}

/// The clearance (m) a leg's foot keeps at each frame: 0 where `flags` plants it, else
/// [`SWING_CLEARANCE_M`] times the share of [`CLEARANCE_EASE_FRAMES`] (capped at 1) the frame
/// lies from the nearest planted frame (the full clearance without any).
fn clearance(flags: &[bool]) -> Vec<f32> {
    let n = flags.len();
    let far = CLEARANCE_EASE_FRAMES as f32;
    // Frames since the last planted frame, and until the next one.
    let mut since = vec![f32::INFINITY; n];
    let mut last: Option<usize> = None;
    for (f, &c) in flags.iter().enumerate() {
        if c {
            last = Some(f);
        }
        if let Some(l) = last {
            since[f] = (f - l) as f32;
        }
    }
    let mut next: Option<usize> = None;
    let mut out = vec![0.0; n];
    for f in (0..n).rev() {
        if flags[f] {
            next = Some(f);
        }
        let until = next.map_or(f32::INFINITY, |k| (k - f) as f32);
        out[f] = SWING_CLEARANCE_M * (since[f].min(until) / far).min(1.0);
    }
    out
}

/// Lifts every foot of `clip` that `contacts` does not plant to its clearance above the
/// ground (see the module notes), by two-bone IK on its leg. Returns how many (frame, leg)
/// pairs it lifted.
pub fn clear_swing_feet(clip: &mut Clip, legs: &[Leg], contacts: &[Vec<bool>]) -> usize {
    let sk = clip.skeleton.clone();
    let mut lifted = 0;
    for (leg, flags) in legs.iter().zip(contacts) {
        let least = clearance(flags);
        for (pose, &want) in clip.frames.iter_mut().zip(&least) {
            if want <= 0.0 {
                continue;
            }
            let world = sk.positions(pose);
            let low = leg.lowest_y(&world);
            if low.is_nan() || low >= GROUND_Y + want {
                continue;
            }
            set_foot_height(&sk, pose, leg, GROUND_Y + want);
            lifted += 1;
        }
    }
    lifted
}

/// Frames either side over which [`raise_evenly`] spreads the raise of a frame.
pub const RAISE_EASE_FRAMES: usize = 4;

/// Raises the root of each frame of `clip` by at least `need[f]` metres (what its legs could
/// not reach of the ground; [`fix_ground`]), the raise spread over
/// [`RAISE_EASE_FRAMES`] either side: per frame the mean, over that window, of the largest
/// need within the same window of each frame, which is never less than any frame's own need
/// (each window maximum averaged saw it) and changes evenly. Raised in one frame alone, the
/// body would pop up by the need and back (a strong run whose amplified leg cannot reach the
/// ground where the run lands it moved its root at 4.4 m/s). A foot that stood on the ground
/// before its frame was raised is set back down by two-bone IK as far as its leg reaches, in
/// the frames around whose legs had slack (they keep their feet on the floor; the frames in
/// need have theirs raised onto it).
pub fn raise_evenly(clip: &mut Clip, legs: &[Leg], need: &[f32]) {
    let n = clip.len().min(need.len());
    let window =
        |f: usize| f.saturating_sub(RAISE_EASE_FRAMES)..=(f + RAISE_EASE_FRAMES).min(n - 1);
    let most: Vec<f32> = (0..n)
        .map(|f| need[window(f)].iter().copied().fold(0.0f32, f32::max))
        .collect();
    let sk = clip.skeleton.clone();
    for f in 0..n {
        let raise = most[window(f)].iter().sum::<f32>() / window(f).count() as f32;
        if !(raise > 0.0 && raise.is_finite()) {
            continue;
        }
        let pose = &mut clip.frames[f];
        let before = sk.positions(pose);
        if let Some(t) = pose.translations.first_mut() {
            t.y += raise;
        }
        for leg in legs {
            let low = leg.lowest_y(&before);
            // Only feet on the ground come back down, in frames whose legs had the slack (a
            // frame in need keeps its feet where the raise put them: on the ground).
            if low.is_nan() || low >= GROUND_Y + CONTACT_HEIGHT || need[f] > 0.0 {
                continue;
            }
            // IK on a leg near straight first bends its knee forward, which tips the foot: a
            // foot that would end below the ground stays where the raise put it instead.
            let kept = pose.rotations.clone();
            set_foot_height(&sk, pose, leg, low.max(GROUND_Y));
            if leg.lowest_y(&sk.positions(pose)) < GROUND_Y - SINK_TOLERANCE_M {
                pose.rotations = kept;
            }
        }
    }
}

/// How far below the ground (m) [`raise_evenly`] lets a foot it sets back down end (IK lands a
/// foot within a fraction of a millimetre of its target when the leg has slack).
const SINK_TOLERANCE_M: f32 = 1e-3;

/// Moves the ankle of `leg` up or down by two-bone IK so that the foot's lowest point comes to
/// height `y` (m), as near as the leg reaches (IK keeps the foot's orientation, so the ankle
/// moves by what the lowest point must).
fn set_foot_height(
    sk: &crate::motion::Skeleton,
    pose: &mut crate::motion::Pose,
    leg: &Leg,
    y: f32,
) {
    let world = sk.positions(pose);
    let low = leg.lowest_y(&world);
    let off = low - y;
    let Some(&ankle) = world.get(leg.ankle) else {
        return;
    };
    if off.is_finite() && off.abs() > 1e-5 {
        two_bone_ik(sk, pose, leg, ankle - Vec3::Y * off);
    }
}

/// What the ground pass changed.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GroundFix {
    /// Frames where IK bent a leg.
    pub ik_frames: usize,
    /// Frames where the root had to be raised.
    pub raised_frames: usize,
    /// Deepest penetration found before the fix, metres.
    pub max_depth: f32,
}

/// Removes every foot's penetration below the ground: two-bone IK lifts the ankle; if the leg
/// cannot reach, the root is raised by what remains — evenly over the frames around
/// ([`raise_evenly`]), so the body rises and settles as a person's would
/// rather than popping up for a frame.
pub fn fix_ground(clip: &mut Clip, legs: &[Leg]) -> GroundFix {
    let mut fix = GroundFix::default();
    let sk = clip.skeleton.clone();
    let mut need = vec![0.0f32; clip.len()];
    for (pose, need) in clip.frames.iter_mut().zip(&mut need) {
        let mut bent = false;
        for leg in legs {
            let world = sk.forward(pose);
            let low = leg
                .foot
                .iter()
                .map(|&j| world[j].position.y)
                .fold(f32::INFINITY, f32::min);
            let depth = GROUND_Y - low;
            if depth <= 0.0 || !depth.is_finite() {
                continue;
            }
            fix.max_depth = fix.max_depth.max(depth);
            let target = world[leg.ankle].position + Vec3::Y * (depth + 1e-4);
            two_bone_ik(&sk, pose, leg, target);
            bent = true;
        }
        // Whatever IK could not reach: raise the whole body.
        let world = sk.positions(pose);
        let low = legs
            .iter()
            .flat_map(|l| l.foot.iter())
            .map(|&j| world[j].y)
            .fold(f32::INFINITY, f32::min);
        if low < GROUND_Y && low.is_finite() {
            *need = GROUND_Y - low + 1e-4;
            fix.raised_frames += 1;
        }
        if bent {
            fix.ik_frames += 1;
        }
    }
    if fix.raised_frames > 0 {
        raise_evenly(clip, legs, &need);
    }
    fix
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::anim::contact::find_legs;
    use crate::motion::Pose;
    use glam::Quat;

    /// One leg standing with its toe on the ground, the knee bent `knee` rad; `frames` frames
    /// at 30 fps, the foot swept along +Z at `speed` m/s (the hip carried with it).
    fn sweeping_leg(frames: usize, speed: f32, knee: f32) -> Clip {
        let sk = crate::anim::contact::leg_skeleton();
        let mut rest = Pose::rest(&sk);
        rest.rotations[2] = Quat::from_rotation_x(knee);
        let toe = sk.positions(&rest)[4].y;
        let poses = (0..frames)
            .map(|f| {
                let mut p = rest.clone();
                p.translations[0] = Vec3::new(0.0, -toe, speed * f as f32 / 30.0);
                p
            })
            .collect();
        Clip {
            name: "sweep".into(),
            skeleton: sk,
            frame_time: 1.0 / 30.0,
            frames: poses,
        }
    }

    fn toe_height(c: &Clip, f: usize) -> f32 {
        let p = c.joint_positions(f);
        p[3].y.min(p[4].y)
    }

    #[test]
    fn a_foot_standing_still_is_planted_even_where_its_source_was_not() {
        let c = sweeping_leg(10, 0.0, 0.2);
        let legs = find_legs(&c);
        let flags = planted(&c, &legs, &[vec![false; 10]]);
        assert_eq!(flags, vec![vec![true; 10]]);
        // A foot sweeping at 2 m/s is no contact, but the source's contacts are kept.
        let c = sweeping_leg(10, 2.0, 0.2);
        let mut source = vec![false; 10];
        source[4] = true;
        let flags = planted(&c, &legs, &[source.clone()]);
        assert_eq!(flags, vec![source]);
    }

    #[test]
    fn a_foot_sweeping_along_the_floor_is_lifted_clear_of_it_and_a_planted_one_is_not() {
        let mut c = sweeping_leg(12, 2.0, 0.2);
        let legs = find_legs(&c);
        let hip_before: Vec<Vec3> = (0..12).map(|f| c.joint_positions(f)[1]).collect();
        // Planted in frames 0–1, swinging after.
        let mut flags = vec![false; 12];
        flags[0] = true;
        flags[1] = true;
        let lifted = clear_swing_feet(&mut c, &legs, &[flags]);
        assert_eq!(lifted, 10);
        assert!(toe_height(&c, 0).abs() < 1e-5 && toe_height(&c, 1).abs() < 1e-5);
        // It rises over CLEARANCE_EASE_FRAMES, then keeps the full clearance.
        for (f, hip) in hip_before.iter().enumerate().skip(2) {
            let share = ((f - 1) as f32 / CLEARANCE_EASE_FRAMES as f32).min(1.0);
            let want = SWING_CLEARANCE_M * share;
            assert!(
                (toe_height(&c, f) - want).abs() < 2e-3,
                "frame {f}: {} want {want}",
                toe_height(&c, f)
            );
            // The hip did not move: the knee bent.
            assert!((c.joint_positions(f)[1] - *hip).length() < 1e-5);
        }
    }

    #[test]
    fn a_raise_is_spread_over_the_frames_around_and_their_feet_stay_down() {
        // A knee bent 0.6 rad: 4 cm of slack before the leg is straight.
        let mut c = sweeping_leg(21, 0.0, 0.6);
        let legs = find_legs(&c);
        // Frame 10's foot is 4 cm into the ground where its leg could not reach.
        c.frames[10].translations[0].y -= 0.04;
        let mut need = vec![0.0; 21];
        need[10] = 0.04;
        let root_before: Vec<f32> = (0..21).map(|f| c.frames[f].translations[0].y).collect();
        raise_evenly(&mut c, &legs, &need);
        let raise: Vec<f32> = (0..21)
            .map(|f| c.frames[f].translations[0].y - root_before[f])
            .collect();
        // Never less than a frame's own need, and no step between frames larger than an even
        // share of it.
        assert!(raise[10] >= 0.04 - 1e-6, "{raise:?}");
        let share = 0.04 / (RAISE_EASE_FRAMES + 1) as f32;
        for w in raise.windows(2) {
            assert!((w[1] - w[0]).abs() <= share + 1e-5, "{raise:?}");
        }
        assert_eq!(raise[0], 0.0);
        assert_eq!(raise[20], 0.0);
        // The frame in need stands on the ground, and the bent knee has the slack to keep the
        // foot of the frames around on it (IK lands it within millimetres).
        for f in 0..21 {
            assert!(
                toe_height(&c, f).abs() < 3e-3,
                "frame {f}: {}",
                toe_height(&c, f)
            );
        }
    }

    #[test]
    fn clearance_rises_from_the_nearest_planted_frame() {
        let flags = [true, false, false, false, false, false, false, true];
        let c = clearance(&flags);
        let step = SWING_CLEARANCE_M / CLEARANCE_EASE_FRAMES as f32;
        let want = [
            0.0,
            step,
            2.0 * step,
            3.0 * step,
            3.0 * step,
            2.0 * step,
            step,
            0.0,
        ];
        for (a, b) in c.iter().zip(want) {
            assert!((a - b).abs() < 1e-6, "{c:?}");
        }
        assert_eq!(clearance(&[false; 2]), vec![SWING_CLEARANCE_M; 2]);
    }

    #[test]
    fn finds_the_leg_and_lifts_the_foot_with_ik() {
        let mut c = crate::anim::contact::tests::leg_clip();
        let legs = find_legs(&c);
        assert_eq!(legs.len(), 1, "{legs:?}");
        assert_eq!((legs[0].hip, legs[0].knee, legs[0].ankle), (1, 2, 3));
        let before = c.joint_positions(0);
        let fix = fix_ground(&mut c, &legs);
        let after = c.joint_positions(0);
        assert!(fix.max_depth > 0.0 && fix.ik_frames == 2, "{fix:?}");
        assert!(after[4].y >= -1e-5 && after[3].y >= -1e-5, "{after:?}");
        // The pelvis did not move: IK alone did it (the bent knee has slack).
        assert!((after[0] - before[0]).length() < 1e-6);
        assert_eq!(fix.raised_frames, 0);
    }

    #[test]
    fn unreachable_targets_raise_the_root() {
        let mut c = crate::anim::contact::tests::leg_clip();
        for p in &mut c.frames {
            p.translations[0].y = -1.5; // hip 1.5 m under ground: the leg cannot reach
        }
        let legs = find_legs(&c);
        let fix = fix_ground(&mut c, &legs);
        assert_eq!(fix.raised_frames, 2);
        let p = c.joint_positions(1);
        assert!(p[3].y >= -1e-4 && p[4].y >= -1e-4, "{p:?}");
    }
}
