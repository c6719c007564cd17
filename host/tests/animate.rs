//! End-to-end animation assembly: synthetic doodles with known actions → animation, checked
//! against the requirements (path, timing, efforts, ground, errors, exports).

use std::path::{Path, PathBuf};

use figurine_host::anim::assemble::{assemble, AssembleOptions, Assembly, LIMB_SWING_JOINTS};
use figurine_host::anim::effort::spine_lean;
use figurine_host::anim::joint_limits::JointRanges;
use figurine_host::anim::library::ClipLibrary;
use figurine_host::anim::phrasing::Stage;
use figurine_host::anim::trajectory::ground;
use figurine_host::events::ActionRecord;
use figurine_host::poselog::{PoseLog, PoseSample};
use glam::{Quat, Vec3};

/// Deterministic noise in [-1, 1].
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// One doodled action: name, duration (s), ground direction change (rad/s) and speed (toy m/s).
struct Seg {
    action: &'static str,
    dur: f64,
    speed: f64,
    turn: f64,
}

/// A toy doodle at `rate` Hz following `segs` with 0.4 s pauses between them; returns the
/// log and the events a perfect recognizer would emit (efforts set by the caller).
fn doodle(segs: &[Seg], rate: f64, seed: u64, scale: f64) -> (PoseLog, Vec<ActionRecord>) {
    let mut rng = Lcg(seed);
    let mut t = 0.0;
    let mut pos = [0.2, 0.9, -0.1];
    let mut heading: f64 = 0.4; // radians, ground direction of travel
    let mut samples = Vec::new();
    let mut events = Vec::new();
    let dt = 1.0 / rate;
    let push =
        |t: f64, pos: [f64; 3], heading: f64, rng: &mut Lcg, samples: &mut Vec<PoseSample>| {
            // Object +Z (front) along the travel direction: yaw about +Y.
            let yaw = (heading.cos()).atan2(heading.sin());
            let q = Quat::from_rotation_y(yaw as f32);
            let p = [
                pos[0] + 0.001 * rng.next(),
                pos[1] + 0.001 * rng.next(),
                pos[2] + 0.001 * rng.next(),
            ];
            samples.push(PoseSample {
                t: t + 0.2 * dt * rng.next(),
                pos: p,
                quat: [q.w as f64, q.x as f64, q.y as f64, q.z as f64],
            });
        };
    for _ in 0..20 {
        push(t, pos, heading, &mut rng, &mut samples);
        t += dt;
    }
    for s in segs {
        let start = t;
        let n = (s.dur * rate).round() as usize;
        for i in 0..n {
            let u = i as f64 / n as f64;
            heading += s.turn * dt;
            pos[0] += scale * s.speed * heading.cos() * dt;
            pos[2] += scale * s.speed * heading.sin() * dt;
            let hop = if s.action == "jump" {
                0.12 * (std::f64::consts::PI * u).sin()
            } else {
                0.02 * (u * 20.0).sin().abs()
            };
            let mut p = pos;
            p[1] += scale * hop;
            push(t, p, heading, &mut rng, &mut samples);
            t += dt;
        }
        events.push(ActionRecord {
            action: s.action.into(),
            start,
            end: t,
            time: 0.0,
            weight: 0.0,
            distance: 0,
        });
        for _ in 0..(0.4 * rate) as usize {
            push(t, pos, heading, &mut rng, &mut samples);
            t += dt;
        }
    }
    (PoseLog { samples }, events)
}

fn story() -> Vec<Seg> {
    vec![
        Seg {
            action: "walk",
            dur: 3.0,
            speed: 0.12,
            turn: 0.3,
        },
        Seg {
            action: "jump",
            dur: 1.6,
            speed: 0.08,
            turn: 0.0,
        },
        Seg {
            action: "punch",
            dur: 1.5,
            speed: 0.0,
            turn: 0.0,
        },
        Seg {
            action: "run",
            dur: 2.0,
            speed: 0.3,
            turn: -0.4,
        },
        Seg {
            action: "kick",
            dur: 1.4,
            speed: 0.0,
            turn: 0.0,
        },
        Seg {
            action: "crouch",
            dur: 1.5,
            speed: 0.0,
            turn: 0.0,
        },
    ]
}

