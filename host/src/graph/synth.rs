//! Synthesis on a motion graph: by highest similarity (§5.3) and by example (§5.4).
//!
//! Planning walks the largest strongly connected component of the chosen variant (so the walk
//! never dead-ends): it starts at a seeded random frame, plays the clip forward and, between 80
//! and 100 frames after the previous jump, takes the transition with the highest similarity
//! found in that span — posture correlation for MG, style correlation for LMA-MG (the paper's
//! choice), or, by example, the destination window whose style best matches the reference clip's
//! window at that output time. When the clip would leave the component, the best available
//! transition is taken at once. Landing again near one of the last [`RECENT_JUMPS`] landings
//! costs [`REPEAT_PENALTY`], so a walk does not loop one passage when it has other choices, and
//! landing where fewer than [`MIN_RUN`] frames can play costs [`SHORT_PENALTY`].
//!
//! Rendering turns the plan into poses of the source clips: every segment is placed with a
//! rotation about the vertical and a floor translation (eq. 1's alignment of the two windows,
//! anchored so the roots meet), and the first [`BLEND_FRAMES`] frames after a transition blend
//! the old clip's continuation into the new clip (slerp / lerp).

use std::collections::HashMap;
use std::path::Path;

use glam::{Quat, Vec3};

use crate::motion::{Clip, Pose};

use super::graph::{MotionGraph, Transition, Variant, BLEND_FRAMES};
use super::lma::{clip_measurements, MEASUREMENTS};
use super::posture::align_windows;
use super::roles::RoleOverrides;
use super::source::{load_clip, GraphClip};
use super::style::{pearson, similarity};
use super::{GraphError, HALF, WINDOW};

/// Fewest frames between forced transitions (§5.3).
pub const MIN_SEGMENT: usize = 80;
/// Most frames between forced transitions (§5.3).
pub const MAX_SEGMENT: usize = 100;

/// Jumps remembered to avoid looping the same passage.
pub const RECENT_JUMPS: usize = 8;
/// Score subtracted from a transition landing within a window of a recent jump's landing.
pub const REPEAT_PENALTY: f32 = 1.0;

/// Fewest frames a jump's destination should be able to play before the next forced jump.
pub const MIN_RUN: usize = WINDOW;
/// Score subtracted from a transition whose destination plays fewer than [`MIN_RUN`] frames.
pub const SHORT_PENALTY: f32 = 0.5;

/// A small seeded generator (SplitMix64) so plans are reproducible.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform integer in `lo..=hi`.
    pub fn range(&mut self, lo: usize, hi: usize) -> usize {
        lo + (self.next_u64() % (hi.saturating_sub(lo) as u64 + 1)) as usize
    }
}

/// A planned walk: the source frame of every output frame and the transitions taken.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Plan {
    /// Global source frame per output frame (30 fps).
    pub frames: Vec<u32>,
    /// (output frame index of the jump, transition): output frame `k` plays `t.to + 1`.
    pub cuts: Vec<(usize, Transition)>,
}

/// How a walk picks its transitions.
pub enum Chooser<'a> {
    /// Highest similarity of the variant (posture for MG, style for LMA-MG).
    Similarity(Variant),
    /// Destination whose style best matches the reference window at that output frame
    /// (style vectors of the reference, `windows × MEASUREMENTS`).
    Example(&'a [f32]),
}

/// Style vectors of every window of the graph, indexed like its measurements.
fn graph_style(g: &MotionGraph) -> Vec<f32> {
    g.standardiser.style_vectors(&g.measurements)
}

