//! The default library's sidestep is a real sideways stepping clip (LAFAN1, retargeted onto
//! DeepMimic's humanoid), not the walk: its root moves across the character's facing, towards
//! the side the doodle moves, while its feet step in turn.

use figurine_host::anim::assemble::{assemble, AssembleOptions, Assembly};
use figurine_host::anim::cli::label_events;
use figurine_host::anim::library::ClipLibrary;
use figurine_host::anim::sideways::{onsets, track};
use figurine_host::data::data_file;
use figurine_host::poselog::PoseLog;
use figurine_host::synth::{gesture, Action, Effort, Knobs};
use glam::{DQuat, DVec3};

/// Whether the data the default sidestep needs was fetched (`cargo xtask setup`).
fn have_data() -> bool {
    let ok = data_file("deepmimic", "humanoid.urdf").is_some()
        && data_file("bvh", "lafan_test.bvh").is_some();
    if !ok {
        eprintln!("skipping: deepmimic or LAFAN data missing — run `cargo xtask setup`");
    }
    ok
}

/// Assembles the doodle's labelled action, played as `action`'s clip.
fn assemble_as(log: &PoseLog, labels: &[figurine_host::synth::Label], action: &str) -> Assembly {
    let mut events = label_events(labels.to_vec());
    for e in &mut events {
        e.action = action.to_string();
    }
    let lib = ClipLibrary::default_library().unwrap();
    let clips = lib.load([action]).unwrap();
    assemble(
        &events,
        Some(log),
        &clips,
        lib.forward(),
        &AssembleOptions::default(),
    )
    .unwrap()
}

/// +1 when the doodle moves to the toy's left (its +X), −1 to its right.
fn doodle_side(log: &PoseLog) -> f64 {
    let (a, b) = (&log.samples[0], &log.samples[log.samples.len() - 1]);
    let q = DQuat::from_xyzw(a.quat[1], a.quat[2], a.quat[3], a.quat[0]);
    let moved = DVec3::from_array(b.pos) - DVec3::from_array(a.pos);
    (q * DVec3::X).dot(moved).signum()
}

#[test]
fn sidestep_steps_sideways_towards_the_doodle_with_alternating_feet() {
    if !have_data() {
        return;
    }
    let mut sides_seen = [false; 2];
    for seed in 1..=12u64 {
        let d = gesture(seed, &Knobs::default(), Action::Sidestep, Effort::NEUTRAL);
        let side = doodle_side(&d.log);
        let k = usize::from(side > 0.0);
        if sides_seen[k] {
            continue;
        }
        sides_seen[k] = true;
        let side_step = assemble_as(&d.log, &d.labels, "sidestep");
        let walk = assemble_as(&d.log, &d.labels, "walk");
        assert_ne!(
            side_step.clip.frames, walk.clip.frames,
            "seed {seed}: sidestep plays the walk"
        );
        let p = &side_step.placements[0];
        let tr = track(&side_step.clip).unwrap();
        let (a, b) = (p.start_frame, p.end_frame);
        // The root moves across the body, not along its facing.
        let across: f32 = tr.lateral[a..=b].iter().sum::<f32>() * tr.dt;
        let along: f32 = tr.along[a..=b].iter().map(|v| v.abs()).sum::<f32>() * tr.dt;
        assert!(
            across.abs() > 0.3 && across.abs() > 3.0 * along,
            "seed {seed}: {across:.2} m across the body, {along:.2} m along its facing"
        );
        // Towards the doodle's side: the toy's left (+X) is the character's left (lateral < 0).
        assert_eq!(
            f64::from(-across.signum()),
            side,
            "seed {seed}: the doodle moves to the toy's {} but the character steps the other way",
            if side > 0.0 { "left" } else { "right" }
        );
        // The feet take turns: every plant is the other foot's.
        let steps = onsets(&tr, a, b);
        eprintln!(
            "seed {seed}: doodle to the toy's {}: {across:+.2} m across the body (> 0 right), \
             {along:.2} m along its facing, {} steps",
            if side > 0.0 { "left" } else { "right" },
            steps.len()
        );
        assert!(steps.len() >= 2, "seed {seed}: {} steps", steps.len());
        assert!(
            steps.windows(2).all(|w| w[0].1 != w[1].1),
            "seed {seed}: feet do not alternate: {steps:?}"
        );
        if sides_seen.iter().all(|s| *s) {
            return;
        }
    }
    panic!("seeds 1-12 never sidestep to both sides: {sides_seen:?}");
}

#[test]
fn sidestep_effort_stays_visible() {
    let amplitude = |a: &Assembly| a.limb_swing_rad(0).unwrap_or(0.0);
    if !have_data() {
        return;
    }
    let (anims, _) = figurine_host::anim::defaults::default_animations(5).unwrap();
    let get = |effort: &str| {
        anims
            .iter()
            .find(|a| a.action == "sidestep" && a.effort == effort)
            .map(|a| &a.assembly)
            .unwrap()
    };
    let seconds = |a: &Assembly| {
        let p = &a.placements[0];
        (p.end_frame - p.start_frame) as f32 / 30.0
    };
    for time in ["sudden", "sustained"] {
        let (strong, light) = (
            get(&format!("{time}-strong")),
            get(&format!("{time}-light")),
        );
        eprintln!(
            "sidestep {time}: amplitude light {:.3} strong {:.3} rad",
            amplitude(light),
            amplitude(strong)
        );
        assert!(amplitude(strong) > 1.2 * amplitude(light), "{time}");
    }
    for weight in ["strong", "light"] {
        let (sudden, sustained) = (
            get(&format!("sudden-{weight}")),
            get(&format!("sustained-{weight}")),
        );
        eprintln!(
            "sidestep {weight}: sudden {:.2} s, sustained {:.2} s",
            seconds(sudden),
            seconds(sustained)
        );
        assert!(seconds(sustained) > 1.3 * seconds(sudden), "{weight}");
    }
}
