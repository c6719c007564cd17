//! Torso tilt per kind of action (issue 29: "torso tilt within the reference's range for that
//! kind of action; a backflip may flip").
//!
//! The reference of an action is every real take of its kind the project holds: each clip a
//! shipped library plays for it, cut as it is played (all its variants: the default
//! library's, and LAFAN1's gait cycles and dance stretches in `host/assets/lafan_clips.json`),
//! and each span of a real take labelled with it by hand (`host/assets/real_takes.json`). Its
//! range is the lowest to the highest tilt figure ([`TiltFigures`]: 95th percentile, max)
//! among those takes, widened by [`TILT_MARGIN_DEG`] either side: how far real takes of one
//! kind differ at different vigour, measured ([`vigour_spread`]). One rule for every action;
//! an assembled animation is judged placement by placement, over the frames each action
//! plays alone ([`TiltReference::judge`]).

use std::collections::BTreeMap;

use anyhow::Result;

use super::assemble::Assembly;
use super::envelope::TILT_MARGIN_DEG;
use super::library::ClipLibrary;
use super::torso_tilt::{tilt_series, TiltFigures};
use crate::motion::read_take;

/// LAFAN1's library (walks and dances of different vigour), shipped beside the default one.
pub const LAFAN_LIBRARY: &str = include_str!("../../assets/lafan_clips.json");

/// One real take of a kind of action.
#[derive(Debug, Clone, PartialEq)]
pub struct TakeTilt {
    /// Where it comes from (`library variant` or `file span`).
    pub source: String,
    /// Its tilt.
    pub figures: TiltFigures,
}

/// The range an action's torso tilt must stay within, °: each of p95 and max within
/// `[lo, hi]`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TiltBounds {
    /// Lowest and highest 95th percentile.
    pub p95: (f32, f32),
    /// Lowest and highest maximum.
    pub max: (f32, f32),
}

impl TiltBounds {
    /// Whether `f` lies within both ranges.
    pub fn holds(&self, f: TiltFigures) -> bool {
        let within = |x: f32, (lo, hi): (f32, f32)| x >= lo && x <= hi;
        within(f.p95, self.p95) && within(f.max, self.max)
    }
}

/// One placement of an assembled animation, its tilt judged against its kind's reference.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TiltJudgement {
    /// The action.
    pub action: String,
    /// Its tilt over the frames it plays alone.
    pub figures: TiltFigures,
    /// Its kind's range (`None`: the reference holds no take of that kind, not judged).
    pub bounds: Option<TiltBounds>,
    /// Played whole, alone in its animation: judged on both sides of the range. Blended into
    /// a neighbour, an action may be cut short of its deepest or its most upright poses (a
    /// sudden turn handing over to a spin before its own deepest lean), so only the top of
    /// the range is judged: no pose of it leans further than its kind's takes.
    pub whole: bool,
}

impl TiltJudgement {
    /// Within its kind's range (or not judged): both sides for an action played whole, the
    /// top for one blended into its neighbours.
    pub fn holds(&self) -> bool {
        self.bounds.is_none_or(|b| {
            let f = self.figures;
            if self.whole {
                b.holds(f)
            } else {
                f.p95 <= b.p95.1 && f.max <= b.max.1
            }
        })
    }
}

/// The real takes of every kind of action, and the margin their range is widened by.
#[derive(Debug, Clone)]
pub struct TiltReference {
    /// Action → the takes of its kind.
    pub kinds: BTreeMap<String, Vec<TakeTilt>>,
    /// Degrees each range is widened by either side ([`TILT_MARGIN_DEG`]).
    pub margin_deg: f32,
}

/// The clips `library` plays for each of its actions (every variant, as cut), their tilt.
fn library_takes(library: &ClipLibrary, kinds: &mut BTreeMap<String, Vec<TakeTilt>>) -> Result<()> {
    let actions: Vec<&str> = library.actions.keys().map(String::as_str).collect();
    let loaded = library.load(actions)?;
    for (action, ac) in &loaded {
        for v in ac.variants() {
            let series = tilt_series(&v.clip, &v.variant)?;
            kinds.entry(action.clone()).or_default().push(TakeTilt {
                source: format!("{} {}", library_label(library), v.variant),
                figures: TiltFigures::of(&series),
            });
        }
    }
    Ok(())
}

