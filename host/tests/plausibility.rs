//! `figurine check` against real motion capture: people walking, dancing and turning, as the
//! project fetches them, sit within the envelope assembled animations are held to.

use figurine_host::anim::assemble::Assembly;
use figurine_host::anim::assemble::{assemble, AssembleOptions};
use figurine_host::anim::check::{
    accel_near, check_assembly, check_path, check_reference, default_tilt_reference, envelope,
    Ground, Plausibility, JOIN_WINDOW_S,
};
use figurine_host::anim::cli::label_events;
use figurine_host::anim::defaults::default_animations;
use figurine_host::anim::library::ClipLibrary;
use figurine_host::anim::pacing::HUMAN_ROOT_ACCEL_M_S2;
use figurine_host::anim::tilt_reference::vigour_spread;
use figurine_host::data::data_file;
use figurine_host::recognize::simulate::effort_words;
use figurine_host::synth::{sequence, Knobs};

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
fn measures(r: &Plausibility) -> [(&'static str, f32, f32); 7] {
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
        (
            "pops at joins",
            r.root_accel_joins_max.unwrap_or(0.0),
            envelope::ROOT_ACCEL_JOIN_M_S2,
        ),
    ]
}

/// The largest `measure` among the reference takes that sit within the envelope.
fn most_within_envelope(rows: &[Plausibility], measure: impl Fn(&Plausibility) -> f32) -> f32 {
    rows.iter()
        .filter(|r| r.beyond().is_empty())
        .map(measure)
        .fold(0.0f32, f32::max)
}

/// The bound on the root's acceleration at joins is the real takes' own: the largest 95th
/// percentile of root acceleration among the takes within the rest of the envelope.
#[test]
fn the_bound_on_pops_at_joins_is_what_real_takes_reach() {
    let Ok(rows) = check_reference() else {
        eprintln!("skipping: no motion capture — run `cargo xtask setup`");
        return;
    };
    let highest = most_within_envelope(&rows, |r| r.root_accel_p95);
    assert!(
        (highest - envelope::ROOT_ACCEL_JOIN_M_S2).abs() < 1.0,
        "real takes within the envelope reach {highest} m/s² (95th percentile)"
    );
}

/// The hardest a squeeze may make the root accelerate is the real takes' own: the largest
/// root acceleration among the takes within the envelope.
#[test]
fn the_bound_on_a_squeezed_roots_acceleration_is_what_real_takes_reach() {
    let Ok(rows) = check_reference() else {
        eprintln!("skipping: no motion capture — run `cargo xtask setup`");
        return;
    };
    let hardest = most_within_envelope(&rows, |r| r.root_accel_max);
    assert!(
        (hardest - HUMAN_ROOT_ACCEL_M_S2).abs() < 1.0,
        "real takes within the envelope reach {hardest} m/s²"
    );
}

/// The margin an action's torso tilt is judged with is the real takes' own: the widest
/// spread of tilt (95th percentile or max) among one performer's takes of one kind at
/// different vigour (LAFAN1's calm, median and wild dance; its stroll, walk and stride).
#[test]
fn the_tilt_margin_is_how_far_real_takes_of_one_kind_differ_in_vigour() {
    let Ok(tilt) = default_tilt_reference() else {
        eprintln!("skipping: no motion capture — run `cargo xtask setup`");
        return;
    };
    let spread = vigour_spread(&tilt.kinds);
    assert!(
        (spread - envelope::TILT_MARGIN_DEG).abs() < 0.1,
        "one performer's takes of one kind differ by up to {spread}°"
    );
    // Every kind of action the default library plays has real takes to judge it by.
    for action in ClipLibrary::default_library().unwrap().actions.keys() {
        assert!(tilt.bounds(action).is_some(), "{action}");
    }
}

/// The largest root acceleration (m/s²) of an assembled animation away from its joins
/// (further than [`JOIN_WINDOW_S`] from every one): the actions' own.
fn accel_away_from_joins(asm: &Assembly) -> f32 {
    let near = (JOIN_WINDOW_S / asm.clip.frame_time).round() as usize;
    let away: Vec<usize> = (1..asm.clip.len().saturating_sub(1))
        .filter(|&f| asm.joins.iter().all(|&k| f.abs_diff(k) > near))
        .collect();
    accel_near(&asm.clip, &away, 0.0)
}

