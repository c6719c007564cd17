//! Pacing: an animation moves no faster than a person does.
//!
//! Effort transfer and the doodle both ask for speed: a sudden retime compresses a lunge, a
//! short event squeezes a long clip, a toy swept across a table at 0.7 m/s becomes a 7 m/s
//! path at the default world scale. A person's speed has limits, and this module holds an
//! animation within them:
//! - **gaits** (`pace`): whole cycles at a cadence within [`MAX_CADENCE`] of the clip's,
//!   their stride the clip's (rescaled) travel, the path shrunk about its start where the
//!   doodle asks more than that cadence, or [`HUMAN_ROOT_SPEED_M_S`] on average, covers
//!   (and the assembler shrinks it further where the cycle's bob and surge on top of that
//!   pace would outrun [`HUMAN_ROOT_SPEED_M_S`]);
//! - **any clip** ([`EffortClip::paced`]): no stretch of its time map moves the root faster
//!   than a person ([`HUMAN_ROOT_SPEED_M_S`]), nor squeezes it, beyond the effort's own
//!   timing, into accelerating harder than a person ([`HUMAN_ROOT_ACCEL_M_S2`]); such
//!   stretches borrow time from the slow ones.

use glam::Vec3;

use super::effort::EffortClip;
use super::library::ActionClip;
use super::trajectory::{ground, Polyline};
use crate::motion::{Clip, Pose};

/// How many times more (or fewer) steps a gait may take per second than its clip does. People
/// walk at about 70–140 steps a minute and run at 150–230 (a sprint), about 1.5× either side
/// of an everyday pace; beyond it a walk would turn into a run, a run into a shuffle.
pub const MAX_CADENCE: f32 = 1.5;

/// The fastest a character's root may move, m/s: the fastest real take the project fetches
/// (DeepMimic's run, 4.2 m/s), the same limit `figurine check` judges against
/// ([`super::envelope::ROOT_SPEED_M_S`]). No person's hips outrun it; an action that
/// would is given more time.
pub const HUMAN_ROOT_SPEED_M_S: f32 = super::envelope::ROOT_SPEED_M_S;

/// The hardest a character's root may be made to accelerate by squeezing a clip into a short
/// event, m/s²: the largest root acceleration among the real takes within the rest of the
/// envelope (DeepMimic's spinning kick, 48 m/s²; its kick 40, its jump 35; people walking
/// 6–13). Acceleration goes as the square of the squeeze: the sudden, strong jump's backflip
/// squeezed 2.6× into a 0.7 s event took off at 181 m/s². Effort's own retiming (a sudden
/// execution, eq. 6) is the performer's and is left as it is; only what the event's length
/// adds is held here.
pub const HUMAN_ROOT_ACCEL_M_S2: f32 = 48.0;

/// The limits [`EffortClip::paced`] holds a clip's root within.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaceLimits {
    /// Fastest root speed, m/s.
    pub speed_m_s: f32,
    /// Hardest root acceleration a squeeze beyond the effort's own timing may bring, m/s².
    pub accel_m_s2: f32,
    /// Output frame time, s: the step at which the root's acceleration is judged (as
    /// `figurine check` judges it, frame to frame).
    pub frame_s: f32,
}

/// Share of [`HUMAN_ROOT_SPEED_M_S`] an action is paced to: the passes after placement (the
/// ground pass raising a root whose leg cannot reach, blends between actions) move the root
/// by a few millimetres more per frame, so pacing to the limit itself would end just over it.
pub const PACE_HEADROOM: f32 = 0.97;

/// Ground distance (m) a clip's root travels from its first frame to its last: a cycle's travel
/// for a gait, a jump's reach.
pub(super) fn ground_travel(clip: &Clip) -> f32 {
    let root = clip.root_path();
    match (root.first(), root.last()) {
        (Some(&r0), Some(&rl)) => ground(rl - r0).length(),
        _ => 0.0,
    }
}

