//! Phrasing detection (seed 000 §6.1): cut a clip into motion stages at extreme poses.
//!
//! A stage ends at an extreme pose, where the body's speed and acceleration both vanish. We
//! measure the body's speed as the mean joint speed relative to the root's ground position
//! (so travel does not hide the pose's own stillness), smooth it over ~0.1 s, and take local
//! minima below [`STILL_FRACTION`] of the peak speed — or clearly below the motion on both
//! sides ([`PROMINENCE_RATIO`]), since real captures rarely stop dead — at least
//! [`MIN_STAGE_S`] apart, as extreme poses (at a minimum of the speed its derivative, the acceleration, is zero). At most
//! four are kept (the stillest), giving up to five stages, labelled in their fixed order.
//! With fewer stages we label by energy, refining the seed's rule: the execution releases
//! the energy, so it is the segment with the highest peak speed; the segment just before it
//! is an anticipation when it moves against it (anticipation gathers energy in the opposite
//! direction, the seed's criterion), otherwise a preparation; the one after is the
//! follow-through, later ones the transition.

use std::fmt;

use glam::Vec3;

use crate::motion::Clip;

/// A local speed minimum counts as an extreme pose below this fraction of the peak speed.
pub const STILL_FRACTION: f32 = 0.35;
/// A local minimum also counts when it is below this fraction of the highest speed within
/// [`PROMINENCE_WINDOW_S`] on each side.
pub const PROMINENCE_RATIO: f32 = 0.75;
/// Half-width (seconds) of the window for [`PROMINENCE_RATIO`].
pub const PROMINENCE_WINDOW_S: f32 = 0.5;
/// Minimum stage duration, seconds.
pub const MIN_STAGE_S: f32 = 0.15;
/// Smoothing window for the speed, seconds.
pub const SMOOTH_S: f32 = 0.1;

/// The five motion stages, in their order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Stage {
    /// Intention of the action.
    Preparation,
    /// Energy gathering, against the main motion.
    Anticipation,
    /// Energy release: the action itself.
    Execution,
    /// Motion induced by the execution.
    FollowThrough,
    /// Back to a hold pose or on to the next action.
    Transition,
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Stage::Preparation => "preparation",
            Stage::Anticipation => "anticipation",
            Stage::Execution => "execution",
            Stage::FollowThrough => "follow-through",
            Stage::Transition => "transition",
        })
    }
}

/// One stage: frames `start..=end` of the clip (consecutive stages share their boundary frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageSpan {
    /// The stage.
    pub stage: Stage,
    /// First frame.
    pub start: usize,
    /// Last frame (the extreme pose ending the stage).
    pub end: usize,
}

/// The phrasing of a clip.
#[derive(Debug, Clone, PartialEq)]
pub struct Phrasing {
    /// Stages in time order, covering the whole clip.
    pub spans: Vec<StageSpan>,
    /// Smoothed body speed per frame, length units per second.
    pub speed: Vec<f32>,
}

impl Phrasing {
    /// The span of a stage, if the clip has it.
    pub fn span(&self, stage: Stage) -> Option<StageSpan> {
        self.spans.iter().copied().find(|s| s.stage == stage)
    }

    /// A single execution stage over the whole clip (used for cyclic clips).
    pub fn whole(clip: &Clip) -> Phrasing {
        Phrasing {
            spans: vec![StageSpan {
                stage: Stage::Execution,
                start: 0,
                end: clip.len().saturating_sub(1),
            }],
            speed: vec![0.0; clip.len()],
        }
    }
}

/// Joint positions relative to the root's ground point, per frame.
fn body_positions(clip: &Clip) -> Vec<Vec<Vec3>> {
    clip.all_positions()
        .into_iter()
        .map(|p| {
            let r = p.first().copied().unwrap_or(Vec3::ZERO);
            let base = Vec3::new(r.x, 0.0, r.z);
            p.into_iter().map(|v| v - base).collect()
        })
        .collect()
}

