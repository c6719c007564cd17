//! Laban Effort from the graph's EFFORT measurements: joining the doodle recogniser (seed 000),
//! which reports an action's effort (Lt, Lw), with the style graph (seed 003).
//!
//! A window's effort is estimated from its EFFORT-component measurements, standardised over the
//! graph's library (so "sudden" means sudden relative to this library):
//! - Time `Lt` (> 0 sudden, < 0 sustained) = tanh of the mean z-score of the deceleration
//!   peaks (φ53), the acceleration maxima of pelvis, hands and feet (φ69, 71, 73, 75, 77) and
//!   the jerk maximum (φ79);
//! - Weight `Lw` (> 0 strong, < 0 light) = tanh of the mean z-score of the velocity maxima and
//!   means of pelvis, hands and feet (φ54, 56, 57, 59, 60, 62, 63, 65, 66, 68) — the kinetic
//!   energy the body puts into the movement.
//!
//! The signs follow DESIGN.md's effort convention. [`MotionGraph::best_transition`] adds an
//! effort match to the usual posture / style score, and [`rank_clips_by_effort`] /
//! [`rank_spans_by_effort`] order clip variants of one action by how well their effort matches
//! a recognised one.

use std::ops::Range;

use super::graph::{MotionGraph, Transition, Variant};
use super::lma::{Component, MEASUREMENTS};
use super::style::{pearson, Standardiser};

/// 0-based measurement indices (φ_k − 1) driving Laban Time.
pub const TIME_MEASUREMENTS: [usize; 7] = [52, 68, 70, 72, 74, 76, 78];
/// 0-based measurement indices driving Laban Weight.
pub const WEIGHT_MEASUREMENTS: [usize; 10] = [53, 55, 56, 58, 59, 61, 62, 64, 65, 67];

/// How much an effort match adds to a transition's score (posture / style are in [0, 1]).
pub const EFFORT_WEIGHT: f32 = 1.0;

/// A Laban effort estimate: both components in [−1, 1].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Effort {
    /// Time: > 0 sudden, < 0 sustained.
    pub time: f32,
    /// Weight: > 0 strong, < 0 light.
    pub weight: f32,
}

impl Effort {
    /// Effort of one window from its raw measurements and the library's standardiser.
    pub fn of_measurements(raw: &[f32], st: &Standardiser) -> Effort {
        let z = |k: usize| match (raw.get(k), st.mean.get(k), st.std.get(k)) {
            (Some(v), Some(m), Some(s)) => (v - m) / s,
            _ => 0.0,
        };
        let mean = |ks: &[usize]| ks.iter().map(|&k| z(k)).sum::<f32>() / ks.len() as f32;
        Effort {
            time: mean(&TIME_MEASUREMENTS).tanh(),
            weight: mean(&WEIGHT_MEASUREMENTS).tanh(),
        }
    }

    /// Similarity of two efforts ∈ [0, 1]: 1 − (|ΔLt| + |ΔLw|)/4.
    pub fn matches(&self, other: &Effort) -> f32 {
        let d = (self.time - other.time).abs() + (self.weight - other.weight).abs();
        if d.is_finite() {
            (1.0 - d / 4.0).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }
}

impl MotionGraph {
    /// Effort of the window centred on global frame `frame` (None outside windows).
    pub fn effort_at(&self, frame: u32) -> Option<Effort> {
        Some(Effort::of_measurements(
            self.window_measurements(frame)?,
            &self.standardiser,
        ))
    }

    /// Mean effort of a clip's windows.
    pub fn clip_effort(&self, clip: usize) -> Option<Effort> {
        self.clip_effort_between(clip, 0.0..f32::INFINITY)
    }

    /// Mean effort of the windows of clip `clip` centred within `span` (seconds from the
    /// clip's start); when no window is centred there (a span shorter than a window, near an
    /// end), the window nearest the span's middle. `None` if the clip has no full window.
    pub fn clip_effort_between(&self, clip: usize, span: Range<f32>) -> Option<Effort> {
        let c = self.clips.get(clip)?;
        let last = c.frames.checked_sub(1)?;
        let frame = |t: f32| -> u32 {
            if t.is_finite() {
                (t * super::FPS).round().clamp(0.0, last as f32) as u32
            } else if t > 0.0 {
                last
            } else {
                0
            }
        };
        let (f0, f1) = (frame(span.start), frame(span.end));
        let (mut t, mut w, mut n) = (0.0f32, 0.0f32, 0usize);
        for f in f0..=f1.max(f0) {
            if let Some(e) = self.effort_at(c.start + f) {
                t += e.time;
                w += e.weight;
                n += 1;
            }
        }
        if n == 0 {
            let (lo, hi) = (super::HALF as u32, last.checked_sub(super::HALF as u32)?);
            let mid = ((f0 + f1.max(f0)) / 2).clamp(lo, hi.max(lo));
            return self.effort_at(c.start + mid);
        }
        Some(Effort {
            time: t / n as f32,
            weight: w / n as f32,
        })
    }

