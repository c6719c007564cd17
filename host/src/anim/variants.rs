//! Clip variants chosen by effort: the recognised Laban Time and Weight of an action pick which
//! of its clips plays (the join of seed 000's effort recognition and seed 003's LMA features).
//!
//! Every variant gets an effort estimate from its **Effort-component LMA measurements**
//! ([`crate::graph::effort`]: Time from deceleration peaks, acceleration maxima and jerk; Weight
//! from the velocity maxima and means of pelvis, hands and feet), computed over 35-frame
//! windows at 30 fps of the clip itself and standardised over the windows of all the action's
//! variants — so "sudden" means sudden *for this action*: the most sudden of three punches is
//! the sudden punch even if every punch is faster than a walk. A variant shorter than one
//! window is measured on the clip played forwards then backwards (speeds and accelerations
//! kept) until a window fits.
//!
//! With a motion graph (`figurine animate --graph G.bin`) whose clips include every variant's
//! source file, the graph's own estimates are used instead (standardised over the graph's
//! library, over the variant's frame range: [`rank_spans_by_effort`]); otherwise the clip-based
//! ones. The variant with the best match `1 − (|ΔLt| + |ΔLw|)/4` wins, but the primary (first)
//! variant is kept unless another beats it by [`VARIANT_MARGIN`] — a neutral effort, halfway
//! between a sustained and a sudden variant, plays the library's default clip rather than
//! whichever side rounding favours. Ties go to the earlier variant, so the choice is
//! deterministic.

use super::graph_cuts::GraphGuide;
use super::library::ActionClip;
use crate::graph::effort::{rank_spans_by_effort, Effort};

/// How much better (in match units, [0, 1]) another variant must match the recognised effort
/// than the primary to replace it (0.05 = a summed |ΔLt| + |ΔLw| of 0.2).
pub const VARIANT_MARGIN: f32 = 0.05;

/// Which variant of an action was played, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct VariantChoice {
    /// Position of the variant in the library's list (0 = primary).
    pub index: usize,
    /// Variant name.
    pub name: String,
    /// Match between the recognised effort and the variant's ∈ [0, 1].
    pub effort_match: f32,
    /// The variant's effort estimate that was compared.
    pub variant_effort: Effort,
    /// Whether the estimate came from the motion graph (else from the clip itself).
    pub by_graph: bool,
    /// Number of variants the action has.
    pub of: usize,
}

/// The variant of `ac`'s action whose effort best matches `want` (Lt, Lw ∈ [−1, 1]; non-finite
/// values count as neutral), with the reason; `None` for the reason when the action has a
/// single clip. With `guide`, the motion graph's estimates are used when it holds every
/// variant's source clip.
pub fn choose_variant<'a>(
    ac: &'a ActionClip,
    want: Effort,
    guide: Option<&GraphGuide>,
) -> (&'a ActionClip, Option<VariantChoice>) {
    let all: Vec<&ActionClip> = ac.variants().collect();
    if all.len() < 2 {
        return (ac, None);
    }
    let f = |x: f32| {
        if x.is_finite() {
            x.clamp(-1.0, 1.0)
        } else {
            0.0
        }
    };
    let want = Effort {
        time: f(want.time),
        weight: f(want.weight),
    };
    let chosen = |(i, m, e): (usize, f32, Effort), by_graph: bool| {
        (
            all[i],
            Some(VariantChoice {
                index: i,
                name: all[i].variant.clone(),
                effort_match: m,
                variant_effort: e,
                by_graph,
                of: all.len(),
            }),
        )
    };
    if let Some(c) = guide.and_then(|g| graph_choice(&all, want, g)) {
        return chosen(c, true);
    }
    let scored: Vec<(usize, f32, Effort)> = all
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let e = v.effort.unwrap_or_default();
            (i, e.matches(&want), e)
        })
        .collect();
    chosen(pick(&scored).unwrap_or((0, 0.0, Effort::default())), false)
}