fn smooth(v: &[f32], half: usize) -> Vec<f32> {
    (0..v.len())
        .map(|i| {
            let a = i.saturating_sub(half);
            let b = (i + half).min(v.len().saturating_sub(1));
            let s = &v[a..=b];
            s.iter().sum::<f32>() / s.len() as f32
        })
        .collect()
}

/// Detects the stages of a clip.
pub fn detect_stages(clip: &Clip) -> Phrasing {
    let n = clip.len();
    if n < 3 {
        return Phrasing::whole(clip);
    }
    let pos = body_positions(clip);
    let dt = clip.frame_time.max(1e-6);
    let mut speed = vec![0.0f32; n];
    for i in 0..n {
        let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
        let span = (b - a) as f32 * dt;
        let s: f32 = pos[a]
            .iter()
            .zip(&pos[b])
            .map(|(p, q)| (*q - *p).length())
            .sum();
        speed[i] = s / pos[i].len().max(1) as f32 / span;
    }
    let half = ((SMOOTH_S / dt / 2.0).round() as usize).max(1);
    let speed = smooth(&speed, half);
    let peak = speed.iter().copied().fold(0.0f32, f32::max);
    let min_gap = ((MIN_STAGE_S / dt).round() as usize).max(2);
    // Candidate extreme poses: local minima that are near-still, or clearly deeper than the
    // motion on both sides (real captures rarely stop completely between stages).
    let reach = ((PROMINENCE_WINDOW_S / dt).round() as usize).max(2);
    let mut cands: Vec<usize> = (1..n - 1)
        .filter(|&i| {
            let lo = i.saturating_sub(half).max(1);
            let hi = (i + half).min(n - 2);
            let is_min = (lo..=hi).all(|k| speed[i] <= speed[k]);
            let left = speed[i.saturating_sub(reach)..=i]
                .iter()
                .copied()
                .fold(0.0f32, f32::max);
            let right = speed[i..=(i + reach).min(n - 1)]
                .iter()
                .copied()
                .fold(0.0f32, f32::max);
            let deep = speed[i] < PROMINENCE_RATIO * left.min(right);
            is_min && (speed[i] < STILL_FRACTION * peak || deep) && i >= min_gap && i + min_gap < n
        })
        .collect();
    // Merge candidates closer than the minimum stage length (keep the stiller one).
    let mut merged: Vec<usize> = Vec::new();
    for c in cands.drain(..) {
        match merged.last_mut() {
            // Too close, or no real movement between them: one extreme pose, the stiller.
            Some(last)
                if c - *last < min_gap
                    || speed[*last..=c].iter().copied().fold(0.0f32, f32::max)
                        * PROMINENCE_RATIO
                        < speed[*last].max(speed[c]) =>
            {
                if speed[c] < speed[*last] {
                    *last = c;
                }
            }
            _ => merged.push(c),
        }
    }
    if merged.len() > 4 {
        let mut by_speed = merged.clone();
        by_speed.sort_by(|a, b| speed[*a].total_cmp(&speed[*b]));
        by_speed.truncate(4);
        by_speed.sort_unstable();
        merged = by_speed;
    }
    let mut bounds = vec![0];
    bounds.extend(&merged);
    bounds.push(n - 1);
    let segs: Vec<(usize, usize)> = bounds.windows(2).map(|w| (w[0], w[1])).collect();
    let reversal = |a: usize, b: usize| -> bool {
        match (segs.get(a), segs.get(b)) {
            (Some(&sa), Some(&sb)) => direction(&pos, sa).dot(&direction(&pos, sb)) < 0.0,
            _ => false,
        }
    };
    use Stage::*;
    let labels: Vec<Stage> = if segs.len() >= 5 {
        vec![
            Preparation,
            Anticipation,
            Execution,
            FollowThrough,
            Transition,
        ]
    } else {
        // Fewer than five stages: the execution releases the energy, so it is the segment
        // with the highest peak speed; the segment just before it is an anticipation if it
        // moves against it (else a preparation), the one after it a follow-through, and any
        // others preparation / transition.
        let peak_of =
            |&(a, b): &(usize, usize)| speed[a..=b].iter().copied().fold(0.0f32, f32::max);
        let exec = (0..segs.len())
            .max_by(|&x, &y| peak_of(&segs[x]).total_cmp(&peak_of(&segs[y])))
            .unwrap_or(0);
        (0..segs.len())
            .map(|k| match k {
                k if k == exec => Execution,
                k if k + 1 == exec && reversal(k, exec) => Anticipation,
                k if k < exec => Preparation,
                k if k == exec + 1 => FollowThrough,
                _ => Transition,
            })
            .collect()
    };
    let spans = segs
        .iter()
        .zip(labels)
        .map(|(&(start, end), stage)| StageSpan { stage, start, end })
        .collect();
    Phrasing { spans, speed }
}