    /// Pearson r of the EFFORT component between the windows centred on two frames.
    pub fn effort_correlation(&self, a: u32, b: u32) -> Option<f32> {
        let va = self
            .standardiser
            .style_vectors(self.window_measurements(a)?);
        let vb = self
            .standardiser
            .style_vectors(self.window_measurements(b)?);
        let k = Component::ALL
            .iter()
            .position(|c| *c == Component::Effort)?;
        (va.len() == MEASUREMENTS && vb.len() == MEASUREMENTS).then(|| pearson(&va, &vb)[k])
    }

    /// The best transition leaving any frame in `from_frames` (global), landing in one of the
    /// clips `to_clips` (all clips if empty), scored by the variant's correlation (posture for
    /// MG, style for LMA-MG) plus [`EFFORT_WEIGHT`] × the match between `effort` (a recognised
    /// (Lt, Lw)) and the destination window's effort. `transitions` comes from
    /// [`MotionGraph::transitions`].
    pub fn best_transition(
        &self,
        transitions: &[Vec<Transition>],
        from_frames: Range<u32>,
        to_clips: &[usize],
        effort: Option<Effort>,
        variant: Variant,
    ) -> Option<Transition> {
        let mut best: Option<(f32, Transition)> = None;
        for f in from_frames {
            for t in transitions.get(f as usize).into_iter().flatten() {
                let clip = self.clip_of(t.to);
                if !to_clips.is_empty() && !clip.is_some_and(|c| to_clips.contains(&c)) {
                    continue;
                }
                let base = match variant {
                    Variant::Mg => t.posture,
                    Variant::Lma => t.style,
                };
                let bonus = match (effort, self.effort_at(t.to)) {
                    (Some(want), Some(have)) => EFFORT_WEIGHT * want.matches(&have),
                    _ => 0.0,
                };
                let score = base + bonus;
                if best.as_ref().is_none_or(|(s, _)| score > *s) {
                    best = Some((score, *t));
                }
            }
        }
        best.map(|(_, t)| t)
    }
}

/// A transition between two source clips, in seconds of each clip (rate-independent).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClipCut {
    /// Time in the clip left, seconds from its start.
    pub from_time: f32,
    /// Time in the clip joined, seconds from its start (playback continues after it).
    pub to_time: f32,
    /// Posture correlation ∈ [0, 1].
    pub posture: f32,
    /// Style similarity ∈ [0, 1].
    pub style: f32,
    /// Match between the wanted effort and the destination window's effort ∈ [0, 1] (0 if none
    /// was asked for).
    pub effort_match: f32,
}

impl MotionGraph {
    /// Index of the clip whose name (file stem) or recorded path is `key`.
    pub fn clip_index(&self, key: &str) -> Option<usize> {
        self.clips
            .iter()
            .position(|c| c.name == key || c.path == key)
            .or_else(|| {
                let stem = std::path::Path::new(key)
                    .file_stem()?
                    .to_string_lossy()
                    .into_owned();
                let stem = stem
                    .strip_prefix("humanoid3d_")
                    .unwrap_or(&stem)
                    .to_string();
                self.clips.iter().position(|c| c.name == stem)
            })
    }

    /// The best transition from clip `from` (leaving between `from_window` seconds of it) to
    /// clip `to` (joining between `to_window` seconds), scored like [`MotionGraph::best_transition`].
    /// For an animation assembler: ranges are in seconds of the source clips.
    pub fn best_cut_between(
        &self,
        transitions: &[Vec<Transition>],
        (from, from_window): (usize, Range<f32>),
        (to, to_window): (usize, Range<f32>),
        effort: Option<Effort>,
        variant: Variant,
    ) -> Option<ClipCut> {
        let (a, b) = (self.clips.get(from)?, self.clips.get(to)?);
        let frame = |c: &super::graph::ClipEntry, t: f32| -> u32 {
            let f = (t * super::FPS)
                .round()
                .clamp(0.0, c.frames.saturating_sub(1) as f32);
            c.start + f as u32
        };
        let (fa0, fa1) = (frame(a, from_window.start), frame(a, from_window.end));
        let (fb0, fb1) = (frame(b, to_window.start), frame(b, to_window.end));
        let mut best: Option<(f32, ClipCut)> = None;
        for f in fa0..=fa1 {
            for t in transitions.get(f as usize).into_iter().flatten() {
                if !(fb0..=fb1).contains(&t.to) {
                    continue;
                }
                let base = match variant {
                    Variant::Mg => t.posture,
                    Variant::Lma => t.style,
                };
                let m = match (effort, self.effort_at(t.to)) {
                    (Some(want), Some(have)) => want.matches(&have),
                    _ => 0.0,
                };
                let score = base + EFFORT_WEIGHT * m;
                if best.as_ref().is_none_or(|(s, _)| score > *s) {
                    best = Some((
                        score,
                        ClipCut {
                            from_time: (t.from - a.start) as f32 / super::FPS,
                            to_time: (t.to - b.start) as f32 / super::FPS,
                            posture: t.posture,
                            style: t.style,
                            effort_match: m,
                        },
                    ));
                }
            }
        }
        best.map(|(_, c)| c)
    }
}