/// Plans `frames` output frames on `g` (variant `v`), starting at `start` or a seeded random
/// frame of the component.
pub fn plan(
    g: &MotionGraph,
    v: Variant,
    chooser: &Chooser<'_>,
    frames: usize,
    start: Option<u32>,
    rng: &mut Rng,
) -> Result<Plan, GraphError> {
    let trans = g.transitions(v, None, None);
    let scc = g.largest_scc(&trans);
    let members: Vec<u32> = (0..scc.len() as u32).filter(|&f| scc[f as usize]).collect();
    if members.is_empty() {
        return Err(GraphError::Invalid(format!(
            "the {v:?} graph has no cycle to walk ({} transitions); lower --t-mg/--t-lma when building or add clips",
            g.count(v, None, None)
        )));
    }
    let weights = g.params.weights.normalised();
    let style = match chooser {
        Chooser::Example(_) => graph_style(g),
        Chooser::Similarity(_) => Vec::new(),
    };
    let ref_windows = match chooser {
        Chooser::Example(r) => r.len() / MEASUREMENTS,
        _ => 0,
    };
    let example_score = |to: u32, out_frame: usize| -> f32 {
        let Chooser::Example(r) = chooser else {
            return 0.0;
        };
        let Some(w) = g.window_of(to) else { return 0.0 };
        let rw = out_frame
            .saturating_sub(HALF)
            .min(ref_windows.saturating_sub(1));
        match (
            style.get(w * MEASUREMENTS..(w + 1) * MEASUREMENTS),
            r.get(rw * MEASUREMENTS..(rw + 1) * MEASUREMENTS),
        ) {
            (Some(a), Some(b)) => similarity(pearson(a, b), &weights),
            _ => 0.0,
        }
    };
    let next_natural = |f: u32| -> Option<u32> {
        let c = &g.clips[g.clip_of(f)?];
        (f + 1 < c.start + c.frames && scc[f as usize + 1]).then_some(f + 1)
    };
    // Frames playable from each frame before its clip leaves the component (backward pass).
    let mut run = vec![0u32; scc.len()];
    for f in (0..scc.len()).rev() {
        if let Some(n) = next_natural(f as u32) {
            run[f] = run[n as usize].saturating_add(1);
        }
    }
    // Destinations of the last few jumps: landing there again would loop the same passage.
    let recent = std::cell::RefCell::new(std::collections::VecDeque::<u32>::new());
    let score = |t: &Transition, out_frame: usize| -> f32 {
        let base = match chooser {
            Chooser::Similarity(Variant::Mg) => t.posture,
            Chooser::Similarity(Variant::Lma) => t.style,
            Chooser::Example(_) => example_score(t.to, out_frame),
        };
        let repeat = recent
            .borrow()
            .iter()
            .any(|&r| r.abs_diff(t.to) < WINDOW as u32);
        let short = run
            .get(t.to as usize + 1)
            .is_some_and(|&r| (r as usize) < MIN_RUN);
        base - if repeat { REPEAT_PENALTY } else { 0.0 } - if short { SHORT_PENALTY } else { 0.0 }
    };
    let usable = |f: u32| -> Vec<Transition> {
        trans
            .get(f as usize)
            .map(|l| {
                l.iter()
                    .filter(|t| scc.get(t.to as usize + 1).copied().unwrap_or(false))
                    .copied()
                    .collect()
            })
            .unwrap_or_default()
    };
    let mut cur = match start {
        Some(s) if scc.get(s as usize).copied().unwrap_or(false) => s,
        Some(s) => {
            // Nearest member of the component (the example's best match may be outside).
            *members
                .iter()
                .min_by_key(|&&m| m.abs_diff(s))
                .unwrap_or(&members[0])
        }
        None => {
            let clips: Vec<usize> = (0..g.clips.len())
                .filter(|&c| members.iter().any(|&m| g.clip_of(m) == Some(c)))
                .collect();
            let c = clips[rng.range(0, clips.len() - 1)];
            let in_clip: Vec<u32> = members
                .iter()
                .copied()
                .filter(|&m| g.clip_of(m) == Some(c))
                .collect();
            in_clip[rng.range(0, in_clip.len() - 1)]
        }
    };
    let mut out = Plan::default();
    out.frames.push(cur);
    let mut since = 0usize;
    while out.frames.len() < frames {
        let natural = next_natural(cur);
        // Frames playable before the clip leaves the component (bounded by the span's end).
        let mut to_forced = 0usize;
        let mut f = cur;
        while to_forced < MAX_SEGMENT {
            match next_natural(f) {
                Some(n) => {
                    f = n;
                    to_forced += 1;
                }
                None => break,
            }
        }
        let mut take: Option<Transition> = None;
        // Decide in the 80–100 span, or earlier if the clip would force a jump before it.
        if since >= MIN_SEGMENT || since + to_forced < MIN_SEGMENT || natural.is_none() {
            let horizon = MAX_SEGMENT.saturating_sub(since).min(to_forced + 1).max(1);
            let mut best: Option<(f32, usize, Transition)> = None;
            let mut f = cur;
            for ahead in 0..horizon {
                for t in usable(f) {
                    let s = score(&t, out.frames.len() + ahead);
                    if best.as_ref().is_none_or(|(b, _, _)| s > *b) {
                        best = Some((s, ahead, t));
                    }
                }
                match next_natural(f) {
                    Some(n) => f = n,
                    None => break,
                }
            }
            if let Some((_, 0, t)) = best {
                take = Some(t);
            }
        }
        match take {
            Some(t) => {
                cur = t.to + 1;
                out.cuts.push((out.frames.len(), t));
                let mut r = recent.borrow_mut();
                r.push_back(t.to);
                if r.len() > RECENT_JUMPS {
                    r.pop_front();
                }
                since = 0;
            }
            None => match natural {
                Some(n) => {
                    cur = n;
                    since += 1;
                }
                None => {
                    return Err(GraphError::Invalid(format!(
                        "walk stuck at frame {cur}: no transition in the component (graph is inconsistent)"
                    )))
                }
            },
        }
        out.frames.push(cur);
    }
    Ok(out)
}

