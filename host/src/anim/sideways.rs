//! Finding sideways stepping in a motion-capture take (`figurine clip sideways TAKE.bvh`):
//! stretches where the root moves mostly along the body's left/right axis while the feet step
//! in turn, and within each the step cycle whose first and last poses agree best, to cut a
//! loopable sidestep clip from.
//!
//! Per frame, from the joints' world positions (any rig whose landmarks
//! [`crate::graph::roles`] finds):
//! - the body's **right** axis is the ground projection of left hip → right hip, its
//!   **facing** that axis turned a quarter left about +Y;
//! - the root's velocity (central difference over ±[`VELOCITY_HALF_S`]) splits into a
//!   **lateral** part (m/s, > 0 to the right) and a part **along** the facing;
//! - a foot is **planted** while its lowest point is within [`PLANTED_M`] of the ground (a low
//!   percentile of the feet's height over the take) and moves slower than
//!   [`PLANTED_SPEED_M_S`].
//!
//! A frame is sideways when its lateral speed exceeds [`MIN_LATERAL_M_S`] and
//! [`LATERAL_RATIO`] times the speed along the facing. Runs of sideways frames of one sign
//! (gaps up to [`GAP_S`] bridged) lasting at least [`MIN_STRETCH_S`] are reported with their
//! mean lateral speed, the share of their travel that is sideways, the turn of the facing over
//! them, and their steps (a foot's plant onsets) and whether the steps alternate feet.

use anyhow::{Context, Result};
use glam::{Quat, Vec3};
use serde::Serialize;

use crate::graph::roles::{Role, RoleMap, RoleOverrides};
use crate::motion::{Clip, CENTIMETRE_HEIGHT};

/// Half width of the central difference giving the root's velocity, s.
pub const VELOCITY_HALF_S: f32 = 0.1;
/// Height above the ground under which a foot's lowest point may be planted, m.
pub const PLANTED_M: f32 = 0.04;
/// Horizontal speed of a foot under which a low foot is planted, m/s.
pub const PLANTED_SPEED_M_S: f32 = 0.3;
/// Lateral root speed above which a frame may be sideways, m/s.
pub const MIN_LATERAL_M_S: f32 = 0.2;
/// How many times faster than along the facing the root must move sideways.
pub const LATERAL_RATIO: f32 = 2.0;
/// Longest gap of non-sideways frames bridged inside a stretch, s.
pub const GAP_S: f32 = 0.25;
/// Shortest stretch reported, s.
pub const MIN_STRETCH_S: f32 = 0.8;
/// Step cycles searched for a loop last between these, s.
pub const CYCLE_S: (f32, f32) = (0.6, 2.0);

/// What the search sees of a take, per frame.
#[derive(Debug, Clone)]
pub struct BodyTrack {
    /// Seconds between frames.
    pub dt: f32,
    /// Root (hips) velocity across the body, m/s (> 0 to the right).
    pub lateral: Vec<f32>,
    /// Root velocity along the facing, m/s.
    pub along: Vec<f32>,
    /// The facing's yaw about +Y, radians.
    pub yaw: Vec<f32>,
    /// Per foot (left, right): planted.
    pub planted: [Vec<bool>; 2],
}

/// One stretch of sideways stepping.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SideStretch {
    /// First frame.
    pub first: usize,
    /// Last frame (inclusive).
    pub last: usize,
    /// Its start, s into the take.
    pub start_s: f32,
    /// Its length, s.
    pub seconds: f32,
    /// Mean lateral root speed, m/s (> 0: to the right).
    pub lateral_m_s: f32,
    /// Sideways travel over all travel: |Σ lateral| / Σ |velocity|.
    pub sideways_share: f32,
    /// Turn of the facing from first to last frame, ° (absolute).
    pub turn_deg: f32,
    /// Plant onsets of either foot inside the stretch.
    pub steps: usize,
    /// Whether consecutive onsets alternate feet (left, right, left …).
    pub alternating: bool,
    /// The best loop inside the stretch, if a cycle fits.
    pub cycle: Option<StepCycle>,
}