fn setup() -> Option<(
    ClipLibrary,
    std::collections::BTreeMap<String, figurine_host::anim::library::ActionClip>,
)> {
    if figurine_host::data::data_file("deepmimic", "humanoid.urdf").is_none() {
        eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
        return None;
    }
    let lib = ClipLibrary::default_library().unwrap();
    let names: Vec<String> = lib.actions.keys().cloned().collect();
    let mut clips = lib.load(names.iter().map(String::as_str)).unwrap();
    // These tests measure the assembler and effort transfer on one clip per action; which
    // variant a recognised effort picks is tested in animate_variants.rs.
    for c in clips.values_mut() {
        c.alternatives.clear();
    }
    Some((lib, clips))
}

fn out_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("animate");
    let _ = std::fs::create_dir_all(&d);
    d
}

fn run(events: &[ActionRecord], log: Option<&PoseLog>) -> Assembly {
    let (lib, clips) = setup().unwrap();
    assemble(
        events,
        log,
        &clips,
        lib.forward(),
        &AssembleOptions::default(),
    )
    .unwrap()
}

/// Feet never go below the ground.
fn lowest_foot(asm: &Assembly) -> f32 {
    let legs = figurine_host::anim::contact::find_legs(&asm.clip);
    assert_eq!(legs.len(), 2);
    (0..asm.clip.len())
        .flat_map(|f| {
            let p = asm.clip.joint_positions(f);
            legs.iter()
                .flat_map(|l| l.foot.clone())
                .map(move |j| p[j].y)
                .collect::<Vec<_>>()
        })
        .fold(f32::INFINITY, f32::min)
}

/// Stated bound: every root position of a moving action lies within this distance (m) of
/// the mapped doodle path, and the action ends within it of the path's end.
const PATH_BOUND_M: f32 = 0.3;

#[test]
fn root_follows_the_mapped_doodle_and_timing_matches_the_events() {
    if setup().is_none() {
        return;
    }
    for (seed, rate, scale) in [(1u64, 100.0, 1.0), (7, 240.0, 0.5), (11, 60.0, 2.0)] {
        let (log, events) = doodle(&story(), rate, seed, scale);
        let world_scale = 10.0 / scale as f32; // the doodle's size does not change the character's
        let (lib, clips) = setup().unwrap();
        let opts = AssembleOptions {
            world_scale,
            ..AssembleOptions::default()
        };
        let asm = assemble(&events, Some(&log), &clips, lib.forward(), &opts).unwrap();
        let fps = asm.clip.fps();
        assert_eq!(asm.placements.len(), events.len());
        for (p, e) in asm.placements.iter().zip(&events) {
            assert_eq!(p.action, e.action);
            assert!(
                (asm.t_origin as f32 + p.start_frame as f32 / fps - e.start as f32).abs()
                    <= 1.0 / fps,
                "{} start",
                p.action
            );
            assert!(
                (asm.t_origin as f32 + p.end_frame as f32 / fps - e.end as f32).abs() <= 1.0 / fps,
                "{} end",
                p.action
            );
            if !p.moving {
                continue;
            }
            let mut worst = 0.0f32;
            for f in p.start_frame..=p.end_frame {
                let r = ground(asm.clip.frames[f].translations[0]);
                worst = worst.max(p.path.distance(r));
            }
            let end = ground(asm.clip.frames[p.end_frame].translations[0]);
            let path_end = *p.path.pts.last().unwrap();
            eprintln!(
                "seed {seed}: {} path {:.2} m, worst distance {worst:.3} m, end error {:.3} m",
                p.action,
                p.path.length(),
                (end - path_end).length()
            );
            assert!(p.path.length() > 1.0, "{} path too short to test", p.action);
            assert!(worst <= PATH_BOUND_M, "{}: {worst}", p.action);
            assert!((end - path_end).length() <= PATH_BOUND_M, "{}", p.action);
        }
        assert!(
            lowest_foot(&asm) >= -1e-3,
            "foot below ground: {}",
            lowest_foot(&asm)
        );
        let total = (events.last().unwrap().end - asm.t_origin) as f32 + opts.hold_s;
        assert!((asm.clip.duration() - total).abs() <= 1.5 / fps);
        if seed == 1 {
            let png = out_dir().join("story.png");
            figurine_host::anim::cli::plot_assembly(&asm, lib.forward(), &png).unwrap();
            eprintln!("contact sheet: {}", png.display());
        }
    }
}