/// Clip indices ordered by how well their mean effort matches `effort` (best first), with the
/// match ∈ [0, 1]; clips without a full window are left out.
pub fn rank_clips_by_effort(
    graph: &MotionGraph,
    clips: &[usize],
    effort: Effort,
) -> Vec<(usize, f32)> {
    let mut out: Vec<(usize, f32)> = clips
        .iter()
        .filter_map(|&c| Some((c, graph.clip_effort(c)?.matches(&effort))))
        .collect();
    out.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    out
}

/// Spans `(clip, seconds)` ordered by how well their mean effort
/// ([`MotionGraph::clip_effort_between`]) matches `effort` (best first, ties by position):
/// (index into `spans`, match ∈ [0, 1]); spans without a window are left out.
pub fn rank_spans_by_effort(
    graph: &MotionGraph,
    spans: &[(usize, Range<f32>)],
    effort: Effort,
) -> Vec<(usize, f32)> {
    let mut out: Vec<(usize, f32)> = spans
        .iter()
        .enumerate()
        .filter_map(|(i, (c, r))| {
            Some((
                i,
                graph.clip_effort_between(*c, r.clone())?.matches(&effort),
            ))
        })
        .collect();
    out.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::build::{build_graph, tests::fake_clip};
    use crate::graph::lma::tests::synthetic;
    use crate::graph::BuildParams;

    #[test]
    fn fast_swinging_clip_is_sudden_and_strong() {
        let clips = vec![
            fake_clip("calm", synthetic(90, 0.1, 0.05)),
            fake_clip("wild", synthetic(90, 1.5, 0.6)),
        ];
        let (g, _) = build_graph(&clips, &BuildParams::default()).unwrap();
        let calm = g.clip_effort(0).unwrap();
        let wild = g.clip_effort(1).unwrap();
        assert!(
            wild.time > calm.time && wild.weight > calm.weight,
            "{calm:?} {wild:?}"
        );
        assert!(wild.weight > 0.0 && calm.weight < 0.0);
        let strong = Effort {
            time: 0.8,
            weight: 0.8,
        };
        let light = Effort {
            time: -0.8,
            weight: -0.8,
        };
        assert_eq!(rank_clips_by_effort(&g, &[0, 1], strong)[0].0, 1);
        assert_eq!(rank_clips_by_effort(&g, &[0, 1], light)[0].0, 0);
        // Spans: the same ranking through sub-ranges, a span shorter than a window included.
        let spans = [(0, 0.5..0.6), (1, 0.0..3.0)];
        assert_eq!(rank_spans_by_effort(&g, &spans, strong)[0].0, 1);
        assert_eq!(rank_spans_by_effort(&g, &spans, light)[0].0, 0);
        let whole = g.clip_effort(1).unwrap();
        let part = g.clip_effort_between(1, 0.0..100.0).unwrap();
        assert_eq!(whole, part);
        assert!(g.clip_effort_between(5, 0.0..1.0).is_none());
    }

    #[test]
    fn best_transition_prefers_matching_effort() {
        let clips = vec![
            fake_clip("a", synthetic(90, 0.3, 0.3)),
            fake_clip("calm", synthetic(90, 0.3, 0.05)),
            fake_clip("wild", synthetic(90, 0.3, 0.6)),
        ];
        let (mut g, _) = build_graph(&clips, &BuildParams::default()).unwrap();
        // Hand-made transitions from clip a's frame 45 to both variants, equal scores.
        g.edges = vec![
            crate::graph::Edge {
                from: 45,
                to: 90 + 45,
                posture: 0.95,
                style: 0.9,
            },
            crate::graph::Edge {
                from: 45,
                to: 180 + 45,
                posture: 0.95,
                style: 0.9,
            },
        ];
        let tr = g.transitions(Variant::Lma, Some(0.0), Some(0.0));
        let pick = |e| {
            g.best_transition(&tr, 40..50, &[1, 2], Some(e), Variant::Lma)
                .unwrap()
                .to
        };
        assert_eq!(
            pick(Effort {
                time: 1.0,
                weight: 1.0
            }),
            225
        );
        assert_eq!(
            pick(Effort {
                time: -1.0,
                weight: -1.0
            }),
            135
        );
        assert!(g
            .best_transition(&tr, 0..10, &[], None, Variant::Lma)
            .is_none());
        let cut = g
            .best_cut_between(
                &tr,
                (0, 1.0..2.0),
                (2, 0.0..3.0),
                Some(Effort {
                    time: 1.0,
                    weight: 1.0,
                }),
                Variant::Lma,
            )
            .unwrap();
        assert_eq!((cut.from_time, cut.to_time), (1.5, 1.5));
        assert!(cut.effort_match > 0.0);
        assert!(g
            .best_cut_between(&tr, (0, 1.0..2.0), (1, 0.0..1.0), None, Variant::Mg)
            .is_none());
        assert_eq!(g.clip_index("wild"), Some(2));
        assert_eq!(g.clip_index("/x/y/wild.bvh"), Some(2));
        let r = g.effort_correlation(45, 135).unwrap();
        assert!((-1.0..=1.0).contains(&r));
    }
}
