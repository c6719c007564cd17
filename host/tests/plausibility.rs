//! `figurine check` against real motion capture: people walking, dancing and turning, as the
//! project fetches them, sit within the envelope assembled animations are held to.

use std::collections::{BTreeMap, BTreeSet};

use figurine_host::anim::assemble::{assemble, AssembleOptions};
use figurine_host::anim::check::{
    check_clip, check_defaults, check_path, envelope, Ground, Plausibility,
};
use figurine_host::anim::cli::label_events;
use figurine_host::anim::library::ClipLibrary;
use figurine_host::data::data_file;
use figurine_host::synth::{sequence, Action, Knobs};

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

/// The measures of the envelope, as [`Plausibility::beyond`] names them, with the bound each
/// is held to (issue 29's goals, `figurine_host::anim::check::envelope`).
fn measures(r: &Plausibility) -> [(&'static str, f32, f32); 6] {
    [
        (
            "penetration",
            r.penetration_max_mm,
            envelope::PENETRATION_MM,
        ),
        ("hovering", r.airborne_max_s, envelope::AIRBORNE_S),
        ("skating", r.skate_median_cm_s, envelope::SKATE_CM_S),
        (
            "knee backwards",
            r.knee_backwards_max_deg,
            envelope::BENT_BACKWARDS_DEG,
        ),
        (
            "elbow backwards",
            r.elbow_backwards_max_deg,
            envelope::BENT_BACKWARDS_DEG,
        ),
        ("root speed", r.root_speed_max, envelope::ROOT_SPEED_M_S),
    ]
}

/// Per default action, the measures in which one of the source takes its variants play is
/// itself beyond the envelope: an assembled animation cannot be held to a measure its own
/// motion capture fails (DeepMimic's spin and dances slide their feet as they pivot, its run
/// and punch skate a little: `figurine check --reference`).
fn source_beyond(library: &ClipLibrary) -> BTreeMap<String, BTreeSet<&'static str>> {
    let clips = library.load(Action::ALL.iter().map(|a| a.name())).unwrap();
    clips
        .iter()
        .map(|(action, ac)| {
            let beyond = ac
                .variants()
                .flat_map(|v| {
                    check_clip(&v.clip, Ground::Auto, &v.variant)
                        .unwrap()
                        .beyond()
                })
                .collect();
            (action.clone(), beyond)
        })
        .collect()
}

/// Rows of the default animations (`figurine check --defaults`, seed 5) and measures still
/// beyond the envelope although their source takes are within it, and why (issue 29):
/// - a sustained, strong run covers its doodle at the fastest pace a person runs (its path
///   is shrunk to 4.2 m/s on average), and its Weight-amplified stride leaves a leg unable to
///   reach the ground where the run lands it: the ground pass raises the root for those
///   frames, which adds a vertical pop (4.3 m/s) and leaves a knee 25° overextended.
const STILL_BEYOND: [(&str, &str); 2] = [
    ("run sustained-strong", "root speed"),
    ("run sustained-strong", "knee backwards"),
];

/// Asserts every measure of `r` within the envelope, but those `exempt`; returns the
/// measures beyond it (exempt ones).
fn assert_within(r: &Plausibility, exempt: &BTreeSet<&str>) -> Vec<&'static str> {
    let mut beyond = Vec::new();
    for (what, value, bound) in measures(r) {
        if value <= bound {
            continue;
        }
        assert!(
            exempt.contains(what),
            "{}: {what} {value} beyond the envelope's {bound}: {r:?}",
            r.name
        );
        beyond.push(what);
    }
    beyond
}