#[test]
fn cyclic_walk_plays_whole_cycles_without_skating() {
    if setup().is_none() {
        return;
    }
    let seg = [Seg {
        action: "walk",
        dur: 4.0,
        speed: 0.12,
        turn: 0.0,
    }];
    let mut strides = Vec::new();
    for weight in [0.0, -0.9, 0.9] {
        let (log, mut events) = doodle(&seg, 100.0, 3, 1.0);
        events[0].weight = weight;
        let asm = run(&events, Some(&log));
        let p = &asm.placements[0];
        // 4 s at 1.2 m/s = 4.8 m; DeepMimic's walk travels 1.24 m a cycle → 4 cycles; a strong
        // walk takes longer strides (fewer cycles); a light one shorter strides, as many as its
        // quickest cadence allows (MAX_CADENCE × the clip's: 4 in 4 s), covering less ground.
        let stride = p.path.length() / p.cycles as f32;
        eprintln!(
            "walk Lw={weight}: path {:.2} m, stride {stride:.2} m",
            p.path.length()
        );
        match weight {
            w if w < 0.0 => assert!(p.cycles >= 4, "{}", p.cycles),
            w if w > 0.0 => assert!(p.cycles < 4, "{}", p.cycles),
            _ => assert_eq!(p.cycles, 4, "{}", p.path.length()),
        }
        strides.push(stride);
        // Planted feet barely slide: horizontal ankle speed while in contact.
        let legs = figurine_host::anim::contact::find_legs(&asm.clip);
        let dt = asm.clip.frame_time;
        let mut slide = Vec::new();
        for (l, leg) in legs.iter().enumerate() {
            for f in (p.start_frame + 5)..(p.end_frame - 5) {
                if asm.contacts[l][f] && asm.contacts[l][f + 1] {
                    let a = asm.clip.joint_positions(f)[leg.ankle];
                    let b = asm.clip.joint_positions(f + 1)[leg.ankle];
                    slide.push(ground(b - a).length() / dt);
                }
            }
        }
        slide.sort_by(f32::total_cmp);
        let median = slide[slide.len() / 2];
        eprintln!(
            "walk Lw={weight}: {} cycles, contact frames {}, median planted-foot speed {median:.3} m/s",
            p.cycles,
            slide.len()
        );
        assert!(slide.len() > 20 && median < 0.25, "{median}");
    }
    // Light steps short, strong steps long.
    assert!(
        strides[1] < strides[0] && strides[0] < strides[2],
        "{strides:?}"
    );
}

fn single(action: &str, time: f64, weight: f64) -> Assembly {
    let events = vec![ActionRecord {
        action: action.into(),
        start: 0.5,
        end: 2.5,
        time,
        weight,
        distance: 0,
    }];
    run(&events, None)
}

#[test]
fn sudden_executes_faster_than_sustained() {
    if setup().is_none() {
        return;
    }
    for action in ["punch", "kick", "jump"] {
        let exec = |lt: f64| {
            let a = single(action, lt, 0.0);
            let (_, s, e) = *a.placements[0]
                .stages
                .iter()
                .find(|s| s.0 == Stage::Execution)
                .unwrap();
            e - s
        };
        let (sudden, neutral, sustained) = (exec(0.9), exec(0.0), exec(-0.9));
        eprintln!("{action}: execution sudden {sudden:.3} s, neutral {neutral:.3} s, sustained {sustained:.3} s");
        assert!(
            sudden < neutral && neutral < sustained,
            "{action}: {sudden} {neutral} {sustained}"
        );
    }
}

