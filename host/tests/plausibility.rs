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

/// Every default action in the four effort corners and neutral, as `figurine animate`
/// assembles it: none sinks into the ground, hovers beyond a jump's flight (a strong effort's
/// amplified height is put back on the ground wherever the source clip stood) or bends an
/// elbow backwards (the hinges are held within the source's range). The other measures are
/// printed; they are not all within the envelope yet (issue 29).
#[test]
fn no_default_animation_sinks_hovers_or_bends_an_elbow_backwards() {
    use figurine_host::anim::check::{check_defaults, envelope};
    let rows = check_defaults(5).unwrap();
    assert_eq!(rows.len(), 60);
    for r in &rows {
        assert!(r.penetration_max_mm <= envelope::PENETRATION_MM, "{r:?}");
        assert!(r.airborne_max_s <= envelope::AIRBORNE_S, "{r:?}");
        assert!(
            r.elbow_backwards_max_deg <= envelope::BENT_BACKWARDS_DEG,
            "{r:?}"
        );
    }
    let within = rows.iter().filter(|r| r.beyond().is_empty()).count();
    eprintln!("{within} of {} within the whole envelope", rows.len());
}
