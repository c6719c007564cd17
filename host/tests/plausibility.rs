//! `figurine check` against real motion capture: people walking, dancing and turning, as the
//! project fetches them, sit within the envelope assembled animations are held to.

use figurine_host::anim::check::{check_path, Ground};
use figurine_host::data::data_file;

#[test]
fn real_walking_and_dancing_takes_sit_within_the_envelope() {
    let takes = [
        ("deepmimic", "humanoid3d_walk.txt"),
        ("bvh", "mixamo_walk_turn.bvh"),
        ("bvh", "lafan_dance1.bvh"),
        ("bvh", "lafan_test.bvh"),
        ("bvh", "mocapbank_kneel.bvh"),
    ];
    let mut judged = 0;
    for (kind, name) in takes {
        let Some(path) = data_file(kind, name) else {
            eprintln!("skipping {kind}/{name}: run `cargo xtask setup`");
            continue;
        };
        let r = check_path(&path, Ground::Auto).unwrap();
        assert!(
            r.beyond().is_empty(),
            "{name}: beyond {:?}: {r:?}",
            r.beyond()
        );
        // The feet of people standing and walking barely slide.
        assert!(r.skate_median_cm_s < 7.0, "{r:?}");
        judged += 1;
    }
    eprintln!("{judged} real takes judged");
}
