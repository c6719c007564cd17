//! `figurine animate --graph`: transitions between actions taken from a motion graph built
//! from the default library's DeepMimic clips, chosen by the incoming action's effort.

use std::path::PathBuf;

use figurine_host::anim::assemble::{assemble, assemble_guided, AssembleOptions, Assembly};
use figurine_host::anim::graph_cuts::GraphGuide;
use figurine_host::anim::library::ClipLibrary;
use figurine_host::data::data_dir;
use figurine_host::events::ActionRecord;
use figurine_host::graph::roles::RoleOverrides;
use figurine_host::graph::source::load_clips;
use figurine_host::graph::{build_graph, BuildParams};

/// The graph over every DeepMimic clip, with loose thresholds so the few clips offer
/// alternatives (the paper's 0.9 / 0.8 leave 5 LMA-MG transitions on 989 frames).
fn guide() -> Option<GraphGuide> {
    let d = data_dir().join("deepmimic");
    if !d.join("humanoid.urdf").is_file() {
        eprintln!("skipping: DeepMimic data not found; run `cargo xtask setup`");
        return None;
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(&d)
        .unwrap()
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "txt"))
        .collect();
    files.sort();
    let clips = load_clips(&files, &RoleOverrides::new()).unwrap();
    let params = BuildParams {
        t_mg: 0.6,
        t_lma: 0.3,
        ..BuildParams::default()
    };
    let (g, _) = build_graph(&clips, &params).unwrap();
    Some(GraphGuide::new(g))
}

fn ev(action: &str, start: f64, end: f64, e: f64) -> ActionRecord {
    ActionRecord {
        action: action.into(),
        start,
        end,
        time: e,
        weight: e,
        distance: 0,
    }
}

fn story(e: f64) -> Vec<ActionRecord> {
    vec![
        ev("walk", 0.0, 3.0, 0.0),
        ev("punch", 3.0, 5.0, e),
        ev("kick", 5.0, 7.0, e),
        ev("walk", 7.0, 10.0, e),
    ]
}

fn run(events: &[ActionRecord], g: Option<&GraphGuide>) -> Assembly {
    let lib = ClipLibrary::default_library().unwrap();
    let names: Vec<&str> = events.iter().map(|e| e.action.as_str()).collect();
    let clips = lib.load(names).unwrap();
    let opts = AssembleOptions::default();
    match g {
        Some(g) => assemble_guided(events, None, &clips, lib.forward(), &opts, Some(g)),
        None => assemble(events, None, &clips, lib.forward(), &opts),
    }
    .unwrap()
}

/// Largest per-frame displacement of any joint, metres.
fn max_step(a: &Assembly) -> f32 {
    let pos = a.clip.all_positions();
    pos.windows(2)
        .flat_map(|w| w[0].iter().zip(&w[1]).map(|(a, b)| a.distance(*b)))
        .fold(0.0, f32::max)
}

#[test]
fn graph_transitions_follow_the_graph_and_the_effort() {
    let Some(g) = guide() else { return };
    let events = story(0.8);
    let plain = run(&events, None);
    let guided = run(&events, Some(&g));
    // Same placements and length; a valid, continuous animation.
    assert_eq!(guided.clip.len(), plain.clip.len());
    assert_eq!(guided.transitions.len(), 3);
    assert_eq!(guided.graph_cuts.len(), 3);
    assert!(plain.graph_cuts.iter().all(Option::is_none));
    assert!(guided
        .clip
        .frames
        .iter()
        .all(|p| p.translations.iter().all(|t| t.is_finite())));
    // Graph cuts add no pop beyond what the posture path has (the no-graph assembly of this
    // story already has one 1.58 m step, outside the transitions).
    assert!(max_step(&guided) <= max_step(&plain) + 0.05);
    // Where the graph chose a cut, the transition frames are the graph's, not posture's.
    let used: Vec<usize> = (0..3).filter(|&k| guided.graph_cuts[k].is_some()).collect();
    assert!(
        !used.is_empty(),
        "the graph offered no transition: {:?}",
        guided.transitions
    );
    for &k in &used {
        assert_ne!(guided.transitions[k], plain.transitions[k], "boundary {k}");
        let c = guided.graph_cuts[k].unwrap();
        assert!(c.effort_match > 0.0 && c.style > 0.0, "{c:?}");
    }
    // Sustained/light efforts instead of sudden/strong: another cut or another match.
    let soft = run(&story(-0.8), Some(&g));
    let key = |a: &Assembly| {
        a.graph_cuts
            .iter()
            .map(|c| c.map(|c| (c.from_time, c.to_time, c.effort_match)))
            .collect::<Vec<_>>()
    };
    assert_ne!(key(&soft), key(&guided));
    assert!(soft.graph_cuts.iter().any(Option::is_some));
}

#[test]
fn effort_changes_the_chosen_cut_where_the_graph_offers_alternatives() {
    let Some(g) = guide() else { return };
    use figurine_host::graph::effort::Effort;
    let n = g.graph.clips.len();
    let secs = |c: usize| g.graph.clips[c].frames as f32 / figurine_host::graph::FPS;
    let (mut pairs, mut changed) = (0, 0);
    for a in 0..n {
        for b in 0..n {
            let cut = |e: f32| {
                g.graph.best_cut_between(
                    g.transitions(),
                    (a, 0.0..secs(a)),
                    (b, 0.0..secs(b)),
                    Some(Effort { time: e, weight: e }),
                    figurine_host::graph::Variant::Lma,
                )
            };
            let (Some(s), Some(l)) = (cut(1.0), cut(-1.0)) else {
                continue;
            };
            pairs += 1;
            if (s.from_time, s.to_time) != (l.from_time, l.to_time) {
                changed += 1;
                // Each effort's pick matches its own effort better than the other's pick.
                let g = &g.graph;
                let at = |c: &figurine_host::graph::effort::ClipCut| {
                    let f =
                        g.clips[b].start + (c.to_time * figurine_host::graph::FPS).round() as u32;
                    g.effort_at(f).unwrap()
                };
                let (es, el) = (at(&s), at(&l));
                assert!(es.time + es.weight >= el.time + el.weight, "{es:?} {el:?}");
            }
        }
    }
    eprintln!("{pairs} clip pairs with transitions, {changed} change with the effort");
    assert!(pairs > 0);
    assert!(
        changed > 0,
        "effort never changed a cut among {pairs} pairs"
    );
}
