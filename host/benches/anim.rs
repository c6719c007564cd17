//! Animation benchmarks: BVH import of a long capture, assembly of a synthetic doodle, and the
//! exports. Run with `cargo bench -p figurine-host --bench anim` (data from `cargo xtask setup`).

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use figurine_host::anim::assemble::{assemble, AssembleOptions};
use figurine_host::anim::cli::read_label_events;
use figurine_host::anim::library::ClipLibrary;
use figurine_host::motion::{read_bvh_path, write_bvh_string, write_glb_bytes};

fn benches(c: &mut Criterion) {
    if let Some(p) = figurine_host::data::data_file("bvh", "lafan_test.bvh") {
        c.bench_function("bvh import lafan_test (7184 frames, 22 joints)", |b| {
            b.iter(|| black_box(read_bvh_path(&p).map(|i| i.clip.len())))
        });
    } else {
        eprintln!("skipping BVH bench: run `cargo xtask setup`");
    }
    if figurine_host::data::data_file("deepmimic", "humanoid.urdf").is_none() {
        eprintln!("skipping assembly benches: run `cargo xtask setup`");
        return;
    }
    // A 12-action synthetic doodle with its true labels as events.
    let d = figurine_host::synth::sequence::sequence(7, &Default::default(), 12, None);
    let dir = std::env::temp_dir().join("figurine_anim_bench");
    let _ = std::fs::create_dir_all(&dir);
    let labels = dir.join("labels.json");
    if std::fs::write(
        &labels,
        serde_json::to_string(&d.labels).unwrap_or_default(),
    )
    .is_err()
    {
        return;
    }
    let Ok(events) = read_label_events(Path::new(&labels)) else {
        return;
    };
    let lib = match ClipLibrary::default_library() {
        Ok(l) => l,
        Err(e) => {
            eprintln!("{e}");
            return;
        }
    };
    let clips = match lib.load(events.iter().map(|e| e.action.as_str())) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("{e}");
            return;
        }
    };
    let opts = AssembleOptions::default();
    let Ok(asm) = assemble(&events, Some(&d.log), &clips, lib.forward(), &opts) else {
        return;
    };
    eprintln!(
        "assembled: {} actions, {} frames ({:.1} s of animation)",
        asm.placements.len(),
        asm.clip.len(),
        asm.clip.duration()
    );
    c.bench_function("assemble 12 actions from a synthetic doodle", |b| {
        b.iter(|| {
            black_box(
                assemble(&events, Some(&d.log), &clips, lib.forward(), &opts).map(|a| a.clip.len()),
            )
        })
    });
    c.bench_function("load the default clips for 12 actions", |b| {
        b.iter(|| {
            black_box(
                lib.load(events.iter().map(|e| e.action.as_str()))
                    .map(|c| c.len()),
            )
        })
    });
    c.bench_function("export assembled animation as BVH text", |b| {
        b.iter(|| black_box(write_bvh_string(&asm.clip).map(|s| s.len())))
    });
    c.bench_function("export assembled animation as .glb", |b| {
        b.iter(|| black_box(write_glb_bytes(&asm.clip, 1.0).map(|g| g.len())))
    });
}

criterion_group! {
    name = anim;
    config = Criterion::default().sample_size(10);
    targets = benches
}
criterion_main!(anim);