/// Poses the plan with the source clips (re-read from the graph's paths).
pub fn render(g: &MotionGraph, plan: &Plan, name: &str) -> Result<Clip, GraphError> {
    let overrides: RoleOverrides = g.roles.clone();
    let mut loaded: HashMap<usize, GraphClip> = HashMap::new();
    for &f in &plan.frames {
        let ci = g
            .clip_of(f)
            .ok_or_else(|| GraphError::Invalid(format!("plan frame {f} is outside the graph")))?;
        if let std::collections::hash_map::Entry::Vacant(e) = loaded.entry(ci) {
            let entry = &g.clips[ci];
            let c = load_clip(Path::new(&entry.path), &overrides)?;
            if c.len() != entry.frames as usize {
                return Err(GraphError::Invalid(format!(
                    "{}: has {} frames at 30 fps but the graph was built with {}; rebuild the graph",
                    entry.path,
                    c.len(),
                    entry.frames
                )));
            }
            e.insert(c);
        }
    }
    let source = |f: u32| -> (&GraphClip, usize) {
        let ci = g.clip_of(f).unwrap_or(0);
        let c = &loaded[&ci];
        (c, (f - g.clips[ci].start) as usize)
    };
    let first = source(plan.frames[0]).0;
    let skeleton = first.clip.skeleton.clone();
    let roots: Vec<usize> = (0..skeleton.len())
        .filter(|&j| skeleton.joints[j].parent.is_none())
        .collect();
    let place = |pose: &Pose, rot: Quat, shift: Vec3| -> Pose {
        let mut p = pose.clone();
        for &r in &roots {
            if let Some(t) = p.translations.get_mut(r) {
                *t = rot * *t + shift;
            }
            if let Some(q) = p.rotations.get_mut(r) {
                *q = (rot * *q).normalize();
            }
        }
        p
    };
    // Current placement: rotation about y and floor shift (source units).
    let (mut rot, mut shift) = (Quat::IDENTITY, Vec3::ZERO);
    let mut prev: Option<(u32, Quat, Vec3)> = None; // the left clip's frame and placement
    let mut cuts = plan.cuts.iter().peekable();
    let mut frames = Vec::with_capacity(plan.frames.len());
    let mut blend_left = 0usize;
    for (k, &f) in plan.frames.iter().enumerate() {
        if let Some((_, t)) = cuts.next_if(|(at, _)| *at == k) {
            let (ca, la) = source(t.from);
            let (cb, lb) = source(t.to);
            let wa = &ca.points[la - HALF..=la + HALF];
            let wb = &cb.points[lb - HALF..=lb + HALF];
            let (al, _) = align_windows(wa, wb);
            let new_rot = (Quat::from_rotation_y(al.theta) * rot).normalize();
            let root_a = ca.clip.frames[la]
                .translations
                .first()
                .copied()
                .unwrap_or(Vec3::ZERO);
            let root_b = cb.clip.frames[lb]
                .translations
                .first()
                .copied()
                .unwrap_or(Vec3::ZERO);
            let placed_a = rot * root_a + shift;
            let mut new_shift = placed_a - new_rot * root_b;
            new_shift.y = 0.0;
            prev = Some((t.from, rot, shift));
            rot = new_rot;
            shift = new_shift;
            blend_left = BLEND_FRAMES;
        }
        let (c, l) = source(f);
        let mut pose = place(&c.clip.frames[l], rot, shift);
        if blend_left > 0 {
            if let Some((from, r0, s0)) = prev {
                let step = (BLEND_FRAMES - blend_left + 1) as u32;
                let (ca, la) = source(from);
                if let Some(old) = ca.clip.frames.get(la + step as usize) {
                    let same_clip_run = g.clip_of(from) == g.clip_of(from + step);
                    if same_clip_run {
                        let old = place(old, r0, s0);
                        let w = (BLEND_FRAMES - blend_left + 1) as f32 / (BLEND_FRAMES + 1) as f32;
                        pose = old.blend(&pose, w);
                    }
                }
            }
            blend_left -= 1;
        }
        frames.push(pose);
    }
    Ok(Clip {
        name: name.to_string(),
        skeleton,
        frame_time: 1.0 / super::FPS,
        frames,
    })
}