/// The path a moving action covers in `duration` seconds and the cycles it plays on it, at a
/// pace a person keeps.
///
/// - **Cyclic** (walk, run): a stride stays tied to the distance it covers, and steps come
///   no more than [`MAX_CADENCE`] times as often as in the clip, nor less than 1/[`MAX_CADENCE`]
///   as often. Whole cycles of the (effort-rescaled) clip's travel are fitted to the path
///   within that range of cadence; a path too short for it gets more, shorter steps (a slow
///   run steps short, the stretched-down root and the foot pinning keep the feet planted); a
///   path too long for it — the doodle's pace times the world scale beyond what the action's
///   stride at its quickest cadence covers, or beyond [`HUMAN_ROOT_SPEED_M_S`] on average —
///   is shrunk, about its start, to what that pace covers in the time (its shape kept). The doodle's world scale thus says how big the
///   path is wherever a person can cover it, and the animation keeps the doodle's timing; a
///   character does not sprint 7 m/s because a toy was swept fast across a table.
/// - **Not cyclic** (jump): the path is shrunk to at most the (effort-rescaled) clip's own
///   travel: a jump lands where its take-off carries it.
/// - **In place**: a looping clip repeats as many whole times as fill the duration at its
///   own speed (so does a cyclic clip without a path); else 1.
pub(super) fn pace(
    ac: &ActionClip,
    ec: &EffortClip,
    chunk: &Polyline,
    duration: f32,
) -> (Polyline, usize) {
    let travel = ground_travel(&ec.clip);
    let cycle_s = ec.clip.duration().max(1e-3);
    let len = chunk.length();
    if ac.moving && ac.cyclic && len > 0.05 && travel > 0.05 && duration.is_finite() {
        // Cycles at the quickest and slowest cadence that fill the duration.
        let most = ((duration * MAX_CADENCE / cycle_s).floor() as usize).max(1);
        let least = ((duration / (MAX_CADENCE * cycle_s)).ceil() as usize).clamp(1, most);
        // Nor faster on average than the fastest person (HUMAN_ROOT_SPEED_M_S).
        let reach = (most as f32 * travel).min(HUMAN_ROOT_SPEED_M_S * duration);
        let chunk = shrink(chunk, reach);
        let cycles = ((chunk.length() / travel).round() as usize).clamp(least, most);
        (chunk, cycles)
    } else if ac.moving && !ac.cyclic && len > 0.05 {
        (shrink(chunk, travel.max(0.05)), 1)
    } else if ac.looping && (!ac.moving || ac.cyclic) && duration.is_finite() {
        let cycles = (duration / ac.clip.duration().max(1e-3)).round().max(1.0) as usize;
        (chunk.clone(), cycles)
    } else {
        (chunk.clone(), 1)
    }
}

/// `chunk` (starting at the origin) scaled about its start to at most `most` metres long.
pub(super) fn shrink(chunk: &Polyline, most: f32) -> Polyline {
    let len = chunk.length();
    if len <= most || len <= 0.0 {
        return chunk.clone();
    }
    let f = most / len;
    Polyline::new(chunk.pts.iter().map(|p| *p * f).collect())
}

/// The fastest the root of `poses` moves from one frame to the next, m/s.
pub(super) fn root_speed_max(poses: &[Pose], dt: f32) -> f32 {
    poses
        .windows(2)
        .map(|w| (w[1].translations[0] - w[0].translations[0]).length() / dt)
        .filter(|v| v.is_finite())
        .fold(0.0, f32::max)
}