/// A cycle of sideways stepping whose first and last poses nearly agree.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct StepCycle {
    /// First frame.
    pub first: usize,
    /// Last frame (inclusive).
    pub last: usize,
    /// Largest angle between a joint's local rotation at the first and last frame, ° (the
    /// root's only by its tilt: its heading may differ).
    pub mismatch_deg: f32,
    /// Lateral root travel over the cycle, m (> 0: to the right).
    pub lateral_m: f32,
    /// Plant onsets of the left and of the right foot inside the cycle.
    pub onsets: [usize; 2],
}

/// A take read in metres (centimetre rigs are scaled, see [`CENTIMETRE_HEIGHT`]).
pub fn in_metres(mut clip: Clip) -> Clip {
    if clip.is_empty() {
        return clip;
    }
    let p = clip.joint_positions(0);
    let (lo, hi) = p
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), v| {
            (a.min(v.y), b.max(v.y))
        });
    if hi - lo > CENTIMETRE_HEIGHT {
        clip.scale_lengths(0.01);
    }
    clip
}

/// The joints of each foot (left, right): the ankle and every joint below it.
pub fn foot_joints(clip: &Clip, roles: &RoleMap) -> [Vec<usize>; 2] {
    [Role::LeftFoot, Role::RightFoot].map(|r| {
        let mut out = vec![roles.joint(r)];
        let mut i = 0;
        while i < out.len() {
            out.extend(clip.skeleton.children(out[i]));
            i += 1;
        }
        out
    })
}

/// Measures a take (metres) frame by frame.
pub fn track(clip: &Clip) -> Result<BodyTrack> {
    let roles = RoleMap::detect(&clip.skeleton, &RoleOverrides::new(), &clip.name)?;
    let pos = clip.all_positions();
    let n = pos.len();
    let dt = clip.frame_time.max(1e-6);
    let feet = foot_joints(clip, &roles);
    let low = |f: usize, k: usize| {
        feet[k]
            .iter()
            .map(|&j| pos[f][j].y)
            .fold(f32::INFINITY, f32::min)
    };
    let mut lows: Vec<f32> = (0..n).map(|f| low(f, 0).min(low(f, 1))).collect();
    lows.sort_by(f32::total_cmp);
    let ground = lows.get(n / 20).copied().unwrap_or(0.0);
    let hips = roles.joint(Role::Hips);
    let (lh, rh) = (roles.joint(Role::LeftHip), roles.joint(Role::RightHip));
    let right: Vec<Vec3> = (0..n)
        .map(|f| {
            let d = pos[f][rh] - pos[f][lh];
            Vec3::new(d.x, 0.0, d.z).normalize_or(Vec3::Z)
        })
        .collect();
    let h = ((VELOCITY_HALF_S / dt).round() as usize).max(1);
    let (mut lateral, mut along, mut yaw) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for f in 0..n {
        let (a, b) = (f.saturating_sub(h), (f + h).min(n - 1));
        let v = (pos[b][hips] - pos[a][hips]) / ((b - a).max(1) as f32 * dt);
        let facing = Vec3::Y.cross(right[f]);
        lateral[f] = v.x * right[f].x + v.z * right[f].z;
        along[f] = v.x * facing.x + v.z * facing.z;
        yaw[f] = (-facing.z).atan2(facing.x);
    }
    let planted = [0, 1].map(|k| {
        let ankle = feet[k][0];
        (0..n)
            .map(|f| {
                let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
                let d = pos[b][ankle] - pos[a][ankle];
                let v = Vec3::new(d.x, 0.0, d.z).length() / ((b - a).max(1) as f32 * dt);
                low(f, k) < ground + PLANTED_M && v < PLANTED_SPEED_M_S
            })
            .collect()
    });
    Ok(BodyTrack {
        dt,
        lateral,
        along,
        yaw,
        planted,
    })
}

/// Plant onsets (frame, foot 0 = left / 1 = right) in `first..=last`, in frame order.
pub fn onsets(track: &BodyTrack, first: usize, last: usize) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for f in first.max(1)..=last.min(track.lateral.len().saturating_sub(1)) {
        for k in 0..2 {
            if track.planted[k][f] && !track.planted[k][f - 1] {
                out.push((f, k));
            }
        }
    }
    out
}

