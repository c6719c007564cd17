//! Evaluation (seed 003 §5.2–5.3): label-switching cost of synthesised walks on MG vs LMA-MG.
//!
//! Labels are given per source clip in a JSON object `{"clip name": "label", …}` (clip names
//! are file stems; a key may also be the clip's path). The cost of a transition between labels
//! is Table 3's Euclidean distance on Russell's circumplex when both labels are among its
//! emotions (afraid, angry, excited, happy, relaxed, bored), else 0 for equal labels and 1 for
//! different ones. Table 3 is used as printed (row = from, column = to; it is not symmetric for
//! angry/happy). For each variant, `runs` walks of `transitions` transitions each are planned
//! with synthesis by highest similarity (§5.3) — both variants starting each run from the same
//! frame of their common component — and the mean cost C = (1/k) Σ cost(s_i, s_j),
//! its standard deviation over runs, and the share of transitions crossing labels are reported,
//! with the transition counts of both graphs (before / after LMA pruning).

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use super::graph::{MotionGraph, Variant};
use super::synth::{plan, Chooser, Rng, MAX_SEGMENT};
use super::GraphError;

/// Emotions of Table 3, in its row / column order.
pub const EMOTIONS: [&str; 6] = ["afraid", "angry", "excited", "happy", "relaxed", "bored"];

/// Table 3: Euclidean distances between emotions on Russell's circumplex (diameter 1).
pub const EMOTION_DISTANCES: [[f32; 6]; 6] = [
    [0.0, 0.08, 0.36, 0.44, 0.68, 0.45],
    [0.08, 0.0, 0.43, 0.07, 0.69, 0.39],
    [0.36, 0.43, 0.0, 0.13, 0.58, 0.67],
    [0.44, 0.51, 0.13, 0.0, 0.48, 0.67],
    [0.68, 0.69, 0.58, 0.48, 0.0, 0.54],
    [0.45, 0.39, 0.67, 0.67, 0.54, 0.0],
];

/// Cost of switching from label `a` to label `b`.
pub fn label_cost(a: &str, b: &str) -> f32 {
    let ix = |s: &str| EMOTIONS.iter().position(|e| e.eq_ignore_ascii_case(s));
    match (ix(a), ix(b)) {
        (Some(i), Some(j)) => EMOTION_DISTANCES[i][j],
        _ => {
            if a == b {
                0.0
            } else {
                1.0
            }
        }
    }
}

/// Reads a labels file and returns the label of every clip of `g` (by index).
pub fn read_labels(path: &Path, g: &MotionGraph) -> Result<Vec<String>, GraphError> {
    let text = std::fs::read_to_string(path).map_err(|source| GraphError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let map: BTreeMap<String, String> = serde_json::from_str(&text)
        .map_err(|e| GraphError::format(path, format!("labels: {e}")))?;
    let mut out = Vec::with_capacity(g.clips.len());
    let mut missing = Vec::new();
    for c in &g.clips {
        match map.get(&c.name).or_else(|| map.get(&c.path)) {
            Some(l) => out.push(l.clone()),
            None => missing.push(c.name.clone()),
        }
    }
    if !missing.is_empty() {
        return Err(GraphError::format(
            path,
            format!("no label for clip(s): {}", missing.join(", ")),
        ));
    }
    Ok(out)
}

/// Figures of one variant.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VariantReport {
    /// Transitions in the graph (pairs, both directions counted once).
    pub transitions: usize,
    /// Frames in the largest strongly connected component.
    pub component_frames: usize,
    /// Mean label cost per transition over all runs.
    pub mean_cost: f32,
    /// Standard deviation of the per-run mean cost.
    pub cost_std: f32,
    /// Share of transitions whose source and destination labels differ.
    pub crossing_share: f32,
    /// Transitions taken over all runs.
    pub taken: usize,
    /// Share of taken transitions landing in each destination label.
    pub destinations: BTreeMap<String, f32>,
}

/// The evaluation of a graph.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EvalReport {
    /// The plain motion graph.
    pub mg: VariantReport,
    /// The LMA-pruned motion graph.
    pub lma: VariantReport,
    /// Share of MG transitions removed by LMA pruning.
    pub pruned_share: f32,
}