#[test]
fn strong_moves_wider_and_bends_lower_than_light() {
    if setup().is_none() {
        return;
    }
    for action in ["punch", "kick", "wave", "bow"] {
        let light = single(action, 0.0, -0.9);
        let strong = single(action, 0.0, 0.9);
        // Amplitude: mean angle (rad) by which the arms' and legs' joints turn away from
        // their pose at the action's start — what eq. 7 scales. (Positions would mix in the
        // foot pinning, which holds planted feet whatever the amplitude.)
        let amp = |a: &Assembly| a.limb_swing_rad(0).unwrap_or(0.0);
        // Spine angle at the action's first frame, where rescaling (eq. 7, anchored at the
        // stage start) has not acted yet, so the difference is the reshaping's alone.
        let tilt = |a: &Assembly| spine_lean(&a.clip, a.placements[0].start_frame, Vec3::X);
        eprintln!(
            "{action}: amplitude light {:.3} strong {:.3} rad; forward spine lean light {:.1}° strong {:.1}°",
            amp(&light),
            amp(&strong),
            tilt(&light).to_degrees(),
            tilt(&strong).to_degrees()
        );
        assert!(amp(&strong) > amp(&light), "{action}");
        // δθ = 0.1·Lw per spine bone (chest, neck), 0.1 × (0.9 − −0.9) = 0.18 rad each: the
        // chest→head line turns by between one and two bones' worth.
        let d = tilt(&strong) - tilt(&light);
        assert!(d > 0.18 && d < 0.37, "{action}: {d}");
    }
}

/// Per joint of [`LIMB_SWING_JOINTS`]: its mean swing (rad) from the action's first frame over the
/// action, and the share of the action's frames in which swinging it 10 % further from that
/// pose would leave the range the library's actors moved it in (it is at its range's edge).
fn swing_by_joint(a: &Assembly, ranges: &JointRanges) -> Vec<(&'static str, f32, f32)> {
    let sk = &a.clip.skeleton;
    let p = &a.placements[0];
    let frames = &a.clip.frames[p.start_frame..=p.end_frame];
    let q0 = &a.clip.frames[p.start_frame].rotations;
    LIMB_SWING_JOINTS
        .iter()
        .filter_map(|&n| Some((n, sk.find(n)?)))
        .map(|(n, j)| {
            let swing = frames
                .iter()
                .map(|f| q0[j].angle_between(f.rotations[j]))
                .sum::<f32>()
                / frames.len() as f32;
            let at_edge = frames
                .iter()
                .filter(|f| {
                    let d = f.rotations[j] * q0[j].inverse();
                    let d = if d.w < 0.0 { -d } else { d };
                    let (axis, angle) = d.to_axis_angle();
                    angle > 0.05
                        && !ranges.contains(j, Quat::from_axis_angle(axis, angle * 1.1) * q0[j])
                })
                .count() as f32
                / frames.len() as f32;
            (n, swing, at_edge)
        })
        .collect()
}

/// Where a strong kick's swing is held: per joint, its swing light / neutral / strong and
/// how often it sits at the edge of the library's range. Eq. 7 scales every joint's swing by
/// c = Lw + 1 (1.9 at Lw = 0.9); a joint at its range's edge gains less. The strong kick's
/// amplitude beside the light one's is issue 29's effort contrast (README, "Is the animation
/// believable?").
#[test]
fn a_strong_kicks_swing_is_held_where_its_joints_meet_their_range() {
    let Some((_, clips)) = setup() else {
        return;
    };
    let ranges = clips["kick"].ranges.clone().unwrap();
    let (light, neutral, strong) = (
        single("kick", 0.0, -0.9),
        single("kick", 0.0, 0.0),
        single("kick", 0.0, 0.9),
    );
    let (l, n, s) = (
        swing_by_joint(&light, &ranges),
        swing_by_joint(&neutral, &ranges),
        swing_by_joint(&strong, &ranges),
    );
    for ((l, n), s) in l.iter().zip(&n).zip(&s) {
        eprintln!(
            "kick {:<15} swing light {:.3} neutral {:.3} strong {:.3} rad (strong/neutral {:.2}), \
             at its range's edge in {:.0} % of the strong kick's frames",
            l.0,
            l.1,
            n.1,
            s.1,
            s.1 / n.1.max(1e-6),
            100.0 * s.2
        );
    }
    let amp = |a: &Assembly| a.limb_swing_rad(0).unwrap_or(0.0);
    eprintln!(
        "kick amplitude light {:.3} neutral {:.3} strong {:.3} rad",
        amp(&light),
        amp(&neutral),
        amp(&strong)
    );
    // An arm that is rarely at its range's edge (nothing but its range holds an arm: the
    // legs are drawn back from the floor too) swings well wider strong than neutral, and
    // neutral than light: eq. 7 acts where there is room.
    for ((l, n), s) in l.iter().zip(&n).zip(&s) {
        if (s.0.ends_with("shoulder") || s.0.ends_with("elbow")) && s.2 < 0.1 {
            assert!(
                s.1 > 1.3 * n.1 && n.1 > l.1,
                "{}: {} {} {}",
                s.0,
                l.1,
                n.1,
                s.1
            );
        }
    }
    assert!(amp(&strong) > amp(&neutral) && amp(&neutral) > amp(&light));
    let mean = s.iter().map(|j| j.1).sum::<f32>() / s.len() as f32;
    assert!((mean - amp(&strong)).abs() < 1e-4, "{mean}");
}