fn library_label(library: &ClipLibrary) -> &'static str {
    if library.origin.contains("lafan") {
        "lafan"
    } else {
        "default"
    }
}

/// The hand-labelled spans of real takes (`host/assets/real_takes.json`), their tilt.
fn labelled_takes(kinds: &mut BTreeMap<String, Vec<TakeTilt>>) -> Result<()> {
    for take in crate::recognize::real_bench::real_takes()? {
        let Some((kind, file)) = take.take.split_once('/') else {
            continue;
        };
        let path = crate::data::require_data_file(kind, file)?;
        let clip = read_take(&path, None)?;
        let series = tilt_series(&clip, &take.take)?;
        let frame = |t: f64| (t / f64::from(clip.frame_time.max(1e-6))).round() as usize;
        for label in &take.actions {
            let (a, b) = label
                .span
                .or(take.start.zip(take.end))
                .map_or((0, series.len()), |(s, e)| (frame(s), frame(e) + 1));
            let span = series
                .get(a.min(series.len())..b.min(series.len()))
                .unwrap_or(&[]);
            if span.is_empty() {
                continue;
            }
            let figures = TiltFigures::of(span);
            let takes = kinds.entry(label.action.clone()).or_default();
            // A whole take a library already plays for the action is one take, not two.
            if takes.iter().any(|t| t.figures == figures) {
                continue;
            }
            takes.push(TakeTilt {
                source: match label.span {
                    Some((s, e)) => format!("{} {s}-{e} s", take.take),
                    None => take.take.clone(),
                },
                figures,
            });
        }
    }
    Ok(())
}

/// How far real takes of one kind differ at different vigour (°): among the variants the
/// LAFAN1 library cuts from one performer's take for one action at different vigour (a
/// stroll, a walk and a stride; a calm, a median and a wild dance), the largest spread
/// (highest less lowest) of either figure.
pub fn vigour_spread(kinds: &BTreeMap<String, Vec<TakeTilt>>) -> f32 {
    kinds
        .values()
        .map(|takes| {
            let lafan: Vec<TiltFigures> = takes
                .iter()
                .filter(|t| t.source.starts_with("lafan "))
                .map(|t| t.figures)
                .collect();
            let spread = |f: fn(&TiltFigures) -> f32| {
                let lo = lafan.iter().map(f).fold(f32::INFINITY, f32::min);
                let hi = lafan.iter().map(f).fold(f32::NEG_INFINITY, f32::max);
                if lafan.len() >= 2 {
                    hi - lo
                } else {
                    0.0
                }
            };
            spread(|f| f.p95).max(spread(|f| f.max))
        })
        .fold(0.0, f32::max)
}

impl TiltReference {
    /// The reference of `library`'s actions: its clips, LAFAN1's library's and the labelled
    /// real takes (all fetched by `cargo xtask setup`).
    pub fn of_library(library: &ClipLibrary) -> Result<TiltReference> {
        let mut kinds = BTreeMap::new();
        library_takes(library, &mut kinds)?;
        let lafan = ClipLibrary::parse(
            LAFAN_LIBRARY,
            std::path::Path::new("lafan clip library"),
            None,
        )?;
        library_takes(&lafan, &mut kinds)?;
        labelled_takes(&mut kinds)?;
        Ok(TiltReference {
            kinds,
            margin_deg: TILT_MARGIN_DEG,
        })
    }

    /// The range `action`'s tilt must stay within (`None` without a take of its kind).
    pub fn bounds(&self, action: &str) -> Option<TiltBounds> {
        let takes = self.kinds.get(action).filter(|t| !t.is_empty())?;
        let m = self.margin_deg;
        let range = |f: fn(&TiltFigures) -> f32| {
            let lo = takes
                .iter()
                .map(|t| f(&t.figures))
                .fold(f32::INFINITY, f32::min);
            let hi = takes
                .iter()
                .map(|t| f(&t.figures))
                .fold(f32::NEG_INFINITY, f32::max);
            ((lo - m).max(0.0), (hi + m).min(180.0))
        };
        Some(TiltBounds {
            p95: range(|f| f.p95),
            max: range(|f| f.max),
        })
    }