/// Runs the §5.3 evaluation: `runs` walks of `transitions` transitions per variant.
pub fn evaluate(
    g: &MotionGraph,
    labels: &[String],
    runs: usize,
    transitions: usize,
    seed: u64,
) -> Result<EvalReport, GraphError> {
    // Both graphs start each run from the same frame (§5.3), drawn from their common part.
    let scc_mg = g.largest_scc(&g.transitions(Variant::Mg, None, None));
    let scc_lma = g.largest_scc(&g.transitions(Variant::Lma, None, None));
    let common: Vec<u32> = (0..scc_mg.len() as u32)
        .filter(|&f| scc_mg[f as usize] && scc_lma.get(f as usize).copied().unwrap_or(false))
        .collect();
    let start_of = |r: usize| -> Option<u32> {
        if common.is_empty() {
            return None;
        }
        let mut rng = Rng::new(seed.wrapping_mul(31).wrapping_add(r as u64));
        Some(common[rng.range(0, common.len() - 1)])
    };
    let one = |v: Variant| -> Result<VariantReport, GraphError> {
        let trans = g.transitions(v, None, None);
        let component_frames = g.largest_scc(&trans).iter().filter(|&&b| b).count();
        let mut per_run = Vec::new();
        let (mut crossing, mut taken) = (0usize, 0usize);
        let mut dest: BTreeMap<String, usize> = BTreeMap::new();
        for r in 0..runs.max(1) {
            let mut rng = Rng::new(seed.wrapping_add(r as u64));
            let frames = transitions * MAX_SEGMENT + 1;
            let p = plan(g, v, &Chooser::Similarity(v), frames, start_of(r), &mut rng)?;
            let mut sum = 0.0f32;
            for (_, t) in p.cuts.iter().take(transitions) {
                let (Some(a), Some(b)) = (g.clip_of(t.from), g.clip_of(t.to)) else {
                    continue;
                };
                let (la, lb) = (&labels[a], &labels[b]);
                sum += label_cost(la, lb);
                crossing += usize::from(la != lb);
                *dest.entry(lb.clone()).or_default() += 1;
                taken += 1;
            }
            let k = p.cuts.len().min(transitions);
            per_run.push(if k > 0 { sum / k as f32 } else { 0.0 });
        }
        let mean = per_run.iter().sum::<f32>() / per_run.len() as f32;
        let var = per_run.iter().map(|c| (c - mean).powi(2)).sum::<f32>() / per_run.len() as f32;
        let share = |n: usize| {
            if taken > 0 {
                n as f32 / taken as f32
            } else {
                0.0
            }
        };
        Ok(VariantReport {
            transitions: g.count(v, None, None),
            component_frames,
            mean_cost: mean,
            cost_std: var.sqrt(),
            crossing_share: share(crossing),
            taken,
            destinations: dest.into_iter().map(|(k, n)| (k, share(n))).collect(),
        })
    };
    let mg = one(Variant::Mg)?;
    let lma = one(Variant::Lma)?;
    let pruned_share = if mg.transitions > 0 {
        1.0 - lma.transitions as f32 / mg.transitions as f32
    } else {
        0.0
    };
    Ok(EvalReport {
        mg,
        lma,
        pruned_share,
    })
}

impl std::fmt::Display for EvalReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "{:<8} {:>11} {:>10} {:>10} {:>9} {:>9} {:>7}",
            "graph", "transitions", "component", "mean cost", "cost std", "crossing", "taken"
        )?;
        for (name, r) in [("MG", &self.mg), ("LMA-MG", &self.lma)] {
            writeln!(
                f,
                "{name:<8} {:>11} {:>10} {:>10.3} {:>9.4} {:>8.1}% {:>7}",
                r.transitions,
                r.component_frames,
                r.mean_cost,
                r.cost_std,
                100.0 * r.crossing_share,
                r.taken
            )?;
        }
        writeln!(
            f,
            "LMA pruning removed {:.1}% of the MG transitions",
            100.0 * self.pruned_share
        )?;
        for (name, r) in [("MG", &self.mg), ("LMA-MG", &self.lma)] {
            let d: Vec<String> = r
                .destinations
                .iter()
                .map(|(k, v)| format!("{k} {:.0}%", 100.0 * v))
                .collect();
            writeln!(f, "{name} destinations: {}", d.join(", "))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::graph::tests::toy_graph;
    use crate::graph::Edge;

    #[test]
    fn table3_and_fallback_costs() {
        assert_eq!(label_cost("happy", "relaxed"), 0.48);
        assert_eq!(label_cost("Happy", "happy"), 0.0);
        assert_eq!(label_cost("walk", "walk"), 0.0);
        assert_eq!(label_cost("walk", "run"), 1.0);
    }

    #[test]
    fn pruning_cross_label_edges_lowers_the_cost() {
        // Clips 0,1 are "happy", 2,3 "angry". Same-label links have high style, cross-label
        // links high posture but low style.
        let e = |from, to, posture, style| Edge {
            from,
            to,
            posture,
            style,
        };
        let edges = vec![
            // Crosswise pairs make cycles 51..150 → 351..450 → 51 (and the same for 2/3).
            e(50, 450, 0.93, 0.9),
            e(150, 350, 0.93, 0.9),
            e(650, 1050, 0.93, 0.9),
            e(750, 950, 0.93, 0.9),
            e(140, 1040, 0.99, 0.2),
            e(440, 740, 0.99, 0.2),
        ];
        let g = toy_graph(edges, &[300, 300, 300, 300]);
        let labels: Vec<String> = ["happy", "happy", "angry", "angry"]
            .map(String::from)
            .to_vec();
        let r = evaluate(&g, &labels, 2, 50, 3).unwrap();
        assert_eq!(r.mg.transitions, 6);
        assert_eq!(r.lma.transitions, 4);
        assert!(r.lma.mean_cost < r.mg.mean_cost, "{r}");
        assert_eq!(r.lma.crossing_share, 0.0);
        assert!(r.mg.crossing_share > 0.0);
        assert!((r.pruned_share - 1.0 / 3.0).abs() < 1e-6);
    }

    #[test]
    fn missing_labels_are_named() {
        let g = toy_graph(vec![], &[100, 100]);
        let dir = std::env::temp_dir().join(format!("figurine-eval-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("l.json");
        std::fs::write(&p, r#"{"c0": "happy"}"#).unwrap();
        let err = read_labels(&p, &g).unwrap_err().to_string();
        assert!(err.contains("c1") && err.contains("l.json"), "{err}");
        std::fs::write(&p, r#"{"c0": "happy", "c1": "sad"}"#).unwrap();
        assert_eq!(read_labels(&p, &g).unwrap(), vec!["happy", "sad"]);
        std::fs::write(&p, "[1,").unwrap();
        assert!(read_labels(&p, &g).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