#[test]
fn an_action_without_a_clip_lists_the_missing_mappings() {
    let lib = ClipLibrary::default_library().unwrap();
    let events = ["walk", "fly", "juggle", "fly"];
    let err = lib.check_actions(events).unwrap_err().to_string();
    assert!(
        err.contains("fly, juggle") || err.contains("fly") && err.contains("juggle"),
        "{err}"
    );
    let err = lib.load(events).unwrap_err().to_string();
    assert!(
        err.starts_with("no clip for action(s) fly, juggle"),
        "{err}"
    );
}

#[test]
fn cli_writes_bvh_glb_and_plot_that_read_back() {
    if setup().is_none() {
        return;
    }
    let (log, events) = doodle(&story(), 100.0, 5, 1.0);
    let dir = out_dir();
    let log_path = dir.join("doodle.csv");
    let ev_path = dir.join("events.jsonl");
    let mut f = std::fs::File::create(&log_path).unwrap();
    log.write(&mut f).unwrap();
    let mut f = std::fs::File::create(&ev_path).unwrap();
    for e in &events {
        figurine_host::events::write_event(&mut f, e).unwrap();
    }
    let bvh = dir.join("anim.bvh");
    let glb = dir.join("anim.glb");
    let png = dir.join("anim.png");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_figurine"))
        .args(["animate", "--events"])
        .arg(&ev_path)
        .arg("--doodle")
        .arg(&log_path)
        .arg("--out")
        .arg(&bvh)
        .arg("--glb")
        .arg(&glb)
        .arg("--plot")
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{}", String::from_utf8_lossy(&out.stdout));
    let back = figurine_host::motion::read_bvh_path(&bvh).unwrap();
    assert!(back.notes.is_empty());
    assert!((back.clip.fps() - 30.0).abs() < 0.01);
    assert!(std::fs::metadata(&glb).unwrap().len() > 1000);
    assert!(png.is_file());
    // Missing clips are an error naming them.
    let bad = dir.join("bad.jsonl");
    std::fs::write(
        &bad,
        "{\"action\":\"teleport\",\"start\":0,\"end\":1,\"time\":0,\"weight\":0,\"distance\":0}\n",
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_figurine"))
        .args(["animate", "--events"])
        .arg(&bad)
        .arg("--out")
        .arg(dir.join("x.bvh"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("teleport"));
    let _ = Path::new("");
}

/// Peak joint speed (m/s) per frame of an animation.
fn joint_speed_per_frame(asm: &Assembly) -> Vec<f32> {
    let pos = asm.clip.all_positions();
    let dt = asm.clip.frame_time;
    (1..pos.len())
        .map(|f| {
            pos[f]
                .iter()
                .zip(&pos[f - 1])
                .map(|(a, b)| (*a - *b).length() / dt)
                .fold(0.0f32, f32::max)
        })
        .collect()
}

#[test]
fn transitions_do_not_pop() {
    if setup().is_none() {
        return;
    }
    let (log, events) = doodle(&story(), 100.0, 1, 1.0);
    let asm = run(&events, Some(&log));
    let v = joint_speed_per_frame(&asm);
    let inside: f32 = asm
        .placements
        .iter()
        .flat_map(|p| (p.start_frame + 8)..p.end_frame.saturating_sub(8))
        .filter_map(|f| v.get(f))
        .copied()
        .fold(0.0, f32::max);
    for &(i, j) in &asm.transitions {
        let peak = v[i.saturating_sub(2)..(j + 2).min(v.len())]
            .iter()
            .copied()
            .fold(0.0f32, f32::max);
        eprintln!(
            "transition {i}-{j}: peak joint speed {peak:.2} m/s (inside actions {inside:.2})"
        );
        assert!(peak <= inside.max(4.0), "pop at {i}-{j}: {peak}");
    }
}

/// Labels of `figurine synth` as events, as `figurine animate --labels` reads them.
fn label_events(labels: &[figurine_host::synth::sequence::Label]) -> Vec<ActionRecord> {
    figurine_host::anim::cli::label_events(labels.to_vec())
}

#[test]
fn random_synthetic_doodles_animate_within_bounds() {
    if setup().is_none() {
        return;
    }
    let knobs = figurine_host::synth::knobs::Knobs::default();
    let (lib, clips) = setup().unwrap();
    for seed in [101u64, 202, 303, 404] {
        let d = figurine_host::synth::sequence::sequence(seed, &knobs, 6, None);
        let events = label_events(&d.labels);
        let asm = assemble(
            &events,
            Some(&d.log),
            &clips,
            lib.forward(),
            &AssembleOptions::default(),
        )
        .unwrap();
        assert_eq!(asm.placements.len(), events.len());
        let fps = asm.clip.fps();
        for (p, e) in asm.placements.iter().zip(&events) {
            // Starts match (an action may wait for a previous one that overran).
            let start = asm.t_origin as f32 + p.start_frame as f32 / fps;
            assert!(start + 1.0 / fps >= e.start as f32, "{seed} {}", p.action);
            if p.moving && p.path.length() > 0.3 {
                let worst = (p.start_frame..=p.end_frame)
                    .map(|f| p.path.distance(ground(asm.clip.frames[f].translations[0])))
                    .fold(0.0f32, f32::max);
                assert!(worst <= PATH_BOUND_M, "seed {seed} {}: {worst}", p.action);
            }
        }
        assert!(asm
            .clip
            .frames
            .iter()
            .all(|p| p.rotations.iter().all(|q| q.is_finite())));
        assert!(
            lowest_foot(&asm) >= -1e-3,
            "seed {seed}: {}",
            lowest_foot(&asm)
        );
    }
}

#[test]
fn a_jump_travels_only_while_in_the_air() {
    if setup().is_none() {
        return;
    }
    let (log, events) = doodle(
        &[Seg {
            action: "jump",
            dur: 1.8,
            speed: 0.1,
            turn: 0.0,
        }],
        100.0,
        9,
        1.0,
    );
    let asm = run(&events, Some(&log));
    let p = &asm.placements[0];
    let n = p.end_frame - p.start_frame;
    let root = |f: usize| ground(asm.clip.frames[f].translations[0]);
    // DeepMimic's jump crouches for its first ~35 % and lands in its last ~20 %.
    let take_off = p.start_frame + n * 30 / 100;
    let landed = p.end_frame - n * 15 / 100;
    let before = (root(take_off) - root(p.start_frame)).length();
    let after = (root(p.end_frame) - root(landed)).length();
    let flight = (root(landed) - root(take_off)).length();
    eprintln!("jump: path {:.2} m; root moves {before:.3} m before take-off, {flight:.2} m in the air, {after:.3} m after landing", p.path.length());
    assert!(before < 0.1 && after < 0.1, "{before} {after}");
    assert!(flight > 0.8 * p.path.length(), "{flight}");
}

#[test]
fn unordered_overlapping_events_and_degenerate_doodles_still_animate() {
    if setup().is_none() {
        return;
    }
    let ev = |action: &str, start: f64, end: f64| ActionRecord {
        action: action.into(),
        start,
        end,
        time: f64::NAN,
        weight: 3.0,
        distance: 0,
    };
    // Out of order, overlapping, one with an absurd effort: sorted, chained, clamped.
    let events = vec![
        ev("kick", 2.0, 3.0),
        ev("walk", 0.0, 2.5),
        ev("punch", 2.9, 3.1),
    ];
    let one_sample = PoseLog {
        samples: vec![PoseSample {
            t: 0.0,
            pos: [0.0, 1.0, 0.0],
            quat: [1.0, 0.0, 0.0, 0.0],
        }],
    };
    for log in [None, Some(&one_sample), Some(&PoseLog::default())] {
        let asm = run(&events, log);
        let names: Vec<&str> = asm.placements.iter().map(|p| p.action.as_str()).collect();
        assert_eq!(names, ["walk", "kick", "punch"]);
        for w in asm.placements.windows(2) {
            assert!(
                w[1].start_frame >= w[0].end_frame,
                "{} overlaps {}",
                w[1].action,
                w[0].action
            );
        }
        assert!(asm
            .clip
            .frames
            .iter()
            .all(|p| p.translations.iter().all(|t| t.is_finite())));
        assert!(lowest_foot(&asm) >= -1e-3);
    }
}

#[test]
fn cli_reports_malformed_inputs_with_file_and_line() {
    let dir = out_dir();
    let bad_events = dir.join("bad_events.jsonl");
    std::fs::write(
        &bad_events,
        "{\"action\":\"walk\",\"start\":0,\"end\":1,\"time\":0,\"weight\":0,\"distance\":0}\n{\"action\":\"walk\",\"start\":\n",
    )
    .unwrap();
    let bad_lib = dir.join("bad_clips.json");
    std::fs::write(
        &bad_lib,
        "{\n  \"version\": 1,\n  \"actions\": {\n    \"walk\": { \"file\": }\n  }\n}\n",
    )
    .unwrap();
    let good_events = dir.join("good_events.jsonl");
    std::fs::write(
        &good_events,
        "{\"action\":\"walk\",\"start\":0,\"end\":1,\"time\":0,\"weight\":0,\"distance\":0}\n",
    )
    .unwrap();
    let bad_log = dir.join("bad_doodle.csv");
    std::fs::write(
        &bad_log,
        "t,x,y,z,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.1,zero,0,0,1,0,0,0\n",
    )
    .unwrap();
    let cases: [(Vec<&std::ffi::OsStr>, String); 3] = [
        (
            vec![bad_events.as_os_str()],
            format!("{}:2:", bad_events.display()),
        ),
        (
            vec![
                good_events.as_os_str(),
                "--clips".as_ref(),
                bad_lib.as_os_str(),
            ],
            format!("{}:4:", bad_lib.display()),
        ),
        (
            vec![
                good_events.as_os_str(),
                "--doodle".as_ref(),
                bad_log.as_os_str(),
            ],
            format!("{}:3:", bad_log.display()),
        ),
    ];
    for (args, expect) in cases {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_figurine"))
            .args(["animate", "--out"])
            .arg(dir.join("never.bvh"))
            .arg("--events")
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(err.contains(&expect), "expected {expect} in: {err}");
    }
}

#[test]
fn animate_recognises_a_log_itself() {
    if setup().is_none() {
        return;
    }
    let exe = env!("CARGO_BIN_EXE_figurine");
    let dir = out_dir().join("log_mode");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let run_ok = |args: &[&std::ffi::OsStr]| {
        let out = std::process::Command::new(exe).args(args).output().unwrap();
        assert!(
            out.status.success(),
            "{:?}: {}",
            args,
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let ex = dir.join("ex");
    let lib = dir.join("lib.json");
    let log = dir.join("jump.csv");
    let bvh = dir.join("jump.bvh");
    run_ok(&[
        "synth".as_ref(),
        "examples".as_ref(),
        "--action".as_ref(),
        "jump".as_ref(),
        "--seed".as_ref(),
        "1".as_ref(),
        "--out".as_ref(),
        ex.as_os_str(),
    ]);
    let mut learn: Vec<std::ffi::OsString> = vec![
        "learn".into(),
        "--library".into(),
        lib.clone().into(),
        "--name".into(),
        "jump".into(),
    ];
    for k in 1..=3 {
        learn.push(ex.join(format!("jump_{k}.csv")).into());
    }
    run_ok(&learn.iter().map(|s| s.as_os_str()).collect::<Vec<_>>());
    run_ok(&[
        "synth".as_ref(),
        "gesture".as_ref(),
        "--action".as_ref(),
        "jump".as_ref(),
        "--seed".as_ref(),
        "4".as_ref(),
        "--out".as_ref(),
        log.as_os_str(),
    ]);
    let stdout = run_ok(&[
        "animate".as_ref(),
        "--library".as_ref(),
        lib.as_os_str(),
        log.as_os_str(),
        "--out".as_ref(),
        bvh.as_os_str(),
    ]);
    eprintln!("{stdout}");
    assert!(stdout.contains("jump"), "{stdout}");
    let clip = figurine_host::motion::read_bvh_path(&bvh).unwrap().clip;
    assert!(clip.len() > 30);
}
