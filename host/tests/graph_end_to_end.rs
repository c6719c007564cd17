//! End to end: `figurine graph build | synth | eval` on the real DeepMimic clips, the output BVH
//! re-imported and checked for continuity (no pops at transitions).

mod common;

use std::path::{Path, PathBuf};

use common::{deepmimic_dir, figurine};
use figurine_host::graph::source::load_clip;
use figurine_host::motion::read_bvh_path;

/// Largest per-frame displacement of any joint, in the clip's unit.
fn max_step(clip: &figurine_host::motion::Clip) -> f32 {
    let pos = clip.all_positions();
    pos.windows(2)
        .flat_map(|w| w[0].iter().zip(&w[1]).map(|(a, b)| a.distance(*b)))
        .fold(0.0, f32::max)
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("figurine-graph-e2e-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn build_synth_export_reimport_and_eval() {
    let Some(dm) = deepmimic_dir() else { return };
    let dir = tmp("main");
    let g = dir.join("g.bin");
    let (ok, out, err) = figurine(&[
        "graph",
        "build",
        dm.to_str().unwrap(),
        "--out",
        g.to_str().unwrap(),
        "--t-mg",
        "0.85",
        "--t-lma",
        "0.7",
        "--quiet",
    ]);
    assert!(ok, "{out}\n{err}");
    assert!(
        err.contains("shorter than one 35-frame window"),
        "run.txt is 25 frames: {err}"
    );
    assert!(out.contains("transitions: MG"), "{out}");

    let bvh = dir.join("walk.bvh");
    let (ok, out, err) = figurine(&[
        "graph",
        "synth",
        g.to_str().unwrap(),
        "--seconds",
        "12",
        "--out",
        bvh.to_str().unwrap(),
        "--glb",
        dir.join("walk.glb").to_str().unwrap(),
    ]);
    assert!(ok, "{out}\n{err}");
    let back = read_bvh_path(&bvh).unwrap().clip;
    assert_eq!(back.len(), 360);
    assert!((back.frame_time - 1.0 / 30.0).abs() < 1e-5);
    // Continuity: no frame step larger than the sources' own fastest step (plus blend slack).
    let sources: Vec<_> = [
        "walk", "dance_a", "dance_b", "jump", "kick", "punch", "spin", "crawl",
    ]
    .iter()
    .filter_map(|n| load_clip(&dm.join(format!("humanoid3d_{n}.txt")), &Default::default()).ok())
    .collect();
    let source_step = sources
        .iter()
        .map(|c| max_step(&c.clip))
        .fold(0.0, f32::max);
    let step = max_step(&back);
    assert!(
        step <= 1.5 * source_step + 0.05,
        "pop: {step} m vs sources {source_step} m"
    );
    assert!(Path::new(&dir.join("walk.glb")).is_file());

    // By example: follow the dance.
    let ex = dir.join("example.bvh");
    let (ok, out, err) = figurine(&[
        "graph",
        "synth",
        g.to_str().unwrap(),
        "--out",
        ex.to_str().unwrap(),
        "--example",
        dm.join("humanoid3d_dance_b.txt").to_str().unwrap(),
        "--variant",
        "mg",
    ]);
    assert!(ok, "{out}\n{err}");
    let dance_b = load_clip(&dm.join("humanoid3d_dance_b.txt"), &Default::default()).unwrap();
    assert_eq!(read_bvh_path(&ex).unwrap().clip.len(), dance_b.len());

    // Evaluation with labels per clip.
    let labels = dir.join("labels.json");
    std::fs::write(
        &labels,
        r#"{"backflip":"acrobatic","cartwheel":"acrobatic","crawl":"floor","dance_a":"dance",
            "dance_b":"dance","getup_facedown":"floor","getup_faceup":"floor","jump":"acrobatic",
            "kick":"fight","punch":"fight","roll":"floor","spin":"dance","spinkick":"fight",
            "walk":"locomotion"}"#,
    )
    .unwrap();
    let (ok, out, err) = figurine(&[
        "graph",
        "eval",
        g.to_str().unwrap(),
        "--labels",
        labels.to_str().unwrap(),
        "--transitions",
        "50",
    ]);
    assert!(ok, "{out}\n{err}");
    assert!(
        out.contains("LMA-MG") && out.contains("pruning removed"),
        "{out}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_inputs_are_refused_with_the_file_named() {
    let dir = tmp("bad");
    let broken = dir.join("broken.bvh");
    std::fs::write(&broken, "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n").unwrap();
    let (ok, _, err) = figurine(&[
        "graph",
        "build",
        broken.to_str().unwrap(),
        "--out",
        dir.join("g.bin").to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("broken.bvh"), "{err}");

    let not_graph = dir.join("nope.bin");
    std::fs::write(&not_graph, b"hello").unwrap();
    let (ok, _, err) = figurine(&[
        "graph",
        "synth",
        not_graph.to_str().unwrap(),
        "--out",
        dir.join("o.bvh").to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("nope.bin"), "{err}");

    let (ok, _, err) = figurine(&[
        "graph",
        "build",
        broken.to_str().unwrap(),
        "--out",
        "x.bin",
        "--weights",
        "1,2",
    ]);
    assert!(!ok && err.contains("four"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