impl EffortClip {
    /// This clip played over `seconds` with its root never faster than `limits.speed_m_s`:
    /// where the time map would move the root faster (a sudden retime compressing a lunge or a
    /// take-off, a long clip squeezed into a short event), that stretch is given the time the
    /// speed needs and the rest of the clip gives it back, its own timing scaled evenly; only
    /// when even that cannot make room does the clip take longer. Likewise no stretch is
    /// squeezed beyond the effort's own timing (`natural_s`) so far that its
    /// root accelerates harder than `limits.accel_m_s2` (acceleration grows with the square
    /// of the squeeze): a backflip squeezed into a short event takes the time its take-off
    /// needs. Returns the clip and the seconds it now lasts (≥ `seconds`). The effort's
    /// shape stays: slow parts stay slow, fast parts as fast as a person moves.
    pub fn paced(&self, seconds: f32, limits: &PaceLimits) -> (EffortClip, f32) {
        let n = self.table.len();
        let PaceLimits {
            speed_m_s,
            accel_m_s2,
            frame_s,
        } = *limits;
        if n < 2 || !(seconds > 0.0 && speed_m_s > 0.0 && accel_m_s2 > 0.0 && frame_s > 0.0) {
            return (self.clone(), seconds.max(0.0));
        }
        let root = |s: f32| self.clip.sample(s).translations[0];
        let positions: Vec<Vec3> = self.table.iter().map(|e| root(e.1)).collect();
        let end_s = self.clip.duration();
        // The root's acceleration on the clip's own clock at source second `s`, judged one
        // output frame either side (finer steps would read the take's jitter as acceleration
        // a squeezed playback never shows).
        let accel_at = |s: f32| {
            let (a, b) = ((s - frame_s).max(0.0), (s + frame_s).min(end_s));
            let (da, db) = ((s - a).max(1e-6), (b - s).max(1e-6));
            let (x0, x1, x2) = (root(a), root(s), root(b));
            ((x2 - x1) / db - (x1 - x0) / da).length() / (0.5 * (da + db))
        };
        let need: Vec<f32> = positions
            .windows(2)
            .zip(self.table.windows(2))
            .map(|(p, e)| {
                let span = (e[1].1 - e[0].1).max(0.0);
                let natural = (e[1].0 - e[0].0) * self.natural_s;
                // Played `r` times as fast, a stretch accelerates r² times as hard.
                let squeezed = span * (accel_at(0.5 * (e[0].1 + e[1].1)) / accel_m_s2).sqrt();
                ((p[1] - p[0]).length() / speed_m_s).max(squeezed.min(natural))
            })
            .collect();
        let have: Vec<f32> = self
            .table
            .windows(2)
            .map(|w| (w[1].0 - w[0].0) * seconds)
            .collect();
        if need.iter().zip(&have).all(|(n, h)| n <= h) {
            return (self.clone(), seconds);
        }
        let total =
            |alpha: f32| -> f32 { need.iter().zip(&have).map(|(n, h)| n.max(alpha * h)).sum() };
        // The largest α ≤ 1 whose stretched timing fits in `seconds` (bisection; total(α) is
        // increasing), else the clip's timing at α = 0: every stretch as fast as allowed.
        let (mut lo, mut hi) = (0.0f32, 1.0f32);
        for _ in 0..PACE_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if total(mid) <= seconds {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let out_seconds = total(lo).max(seconds);
        let mut table = Vec::with_capacity(n);
        let mut t = 0.0;
        table.push((0.0, self.table[0].1));
        for (k, (nk, hk)) in need.iter().zip(&have).enumerate() {
            t += nk.max(lo * hk);
            table.push(((t / out_seconds).min(1.0), self.table[k + 1].1));
        }
        if let Some(last) = table.last_mut() {
            last.0 = 1.0;
        }
        (
            EffortClip {
                clip: self.clip.clone(),
                phrasing: self.phrasing.clone(),
                table,
                natural_s: out_seconds,
            },
            out_seconds,
        )
    }
}

/// Bisection steps of [`EffortClip::paced`].
const PACE_BISECTIONS: usize = 24;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::anim::effort::{apply_effort, Effort};
    use crate::anim::phrasing::Phrasing;
    use crate::motion::{Clip, Joint, Skeleton};
    use glam::Vec2;

    /// A one-joint clip whose root stands still for 1 s, lunges 0.6 m in 0.1 s, and stands
    /// still for 1 s (30 fps).
    fn lunge() -> Clip {
        let skeleton = Skeleton {
            joints: vec![Joint::bare("root", None, Vec3::ZERO)],
        };
        let frames = (0..=63)
            .map(|f| {
                let mut p = Pose::rest(&skeleton);
                let x = 0.6 * ((f as f32 - 30.0) / 3.0).clamp(0.0, 1.0);
                p.translations[0] = Vec3::new(x, 0.9, 0.0);
                p
            })
            .collect();
        Clip {
            name: "lunge".into(),
            skeleton,
            frame_time: 1.0 / 30.0,
            frames,
        }
    }

    /// Limits on the root's speed alone (`top` m/s), judged at 30 fps.
    fn speed(top: f32) -> PaceLimits {
        PaceLimits {
            speed_m_s: top,
            accel_m_s2: f32::INFINITY,
            frame_s: 1.0 / 30.0,
        }
    }

    /// `clip` with neutral effort, played whole.
    fn neutral(clip: &Clip) -> EffortClip {
        apply_effort(
            clip,
            &Phrasing::whole(clip),
            Effort::default(),
            Vec3::X,
            false,
            None,
        )
    }

    fn fastest(ec: &EffortClip, seconds: f32) -> f32 {
        let n = (seconds * 30.0).round() as usize;
        let poses: Vec<Pose> = (0..=n).map(|k| ec.pose(k as f32 / n as f32)).collect();
        root_speed_max(&poses, seconds / n as f32)
    }