/// Asserts every measure of `r` within the envelope, pops at joins included, and every
/// action's torso tilt (95th percentile and max) within the range of the real takes of its
/// kind, widened by the measured vigour spread (`figurine_host::anim::torso_tilt`).
fn assert_within(r: &Plausibility) {
    for (what, value, bound) in measures(r) {
        assert!(
            value <= bound,
            "{}: {what} {value} beyond the envelope's {bound}: {r:?}",
            r.name
        );
    }
    assert!(!r.tilt_by_action.is_empty(), "{}: tilt not judged", r.name);
    for t in &r.tilt_by_action {
        let b = t
            .bounds
            .unwrap_or_else(|| panic!("{}: no take of {}'s kind", r.name, t.action));
        assert!(
            t.holds(),
            "{}: {}'s torso tilt p95 {:.1}° max {:.1}° beyond its kind's p95 {:.1}-{:.1}° max \
             {:.1}-{:.1}° (both sides judged: {})",
            r.name,
            t.action,
            t.figures.p95,
            t.figures.max,
            b.p95.0,
            b.p95.1,
            b.max.0,
            b.max.1,
            t.whole
        );
    }
}

/// Every default action in the four effort corners and neutral, as `figurine animate`
/// assembles it, stays within the real-mocap envelope in every measure (bounds: penetration ≤
/// 20 mm, airborne ≤ 0.5 s, contact-foot median speed ≤ 10 cm/s, knees and elbows bent
/// backwards ≤ 15°, root speed ≤ 4.2 m/s, root acceleration within 2 frames of a join ≤
/// 28 m/s²), whatever its source take does (DeepMimic's spin slides its feet and flies
/// 0.50 s, its backflip's hips outrun the fastest run: the assembler plants, paces and eases
/// them).
#[test]
fn every_default_animation_stays_within_the_envelope() {
    if data_file("deepmimic", "humanoid.urdf").is_none() {
        eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
        return;
    }
    let (anims, _) = default_animations(5).unwrap();
    let tilt = default_tilt_reference().unwrap();
    assert_eq!(anims.len(), 60);
    for a in &anims {
        let r = &check_assembly(&a.assembly, &format!("{} {}", a.action, a.effort), &tilt).unwrap();
        assert!(
            r.tilt_by_action.iter().all(|t| t.whole),
            "judged on both sides"
        );
        assert_within(r);
    }
    eprintln!(
        "{} of {} within the whole envelope",
        anims.len(),
        anims.len()
    );
}

/// Multi-action sequences from the generator (`figurine synth sequence`: six random actions
/// in random effort corners, seeds 1–5 and the demo's 2026), assembled from their labels along
/// their doodles, stay within the envelope in every measure, pops at joins included (≤ 28 m/s²
/// within 2 frames of a join; the assembler eases the root's velocity across a join and
/// settles an action cut mid-hop there).
#[test]
fn generated_sequences_stay_within_the_envelope() {
    if data_file("deepmimic", "humanoid.urdf").is_none() {
        eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
        return;
    }
    let library = ClipLibrary::default_library().unwrap();
    let tilt = default_tilt_reference().unwrap();
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
            .map(|e| format!("{} {}", e.action, effort_words(e.time, e.weight)))
            .collect();
        let r = check_assembly(&asm, &format!("sequence {seed}"), &tilt).unwrap();
        eprintln!(
            "sequence {seed} ({}): penetration {:.1} mm, airborne {:.2} s, skating {:.1} cm/s, \
             knee {:.0}°, elbow {:.0}°, root {:.2} m/s, {:.0} m/s² at joins ({:.0} away, p95 \
             {:.0}), torso tilt p95/max per action {}",
            played.join(", "),
            r.penetration_max_mm,
            r.airborne_max_s,
            r.skate_median_cm_s,
            r.knee_backwards_max_deg,
            r.elbow_backwards_max_deg,
            r.root_speed_max,
            r.root_accel_joins_max.unwrap_or(0.0),
            accel_away_from_joins(&asm),
            r.root_accel_p95,
            r.tilt_by_action
                .iter()
                .map(|t| format!("{:.0}/{:.0}", t.figures.p95, t.figures.max))
                .collect::<Vec<_>>()
                .join(" "),
        );
        assert_within(&r);
    }
}