/// The sideways stretches of a take (metres), longest first.
pub fn find_sideways(clip: &Clip) -> Result<Vec<SideStretch>> {
    let tr = track(clip)?;
    let n = tr.lateral.len();
    let side = |f: usize| {
        let l = tr.lateral[f];
        if l.abs() > MIN_LATERAL_M_S && l.abs() > LATERAL_RATIO * tr.along[f].abs() {
            l.signum() as i8
        } else {
            0
        }
    };
    let gap = (GAP_S / tr.dt).round() as usize;
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut f = 0;
    while f < n {
        let s = side(f);
        if s == 0 {
            f += 1;
            continue;
        }
        let (first, mut last) = (f, f);
        let mut g = f + 1;
        while g < n && g <= last + gap + 1 {
            match side(g) {
                x if x == s => last = g,
                x if x == -s => break,
                _ => {}
            }
            g += 1;
        }
        runs.push((first, last));
        f = last + 1;
    }
    let mut out: Vec<SideStretch> = runs
        .into_iter()
        .filter(|(a, b)| (b - a) as f32 * tr.dt >= MIN_STRETCH_S)
        .map(|(a, b)| stretch(clip, &tr, a, b))
        .collect();
    out.sort_by(|x, y| y.seconds.total_cmp(&x.seconds));
    Ok(out)
}

fn stretch(clip: &Clip, tr: &BodyTrack, a: usize, b: usize) -> SideStretch {
    let lat: f32 = tr.lateral[a..=b].iter().sum::<f32>() * tr.dt;
    let all: f32 = (a..=b)
        .map(|f| tr.lateral[f].hypot(tr.along[f]))
        .sum::<f32>()
        * tr.dt;
    let steps = onsets(tr, a, b);
    let alternating = steps.len() >= 2 && steps.windows(2).all(|w| w[0].1 != w[1].1);
    let mut turn = (tr.yaw[b] - tr.yaw[a]).to_degrees().abs() % 360.0;
    if turn > 180.0 {
        turn = 360.0 - turn;
    }
    SideStretch {
        first: a,
        last: b,
        start_s: a as f32 * tr.dt,
        seconds: (b - a) as f32 * tr.dt,
        lateral_m_s: lat / ((b - a + 1) as f32 * tr.dt),
        sideways_share: if all > 0.0 { lat.abs() / all } else { 0.0 },
        turn_deg: turn,
        steps: steps.len(),
        alternating,
        cycle: best_cycle(clip, tr, a, b),
    }
}

/// Largest angle between two poses' local joint rotations, ° (the root by its tilt only).
pub fn pose_mismatch_deg(clip: &Clip, f: usize, g: usize) -> f32 {
    let (p, q) = (&clip.frames[f], &clip.frames[g]);
    let angle = |a: Quat, b: Quat| a.angle_between(b).to_degrees();
    let tilt = {
        let up = |r: Quat| r * Vec3::Y;
        let (u, v) = (up(p.rotations[0]), up(q.rotations[0]));
        let (u, v) = (
            Vec3::new(0.0, u.y, u.x.hypot(u.z)),
            Vec3::new(0.0, v.y, v.x.hypot(v.z)),
        );
        u.angle_between(v).to_degrees()
    };
    (1..clip.skeleton.len())
        .filter(|&j| !clip.skeleton.joints[j].end_site)
        .map(|j| angle(p.rotations[j], q.rotations[j]))
        .fold(tilt, f32::max)
}

/// The cycle inside `a..=b` whose first and last poses agree best, among those lasting
/// [`CYCLE_S`] in which each foot plants once or more and the root keeps stepping sideways.
fn best_cycle(clip: &Clip, tr: &BodyTrack, a: usize, b: usize) -> Option<StepCycle> {
    let (lo, hi) = (
        (CYCLE_S.0 / tr.dt).round() as usize,
        (CYCLE_S.1 / tr.dt).round() as usize,
    );
    let mut best: Option<StepCycle> = None;
    for f in a..=b {
        for g in (f + lo)..=(f + hi).min(b) {
            let steps = onsets(tr, f + 1, g);
            let count = [0, 1].map(|k| steps.iter().filter(|s| s.1 == k).count());
            if count.contains(&0) {
                continue;
            }
            let m = pose_mismatch_deg(clip, f, g);
            if best.as_ref().is_some_and(|c| c.mismatch_deg <= m) {
                continue;
            }
            best = Some(StepCycle {
                first: f,
                last: g,
                mismatch_deg: m,
                lateral_m: tr.lateral[f..=g].iter().sum::<f32>() * tr.dt,
                onsets: count,
            });
        }
    }
    best
}