/// Style vectors of a reference clip's windows, standardised like the graph's library.
pub fn reference_style(g: &MotionGraph, reference: &GraphClip) -> Vec<f32> {
    g.standardiser
        .style_vectors(&clip_measurements(&reference.points))
}

/// The graph frame (window centre) whose style best matches the reference's first window.
pub fn best_start(g: &MotionGraph, reference_style: &[f32]) -> Option<u32> {
    let style = graph_style(g);
    let first = reference_style.get(..MEASUREMENTS)?;
    let weights = g.params.weights.normalised();
    (0..g.frames() as u32)
        .filter_map(|f| {
            let w = g.window_of(f)?;
            let s = similarity(
                pearson(style.get(w * MEASUREMENTS..(w + 1) * MEASUREMENTS)?, first),
                &weights,
            );
            Some((s, f))
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, f)| f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::graph::tests::toy_graph;
    use crate::graph::Edge;

    fn e(from: u32, to: u32, posture: f32, style: f32) -> Edge {
        Edge {
            from,
            to,
            posture,
            style,
        }
    }

    #[test]
    fn walk_never_dead_ends_and_cuts_every_80_to_100_frames() {
        // Two 300-frame clips linked in both directions at several points.
        let edges = vec![
            e(50, 350, 0.95, 0.9),
            e(150, 450, 0.92, 0.85),
            e(250, 550, 0.97, 0.95),
            e(120, 220, 0.93, 0.9),
            e(400, 500, 0.94, 0.9),
        ];
        let g = toy_graph(edges, &[300, 300]);
        let mut rng = Rng::new(7);
        let p = plan(
            &g,
            Variant::Lma,
            &Chooser::Similarity(Variant::Lma),
            3000,
            None,
            &mut rng,
        )
        .unwrap();
        assert_eq!(p.frames.len(), 3000);
        assert!(p.cuts.len() >= 10, "{} cuts", p.cuts.len());
        let mut last = 0;
        for (k, t) in &p.cuts {
            assert_eq!(p.frames[*k], t.to + 1);
            assert_eq!(p.frames[*k - 1], t.from);
            last = *k;
        }
        let _ = last;
        // Between cuts the walk advances one frame within a clip.
        for w in p.frames.windows(2).enumerate() {
            let (k, f) = w;
            if !p.cuts.iter().any(|(at, _)| *at == k + 1) {
                assert_eq!(f[1], f[0] + 1, "at {k}");
            }
        }
        // Same seed, same plan.
        let q = plan(
            &g,
            Variant::Lma,
            &Chooser::Similarity(Variant::Lma),
            3000,
            None,
            &mut Rng::new(7),
        )
        .unwrap();
        assert_eq!(p, q);
    }

    #[test]
    fn empty_component_is_a_clear_error() {
        let g = toy_graph(vec![e(50, 350, 0.95, 0.1)], &[300, 300]);
        let err = plan(
            &g,
            Variant::Lma,
            &Chooser::Similarity(Variant::Lma),
            100,
            None,
            &mut Rng::new(1),
        )
        .unwrap_err();
        assert!(err.to_string().contains("no cycle"), "{err}");
    }
}
