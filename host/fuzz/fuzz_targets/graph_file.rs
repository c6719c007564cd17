//! Fuzzes the motion-graph file reader (G.bin, `figurine graph build --out`), which `graph
//! synth`, `graph eval` and `animate --graph` open: a graph or an error naming the file, never
//! a panic or a runaway allocation. An accepted graph is used as those commands use it: its
//! transitions and their largest strongly connected component in both variants, the effort
//! and style of its windows, the cut between every two clips, and a planned walk.
#![no_main]

use std::path::Path;

use figurine_host::graph::synth::{plan, Chooser, Rng};
use figurine_host::graph::{MotionGraph, Variant};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("G.bin");
    let g = match MotionGraph::from_bytes(data, path) {
        Ok(g) => g,
        Err(e) => {
            assert!(e.to_string().contains("G.bin"), "{e}");
            return;
        }
    };
    for v in [Variant::Mg, Variant::Lma] {
        let trans = g.transitions(v, None, None);
        let _ = g.largest_scc(&trans);
        let _ = g.count(v, None, None);
        for a in 0..g.clips.len().min(4) {
            let _ = g.clip_effort(a);
            for b in 0..g.clips.len().min(4) {
                let _ = g.best_cut_between(&trans, (a, 0.0..1e3), (b, 0.0..1e3), None, v);
            }
        }
        let _ = plan(&g, v, &Chooser::Similarity(v), 90, None, &mut Rng::new(7));
    }
    for f in 0..g.frames().min(256) as u32 {
        let _ = g.effort_at(f);
        let _ = g.same_rig(f, 0);
    }
    let _ = g.standardiser.style_vectors(&g.measurements);
});