/// Runs `figurine clip sideways`: prints each take's sideways stretches.
pub fn run_sideways(takes: &[std::path::PathBuf], urdf: Option<&std::path::Path>) -> Result<()> {
    for path in takes {
        let clip = in_metres(crate::motion::read_take(path, urdf)?);
        let found = find_sideways(&clip).with_context(|| path.display().to_string())?;
        println!(
            "{}: {} frames at {:.0} fps, {} sideways stretch(es) ≥ {MIN_STRETCH_S} s",
            path.display(),
            clip.len(),
            clip.fps(),
            found.len()
        );
        println!("  frames        start s  len s  lateral m/s  sideways  turn°  steps  alternate  best loop (mismatch°, lateral m, onsets L/R)");
        for s in &found {
            let cycle = s.cycle.as_ref().map_or("-".to_string(), |c| {
                format!(
                    "{}-{} ({:.1}°, {:+.2} m, {}/{})",
                    c.first, c.last, c.mismatch_deg, c.lateral_m, c.onsets[0], c.onsets[1]
                )
            });
            println!(
                "  {:>5}-{:<6} {:>7.1}  {:>5.2}  {:>+11.2}  {:>7.0}%  {:>5.0}  {:>5}  {:>9}  {cycle}",
                s.first,
                s.last,
                s.start_s,
                s.seconds,
                s.lateral_m_s,
                s.sideways_share * 100.0,
                s.turn_deg,
                s.steps,
                if s.alternating { "yes" } else { "no" },
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::Pose;

    /// A stick figure (facing +X, its right towards +Z) gliding at `v` m/s for 2 s.
    fn gliding(v: Vec3) -> Clip {
        let skeleton = crate::anim::mirror::tests::stick_figure("hips");
        let dt = 1.0 / 30.0;
        let frames = (0..60)
            .map(|f| {
                let mut p = Pose::rest(&skeleton);
                p.translations[0] = Vec3::new(0.0, 0.9, 0.0) + v * (f as f32 * dt);
                p
            })
            .collect();
        Clip {
            name: "glide".into(),
            skeleton,
            frame_time: dt,
            frames,
        }
    }

    #[test]
    fn motion_across_the_body_is_sideways_and_along_it_is_not() {
        let right = find_sideways(&gliding(Vec3::new(0.0, 0.0, 0.6))).unwrap();
        assert_eq!(right.len(), 1, "{right:?}");
        let s = &right[0];
        assert!((s.lateral_m_s - 0.6).abs() < 0.01, "{s:?}");
        assert!(s.sideways_share > 0.99 && s.turn_deg < 0.1, "{s:?}");
        // Gliding is not stepping: no foot lifts, so nothing plants anew and no cycle fits.
        assert_eq!(
            (s.steps, s.alternating, s.cycle.is_none()),
            (0, false, true)
        );
        let left = find_sideways(&gliding(Vec3::new(0.0, 0.0, -0.6))).unwrap();
        assert!(left[0].lateral_m_s < -0.59, "{left:?}");
        let ahead = find_sideways(&gliding(Vec3::new(0.6, 0.0, 0.1))).unwrap();
        assert!(ahead.is_empty(), "{ahead:?}");
    }

    #[test]
    fn lafan_test_take_steps_sideways_upright_at_162_s() {
        let Some(path) = crate::data::data_file("bvh", "lafan_test.bvh") else {
            eprintln!("skipping: LAFAN data missing — run `cargo xtask setup`");
            return;
        };
        let clip = in_metres(crate::motion::read_take(&path, None).unwrap());
        let found = find_sideways(&clip).unwrap();
        // The default library's sidestep (host/assets/default_clips.json) is cut from here.
        let s = found
            .iter()
            .find(|s| s.first <= 4873 && s.last >= 4914)
            .unwrap_or_else(|| panic!("no stretch around frame 4873: {found:?}"));
        assert!(s.lateral_m_s < -0.5 && s.sideways_share > 0.9, "{s:?}");
        assert!(s.alternating && s.steps >= 3, "{s:?}");
        let c = s.cycle.as_ref().unwrap();
        assert_eq!((c.first, c.last), (4873, 4914), "{c:?}");
        assert!(c.mismatch_deg < 10.0 && c.onsets == [1, 1], "{c:?}");
    }
}