/// Every default action in the four effort corners and neutral, as `figurine animate`
/// assembles it, stays within the real-mocap envelope in every measure (bounds: penetration ≤
/// 20 mm, airborne ≤ 0.5 s, contact-foot median speed ≤ 10 cm/s, knees and elbows bent
/// backwards ≤ 15°, root speed ≤ 4.2 m/s) — but the measures its own source takes fail, and
/// those listed in [`STILL_BEYOND`].
#[test]
fn every_default_animation_stays_within_the_envelope_its_source_takes_keep() {
    if data_file("deepmimic", "humanoid.urdf").is_none() {
        eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
        return;
    }
    let library = ClipLibrary::default_library().unwrap();
    let inherited = source_beyond(&library);
    let rows = check_defaults(5).unwrap();
    assert_eq!(rows.len(), 60);
    let mut within = 0;
    for r in &rows {
        let action = r.name.split(' ').next().unwrap_or_default();
        let mut exempt = inherited.get(action).cloned().unwrap_or_default();
        exempt.extend(
            STILL_BEYOND
                .iter()
                .filter(|(row, _)| *row == r.name)
                .map(|(_, what)| *what),
        );
        let beyond = assert_within(r, &exempt);
        if beyond.is_empty() {
            within += 1;
        } else {
            eprintln!("{}: beyond in {beyond:?} (exempt: {exempt:?})", r.name);
        }
    }
    eprintln!("{within} of {} within the whole envelope", rows.len());
}

/// Measures sequences may still leave the envelope in, and why (issue 29): where one action
/// blends into the next, the root is interpolated between the two actions' roots, which
/// stand up to a few centimetres apart; over a 0.2 s blend that adds up to 0.4 m/s to an
/// action already paced near the fastest person's 4.2 m/s (traced in sequence 4 at a punch's
/// end, 4.38 m/s, before the floor restraint; sequence 1 now reaches 4.23 m/s). Blending the
/// root's velocity rather than its position would hold it.
const STILL_BEYOND_AT_JOINS: [&str; 1] = ["root speed"];

/// Multi-action sequences from the generator (`figurine synth sequence`: six random actions
/// in random effort corners, seeds 1–5 and the demo's 2026), assembled from their labels along
/// their doodles, stay within the envelope in every measure but those a source take of one of
/// their actions fails, a row of [`STILL_BEYOND`] they play, or [`STILL_BEYOND_AT_JOINS`].
#[test]
fn generated_sequences_stay_within_the_envelope_their_source_takes_keep() {
    if data_file("deepmimic", "humanoid.urdf").is_none() {
        eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
        return;
    }
    let library = ClipLibrary::default_library().unwrap();
    let inherited = source_beyond(&library);
    for seed in [1, 2, 3, 4, 5, 2026] {
        let doodle = sequence(seed, &Knobs::default(), 6, None);
        let events = label_events(doodle.labels.clone());
        let clips = library
            .load(events.iter().map(|e| e.action.as_str()))
            .unwrap();
        let asm = assemble(
            &events,
            Some(&doodle.log),
            &clips,
            library.forward(),
            &AssembleOptions::default(),
        )
        .unwrap();
        let played: Vec<String> = events
            .iter()
            .map(|e| {
                let time = if e.time > 0.0 { "sudden" } else { "sustained" };
                let weight = if e.weight > 0.0 { "strong" } else { "light" };
                format!("{} {time}-{weight}", e.action)
            })
            .collect();
        let mut exempt: BTreeSet<&str> = STILL_BEYOND_AT_JOINS.into_iter().collect();
        for (e, row) in events.iter().zip(&played) {
            exempt.extend(inherited.get(&e.action).into_iter().flatten().copied());
            exempt.extend(
                STILL_BEYOND
                    .iter()
                    .filter(|(r, _)| r == row)
                    .map(|(_, what)| *what),
            );
        }
        let r = check_clip(&asm.clip, Ground::At(0.0), &format!("sequence {seed}")).unwrap();
        let beyond = assert_within(&r, &exempt);
        eprintln!(
            "sequence {seed} ({}): penetration {:.1} mm, airborne {:.2} s, skating {:.1} cm/s, \
             knee {:.0}°, elbow {:.0}°, root {:.2} m/s; beyond in {beyond:?} (exempt: {exempt:?})",
            played.join(", "),
            r.penetration_max_mm,
            r.airborne_max_s,
            r.skate_median_cm_s,
            r.knee_backwards_max_deg,
            r.elbow_backwards_max_deg,
            r.root_speed_max,
        );
    }
}
