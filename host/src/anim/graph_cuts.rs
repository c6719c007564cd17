//! Motion-graph transitions for the assembler: the join of the two papers (seed 000's
//! recognised actions and efforts, seed 003's style-coherent motion graph).
//!
//! With a graph (`figurine animate --graph G.bin`), the transition between two consecutive
//! actions is first looked up among the graph's LMA-MG transitions between the two source
//! clips, scored by style similarity plus the match between the incoming action's recognised
//! effort (Lt, Lw) and the destination window's Effort-component estimate
//! ([`MotionGraph::best_cut_between`]). The cut is in source-clip seconds; it is mapped back to
//! output frames through each placed action's output → source time map. When the graph has no
//! transition in the search windows (or a clip is not in the graph, or a clip plays ping-pong
//! so its source time is not monotone), the assembler keeps its windowed posture distance.

use std::ops::RangeInclusive;
use std::path::Path;

use crate::graph::effort::{ClipCut, Effort as GraphEffort};
use crate::graph::graph::Transition;
use crate::graph::{GraphError, MotionGraph, Variant};

/// A loaded motion graph with its LMA-MG transitions, computed once.
#[derive(Debug, Clone)]
pub struct GraphGuide {
    /// The graph.
    pub graph: MotionGraph,
    transitions: Vec<Vec<Transition>>,
}

/// One placed action as the guide sees it: its source clip and output → source time map.
#[derive(Debug, Clone, Copy)]
pub struct PlacedSource<'a> {
    /// The source clip file (as the clip library resolved it), looked up with
    /// [`MotionGraph::clip_index`].
    pub file: &'a Path,
    /// Seconds of the source clip where the action's clip starts (its `frames` range);
    /// `None` when the clip has no monotone map to its source (ping-pong).
    pub source_start_s: Option<f32>,
    /// Output frame of `src_times[0]`.
    pub f0: usize,
    /// Per output frame from `f0`: the action clip's time shown, seconds.
    pub src_times: &'a [f32],
}

/// Largest gap (seconds) between a cut's source time and the nearest output frame's source
/// time for the cut to be used (a graph frame is 1/30 s; effort retiming can skip a little).
pub const MAX_CUT_MISMATCH_S: f32 = 0.1;

impl GraphGuide {
    /// Wraps a graph, computing its LMA-MG transitions (the graph's own thresholds).
    pub fn new(graph: MotionGraph) -> GraphGuide {
        let transitions = graph.transitions(Variant::Lma, None, None);
        GraphGuide { graph, transitions }
    }

    /// Loads a graph file (`figurine graph build … --out G.bin`).
    pub fn load(path: &Path) -> Result<GraphGuide, GraphError> {
        Ok(GraphGuide::new(MotionGraph::load(path)?))
    }

    /// Playable transitions leaving each global frame of the graph.
    pub fn transitions(&self) -> &[Vec<Transition>] {
        &self.transitions
    }

    /// The graph's best cut from `a` (leaving at an output frame in `ra`) to `b` (joining at
    /// an output frame in `rb`) given the incoming action's effort: output frames (i, j) and
    /// the cut. `None` when the graph offers nothing there.
    pub fn cut(
        &self,
        a: &PlacedSource<'_>,
        ra: RangeInclusive<usize>,
        b: &PlacedSource<'_>,
        rb: RangeInclusive<usize>,
        effort: Option<GraphEffort>,
    ) -> Option<(usize, usize, ClipCut)> {
        let ca = self.graph.clip_index(&a.file.to_string_lossy())?;
        let cb = self.graph.clip_index(&b.file.to_string_lossy())?;
        let wa = source_window(a, &ra)?;
        let wb = source_window(b, &rb)?;
        let cut = self.graph.best_cut_between(
            &self.transitions,
            (ca, wa),
            (cb, wb),
            effort,
            Variant::Lma,
        )?;
        let i = output_frame(a, &ra, cut.from_time)?;
        let j = output_frame(b, &rb, cut.to_time)?;
        Some((i, j, cut))
    }
}

/// Source-clip seconds (min..max) shown by the output frames `r` of a placed action.
fn source_window(p: &PlacedSource<'_>, r: &RangeInclusive<usize>) -> Option<std::ops::Range<f32>> {
    let off = p.source_start_s?;
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for f in r.clone() {
        let t = *p.src_times.get(f.checked_sub(p.f0)?)?;
        lo = lo.min(t + off);
        hi = hi.max(t + off);
    }
    (lo.is_finite() && hi.is_finite()).then_some(lo..hi)
}

/// The output frame in `r` whose source time is nearest `t` (source-clip seconds), if within
/// [`MAX_CUT_MISMATCH_S`] (cyclic actions show a source time once per cycle; only `r` counts).
fn output_frame(p: &PlacedSource<'_>, r: &RangeInclusive<usize>, t: f32) -> Option<usize> {
    let off = p.source_start_s?;
    let (f, d) = r
        .clone()
        .filter_map(|f| Some((f, (p.src_times.get(f.checked_sub(p.f0)?)? + off - t).abs())))
        .min_by(|x, y| x.1.total_cmp(&y.1))?;
    (d <= MAX_CUT_MISMATCH_S).then_some(f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn source_times_map_both_ways() {
        let times: Vec<f32> = (0..20).map(|k| 0.5 + k as f32 * 0.05).collect();
        let p = PlacedSource {
            file: Path::new("x.bvh"),
            source_start_s: Some(1.0),
            f0: 100,
            src_times: &times,
        };
        let w = source_window(&p, &(105..=110)).unwrap();
        assert!(
            (w.start - 1.75).abs() < 1e-5 && (w.end - 2.0).abs() < 1e-5,
            "{w:?}"
        );
        assert_eq!(output_frame(&p, &(105..=110), 1.86), Some(107));
        assert_eq!(output_frame(&p, &(105..=110), 2.5), None);
        assert!(source_window(&p, &(95..=101)).is_none());
        let pp = PlacedSource {
            source_start_s: None,
            ..p
        };
        assert!(source_window(&pp, &(105..=110)).is_none());
    }
}