/// Main direction of motion over a segment: all joints' displacements, concatenated.
struct Direction(Vec<Vec3>);

impl Direction {
    fn dot(&self, other: &Direction) -> f32 {
        self.0.iter().zip(&other.0).map(|(a, b)| a.dot(*b)).sum()
    }
}

fn direction(pos: &[Vec<Vec3>], (a, b): (usize, usize)) -> Direction {
    match (pos.get(a), pos.get(b)) {
        (Some(pa), Some(pb)) => Direction(pa.iter().zip(pb).map(|(p, q)| *q - *p).collect()),
        _ => Direction(Vec::new()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::skeleton::{Joint, Skeleton};
    use crate::motion::Pose;
    use glam::Quat;

    /// A one-arm clip: swing back (anticipation), swing far forward (execution), settle.
    fn swing() -> Clip {
        let j = Joint::bare;
        let sk = Skeleton {
            joints: vec![
                j("root", None, Vec3::ZERO),
                j("arm", Some(0), Vec3::ZERO),
                j("hand", Some(1), Vec3::new(0.0, -1.0, 0.0)),
            ],
        };
        // Angle keyframes (radians) at 30 fps, eased between with smoothstep.
        let keys = [(0, 0.0f32), (15, -0.6), (35, 1.5), (50, 1.2)];
        let mut frames = Vec::new();
        for f in 0..=50 {
            let k = keys
                .windows(2)
                .find(|w| f >= w[0].0 && f <= w[1].0)
                .unwrap();
            let u = (f - k[0].0) as f32 / (k[1].0 - k[0].0) as f32;
            let s = u * u * (3.0 - 2.0 * u);
            let a = k[0].1 + (k[1].1 - k[0].1) * s;
            let mut p = Pose::rest(&sk);
            p.rotations[1] = Quat::from_rotation_z(a);
            frames.push(p);
        }
        Clip {
            name: "swing".into(),
            skeleton: sk,
            frame_time: 1.0 / 30.0,
            frames,
        }
    }

    #[test]
    fn swing_has_anticipation_then_execution() {
        let ph = detect_stages(&swing());
        let stages: Vec<Stage> = ph.spans.iter().map(|s| s.stage).collect();
        assert_eq!(
            stages,
            vec![Stage::Anticipation, Stage::Execution, Stage::FollowThrough],
            "{:?}",
            ph.spans
        );
        let ex = ph.span(Stage::Execution).unwrap();
        assert!(
            (ex.start as i32 - 15).abs() <= 2 && (ex.end as i32 - 35).abs() <= 2,
            "{ex:?}"
        );
        assert_eq!(ph.spans.last().unwrap().end, 50);
    }

    #[test]
    fn default_clips_have_an_execution_stage() {
        if crate::data::data_file("deepmimic", "humanoid.urdf").is_none() {
            eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
            return;
        }
        let lib = crate::anim::library::ClipLibrary::default_library().unwrap();
        let clips = lib.load(["punch", "kick", "jump"]).unwrap();
        for (name, c) in clips {
            let ph = detect_stages(&c.clip);
            let sp: Vec<String> = ph
                .speed
                .iter()
                .step_by(3)
                .map(|v| format!("{v:.2}"))
                .collect();
            eprintln!("{name}: {:?} speed/3f {}", ph.spans, sp.join(" "));
            assert!(
                ph.span(Stage::Execution).is_some(),
                "{name}: {:?}",
                ph.spans
            );
            assert!(ph.spans.len() >= 2, "{name}: {:?}", ph.spans);
        }
    }
}