    #[test]
    fn a_lunge_too_fast_for_a_person_borrows_time_from_its_stillness() {
        let ec = neutral(&lunge());
        // Played over 1.05 s (2× fast) the lunge moves at 12 m/s.
        assert!(fastest(&ec, 1.05) > 10.0, "{}", fastest(&ec, 1.05));
        let (paced, seconds) = ec.paced(1.05, &speed(4.0));
        assert_eq!(seconds, 1.05, "the still parts had time to give");
        assert!(
            fastest(&paced, seconds) <= 4.0 * 1.02,
            "{}",
            fastest(&paced, seconds)
        );
        // Squeezed into 0.1 s it cannot be paced within the time: it takes longer.
        let (_, longer) = ec.paced(0.1, &speed(4.0));
        assert!(longer >= 0.6 / 4.0 - 1e-3, "{longer}");
        // Slow enough already: unchanged.
        let (same, s) = ec.paced(2.1, &speed(10.0));
        assert_eq!(s, 2.1);
        assert_eq!(same.source_time(0.5), ec.source_time(0.5));
    }

    /// A one-joint clip whose root drops 0.3 m and rises back over 1 s (30 fps): a squat,
    /// up to 0.15 · (2π)² ≈ 5.9 m/s² at its own pace.
    fn squat() -> Clip {
        let skeleton = Skeleton {
            joints: vec![Joint::bare("root", None, Vec3::ZERO)],
        };
        let frames = (0..=30)
            .map(|f| {
                let mut p = Pose::rest(&skeleton);
                let u = f as f32 / 30.0;
                p.translations[0] = Vec3::new(
                    0.0,
                    0.9 - 0.15 * (1.0 - (std::f32::consts::TAU * u).cos()),
                    0.0,
                );
                p
            })
            .collect();
        Clip {
            name: "squat".into(),
            skeleton,
            frame_time: 1.0 / 30.0,
            frames,
        }
    }

    /// The hardest root acceleration of `ec` played over `seconds` at 30 fps, m/s².
    fn hardest(ec: &EffortClip, seconds: f32) -> f32 {
        let n = (seconds * 30.0).round() as usize;
        let h = seconds / n as f32;
        let y: Vec<Vec3> = (0..=n)
            .map(|k| ec.pose(k as f32 / n as f32).translations[0])
            .collect();
        y.windows(3)
            .map(|w| (w[2] - 2.0 * w[1] + w[0]).length() / (h * h))
            .fold(0.0, f32::max)
    }

    #[test]
    fn a_squat_squeezed_into_a_short_event_takes_the_time_its_acceleration_needs() {
        let ec = neutral(&squat());
        // Squeezed 8× it would accelerate at 64 × 5.9 ≈ 380 m/s².
        assert!(hardest(&ec, 0.125) > 300.0, "{}", hardest(&ec, 0.125));
        let limits = PaceLimits {
            speed_m_s: 4.0,
            accel_m_s2: 20.0,
            frame_s: 1.0 / 30.0,
        };
        let (paced, seconds) = ec.paced(0.125, &limits);
        // ∫ √(|a| / 20) dt over the squat ≈ 0.41 s at the least.
        assert!(seconds > 0.35 && seconds < 0.5, "{seconds}");
        // Each stretch is held to the bound at its own pace; the change of pace from one
        // stretch to the next adds to it (here 47 m/s², 2.4× the bound: the pace is not yet
        // smoothed), still 8× less than the even squeeze's 380 m/s².
        eprintln!(
            "paced squat: {seconds:.3} s, hardest {:.1} m/s²",
            hardest(&paced, seconds)
        );
        assert!(
            hardest(&paced, seconds) <= 20.0 * 3.0,
            "{}",
            hardest(&paced, seconds)
        );
        // At its own pace or slower it is left alone.
        let (same, s) = ec.paced(1.5, &limits);
        assert_eq!(s, 1.5);
        assert_eq!(same.source_time(0.3), ec.source_time(0.3));
    }

    #[test]
    fn a_path_shrinks_about_its_start_to_what_a_person_covers() {
        let path = Polyline::new(vec![Vec2::ZERO, Vec2::new(3.0, 0.0), Vec2::new(3.0, 3.0)]);
        let short = shrink(&path, 2.0);
        assert!((short.length() - 2.0).abs() < 1e-5);
        assert!(short.pts[0].length() < 1e-6);
        assert!(
            (short.pts[2] - Vec2::new(1.0, 1.0)).length() < 1e-5,
            "{:?}",
            short.pts
        );
        assert_eq!(shrink(&path, 10.0).pts, path.pts);
    }
}