/// The graph's ranking, if it knows every variant: (index, match, variant effort).
fn graph_choice(
    all: &[&ActionClip],
    want: Effort,
    guide: &GraphGuide,
) -> Option<(usize, f32, Effort)> {
    let g = &guide.graph;
    let spans: Vec<(usize, std::ops::Range<f32>)> = all
        .iter()
        .map(|v| {
            let c = g.clip_index(&v.file.to_string_lossy())?;
            Some((c, v.source_span_s.0..v.source_span_s.1))
        })
        .collect::<Option<_>>()?;
    let ranked = rank_spans_by_effort(g, &spans, want);
    if ranked.len() != all.len() {
        return None;
    }
    let scored: Vec<(usize, f32, Effort)> = ranked
        .iter()
        .map(|&(i, m)| {
            let (c, r) = spans.get(i)?;
            Some((i, m, g.clip_effort_between(*c, r.clone())?))
        })
        .collect::<Option<_>>()?;
    pick(&scored)
}

/// The best-matching (index, match, effort), keeping index 0 (the primary) unless another
/// beats it by [`VARIANT_MARGIN`]; ties to the lower index.
fn pick(scored: &[(usize, f32, Effort)]) -> Option<(usize, f32, Effort)> {
    let best = scored
        .iter()
        .copied()
        .min_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)))?;
    match scored.iter().find(|s| s.0 == 0) {
        Some(&primary) if best.1 < primary.1 + VARIANT_MARGIN => Some(primary),
        _ => Some(best),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::anim::library::sign_variants;
    use crate::anim::variant_effort::clip_rows;
    use crate::graph::lma::MEASUREMENTS;
    use crate::motion::{Clip, Joint, Pose, Skeleton};
    use glam::{Quat, Vec3};
    use std::path::PathBuf;

    /// A small humanoid whose role joints are found by name.
    pub(crate) fn humanoid() -> Skeleton {
        let j = Joint::bare;
        let mut joints = vec![
            j("Hips", None, Vec3::new(0.0, 0.95, 0.0)),
            j("Spine", Some(0), Vec3::new(0.0, 0.25, 0.0)),
            j("Neck", Some(1), Vec3::new(0.0, 0.3, 0.0)),
            j("Head", Some(2), Vec3::new(0.0, 0.15, 0.0)),
        ];
        for (side, x) in [("Left", 1.0f32), ("Right", -1.0)] {
            let n = joints.len();
            joints.extend([
                j(
                    &format!("{side}Arm"),
                    Some(1),
                    Vec3::new(0.0, 0.25, 0.18 * x),
                ),
                j(
                    &format!("{side}ForeArm"),
                    Some(n),
                    Vec3::new(0.0, -0.28, 0.0),
                ),
                j(
                    &format!("{side}Hand"),
                    Some(n + 1),
                    Vec3::new(0.0, -0.25, 0.0),
                ),
                j(
                    &format!("{side}UpLeg"),
                    Some(0),
                    Vec3::new(0.0, -0.05, 0.1 * x),
                ),
                j(
                    &format!("{side}Leg"),
                    Some(n + 3),
                    Vec3::new(0.0, -0.42, 0.0),
                ),
                j(
                    &format!("{side}Foot"),
                    Some(n + 4),
                    Vec3::new(0.0, -0.42, 0.0),
                ),
            ]);
        }
        Skeleton { joints }
    }

    /// `seconds` of arm swings at `hz` with amplitude `amp` (rad); sharp (square-ish) swings
    /// when `snappy`.
    pub(crate) fn swinging(seconds: f32, hz: f32, amp: f32, snappy: bool) -> Clip {
        let sk = humanoid();
        let fps = 30.0;
        let n = (seconds * fps) as usize + 1;
        let arms: Vec<usize> = ["LeftArm", "RightArm", "LeftUpLeg"]
            .iter()
            .filter_map(|a| sk.find(a))
            .collect();
        let frames = (0..n)
            .map(|k| {
                let t = k as f32 / fps;
                let s = (std::f32::consts::TAU * hz * t).sin();
                let s = if snappy { (4.0 * s).tanh() } else { s };
                let mut p = Pose::rest(&sk);
                for (i, &a) in arms.iter().enumerate() {
                    let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                    p.rotations[a] = Quat::from_rotation_z(sign * amp * s);
                }
                p
            })
            .collect();
        Clip {
            name: "swing".into(),
            skeleton: sk,
            frame_time: 1.0 / fps,
            frames,
        }
    }

    fn variant(name: &str, clip: Clip) -> ActionClip {
        ActionClip {
            action: "punch".into(),
            variant: name.into(),
            clip,
            moving: false,
            cyclic: false,
            looping: false,
            anchor: false,
            file: PathBuf::from(format!("{name}.bvh")),
            source_start_s: Some(0.0),
            source_span_s: (0.0, 2.0),
            effort: None,
            alternatives: Vec::new(),
            ranges: None,
            mirrored: None,
        }
    }

    fn punch_with_variants() -> ActionClip {
        let mut v = vec![
            variant("calm", swinging(2.0, 0.4, 0.3, false)),
            variant("mid", swinging(2.0, 1.0, 0.8, false)),
            variant("fierce", swinging(2.0, 2.2, 1.4, true)),
        ];
        sign_variants(&mut v).unwrap();
        let mut it = v.into_iter();
        let mut p = it.next().unwrap();
        p.alternatives = it.collect();
        p
    }

    #[test]
    fn sudden_strong_and_sustained_light_pick_different_variants() {
        let punch = punch_with_variants();
        let e: Vec<Effort> = punch.variants().map(|v| v.effort.unwrap()).collect();
        assert!(
            e[2].time > e[0].time && e[2].weight > e[0].weight,
            "efforts {e:?}"
        );
        let strong = Effort {
            time: 0.8,
            weight: 0.8,
        };
        let light = Effort {
            time: -0.8,
            weight: -0.8,
        };
        let (a, ca) = choose_variant(&punch, strong, None);
        let (b, cb) = choose_variant(&punch, light, None);
        assert_eq!(a.variant, "fierce");
        assert_eq!(b.variant, "calm");
        let (ca, cb) = (ca.unwrap(), cb.unwrap());
        assert!(!ca.by_graph && ca.of == 3 && ca.index == 2);
        assert!(
            ca.effort_match > 0.5 && cb.effort_match > 0.5,
            "{ca:?} {cb:?}"
        );
        // Deterministic: the same answer every time, and from a fresh load.
        let again = punch_with_variants();
        for _ in 0..3 {
            assert_eq!(choose_variant(&again, strong, None).0.variant, "fierce");
            assert_eq!(choose_variant(&again, light, None).0.variant, "calm");
        }
        // Non-finite efforts are neutral, not a panic.
        let nan = Effort {
            time: f32::NAN,
            weight: f32::INFINITY,
        };
        let (_, c) = choose_variant(&punch, nan, None);
        assert!(c.unwrap().effort_match.is_finite());
        // The primary stays unless another variant is clearly better.
        let scored = |m1: f32| {
            let e = Effort::default();
            pick(&[(0, 0.6, e), (1, m1, e), (2, 0.1, e)]).unwrap().0
        };
        assert_eq!(scored(0.6 + VARIANT_MARGIN / 2.0), 0);
        assert_eq!(scored(0.6 + 2.0 * VARIANT_MARGIN), 1);
    }

    #[test]
    fn single_clip_needs_no_choice_and_short_clips_are_measured() {
        let one = variant("only", swinging(2.0, 1.0, 0.5, false));
        let (v, c) = choose_variant(&one, Effort::default(), None);
        assert_eq!(v.variant, "only");
        assert!(c.is_none());
        // 0.5 s: shorter than a 35-frame window, still measured.
        let rows = clip_rows(&swinging(0.5, 2.0, 0.5, false)).unwrap();
        assert!(rows.len() >= MEASUREMENTS && rows.iter().all(|v| v.is_finite()));
        let mut bad = swinging(0.5, 2.0, 0.5, false);
        bad.frames.truncate(1);
        assert!(clip_rows(&bad).is_err());
    }
}