    /// Judges every placement of `asm`: its figures over the frames it plays alone (its own
    /// frames but those of a blend into or out of it) against its kind's range. Held frames
    /// outside every placement repeat an action's first or last pose, and a blend's frames mix
    /// two judged poses: a short turn blended into a wave leans between the two, and counting
    /// those frames, or a lead-in standing still, would dilute its 95th percentile. A
    /// placement blended throughout is judged over all its frames. An action alone in its
    /// animation is judged on both sides of the range, one among others on its top
    /// ([`TiltJudgement::whole`]).
    pub fn judge(&self, asm: &Assembly) -> Result<Vec<TiltJudgement>> {
        let series = tilt_series(&asm.clip, "assembled animation")?;
        let blended = |f: usize| asm.transitions.iter().any(|&(i, j)| f > i && f < j);
        Ok(asm
            .placements
            .iter()
            .map(|p| {
                let all: Vec<f32> = (p.start_frame..=p.end_frame)
                    .filter_map(|f| series.get(f).copied())
                    .collect();
                let alone: Vec<f32> = (p.start_frame..=p.end_frame)
                    .filter(|&f| !blended(f))
                    .filter_map(|f| series.get(f).copied())
                    .collect();
                TiltJudgement {
                    action: p.action.clone(),
                    figures: TiltFigures::of(if alone.is_empty() { &all } else { &alone }),
                    bounds: self.bounds(&p.action),
                    whole: asm.placements.len() == 1,
                }
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn take(source: &str, p95: f32, max: f32) -> TakeTilt {
        TakeTilt {
            source: source.into(),
            figures: TiltFigures { p95, max },
        }
    }

    #[test]
    fn a_kinds_range_spans_its_takes_widened_by_the_margin() {
        let mut kinds = BTreeMap::new();
        kinds.insert(
            "walk".to_string(),
            vec![
                take("default walk", 6.0, 7.0),
                take("lafan stroll", 4.0, 6.0),
                take("lafan stride", 9.0, 10.0),
            ],
        );
        kinds.insert(
            "wave".to_string(),
            vec![
                take("lafan sway", 10.0, 20.0),
                take("lafan wild", 30.0, 32.0),
            ],
        );
        // The spread among one performer's takes of one kind: the dance's max, 32 − 20.
        let margin_deg = vigour_spread(&kinds);
        assert_eq!(margin_deg, 20.0);
        let r = TiltReference { kinds, margin_deg };
        let b = r.bounds("walk").unwrap();
        assert_eq!(b.p95, (0.0, 29.0));
        assert_eq!(b.max, (0.0, 30.0));
        assert!(b.holds(TiltFigures {
            p95: 29.0,
            max: 30.0
        }));
        assert!(!b.holds(TiltFigures {
            p95: 29.5,
            max: 30.0
        }));
        assert!(r.bounds("punch").is_none());
    }

    #[test]
    fn an_action_played_whole_is_judged_on_both_sides_one_blended_on_the_top() {
        let bounds = Some(TiltBounds {
            p95: (40.0, 60.0),
            max: (45.0, 65.0),
        });
        let judged = |p95: f32, max: f32, whole: bool| {
            TiltJudgement {
                action: "bow".into(),
                figures: TiltFigures { p95, max },
                bounds,
                whole,
            }
            .holds()
        };
        assert!(judged(50.0, 55.0, true) && judged(50.0, 55.0, false));
        // Too shallow a bow: out when played whole, not when a blend may have cut it short.
        assert!(!judged(30.0, 44.0, true) && judged(30.0, 44.0, false));
        // Leaning further than any take: out either way.
        assert!(!judged(61.0, 64.0, true) && !judged(50.0, 66.0, false));
    }
}
