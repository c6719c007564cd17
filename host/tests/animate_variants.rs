//! Clip variants chosen by the recognised effort, and looping clips wrapped seamlessly when an
//! action outlasts its clip.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use figurine_host::anim::assemble::{assemble, AssembleOptions, Assembly};
use figurine_host::anim::library::{ActionClip, ClipLibrary};
use figurine_host::events::ActionRecord;
use figurine_host::motion::{Clip, Joint, Pose, Skeleton};
use glam::{Quat, Vec2, Vec3};

fn have_data() -> bool {
    if figurine_host::data::data_file("deepmimic", "humanoid.urdf").is_none() {
        eprintln!("skipping: deepmimic data missing — run `cargo xtask setup`");
        return false;
    }
    true
}

fn event(action: &str, start: f64, end: f64, time: f64, weight: f64) -> ActionRecord {
    ActionRecord {
        action: action.into(),
        start,
        end,
        time,
        weight,
        distance: 0,
    }
}

fn run(lib: &ClipLibrary, events: &[ActionRecord]) -> Assembly {
    let clips = lib.load(events.iter().map(|e| e.action.as_str())).unwrap();
    assemble(
        events,
        None,
        &clips,
        lib.forward(),
        &AssembleOptions::default(),
    )
    .unwrap()
}

/// Root ground positions of frames `a..=b`.
fn root_path(asm: &Assembly, a: usize, b: usize) -> Vec<Vec2> {
    asm.clip.frames[a..=b]
        .iter()
        .map(|p| Vec2::new(p.translations[0].x, p.translations[0].z))
        .collect()
}

/// Largest change of any non-root joint's local rotation between consecutive frames
/// `a..=b`, degrees.
fn joint_steps(asm: &Assembly, a: usize, b: usize) -> f32 {
    asm.clip.frames[a..=b]
        .windows(2)
        .flat_map(|w| {
            w[0].rotations
                .iter()
                .zip(&w[1].rotations)
                .skip(1)
                .map(|(p, q)| p.angle_between(*q).to_degrees())
        })
        .fold(0.0, f32::max)
}

/// Largest backwards step along `dir` and largest step length between consecutive frames, m.
fn steps(path: &[Vec2], dir: Vec2) -> (f32, f32) {
    let mut back = 0.0f32;
    let mut longest = 0.0f32;
    for w in path.windows(2) {
        let d = w[1] - w[0];
        back = back.max(-d.dot(dir));
        longest = longest.max(d.length());
    }
    (back, longest)
}

#[test]
fn sudden_strong_and_sustained_light_kicks_play_different_variants() {
    if !have_data() {
        return;
    }
    let lib = ClipLibrary::default_library().unwrap();
    let events = [
        event("kick", 0.0, 1.6, 0.8, 0.8),
        event("kick", 2.5, 4.1, -0.8, -0.8),
        event("punch", 5.0, 6.0, 0.8, 0.8),
    ];
    let asm = run(&lib, &events);
    let v: Vec<Option<String>> = asm
        .placements
        .iter()
        .map(|p| p.variant.as_ref().map(|v| v.name.clone()))
        .collect();
    assert_eq!(
        v,
        [Some("spinkick".into()), Some("kick".into()), None],
        "variants played"
    );
    let strong = asm.placements[0].variant.as_ref().unwrap();
    let light = asm.placements[1].variant.as_ref().unwrap();
    assert!(strong.variant_effort.time > 0.0 && strong.variant_effort.weight > 0.0);
    assert!(light.variant_effort.time < 0.0 && light.variant_effort.weight < 0.0);
    // The variant carries most of the effort; only the rest is transferred onto it.
    for (p, want) in asm.placements.iter().zip([0.8f32, -0.8]) {
        let v = p.variant.as_ref().unwrap();
        let a = p.applied_effort;
        assert!(
            (a.time - (want - v.variant_effort.time)).abs() < 1e-6,
            "{a:?}"
        );
        assert!(
            a.time.abs() < want.abs() && a.weight.abs() < want.abs(),
            "{a:?}"
        );
    }
    // A single-clip action gets the whole recognised effort.
    assert_eq!(asm.placements[2].applied_effort.time, 0.8);
    // Deterministic: the same events give the same animation, bit for bit.
    let again = run(&lib, &events);
    assert_eq!(asm.clip.frames, again.clip.frames);
}

#[test]
fn a_long_walk_wraps_its_cycle_forward() {
    if !have_data() {
        return;
    }
    let lib = ClipLibrary::default_library().unwrap();
    let asm = run(&lib, &[event("walk", 0.0, 6.0, 0.0, 0.0)]);
    let p = &asm.placements[0];
    assert!(p.cycles >= 4, "{} cycles in 6 s", p.cycles);
    let path = root_path(&asm, p.start_frame, p.end_frame);
    let (back, longest) = steps(&path, Vec2::X);
    assert!(back < 1e-3, "root steps back {back} m along the walk");
    assert!(longest < 0.1, "root jumps {longest} m in one frame");
    // DeepMimic's walk cycle does not close (its last pose is 28° from its first at the right
    // shoulder; unclosed, the wrap turns it 28.8° in one frame): closed over the cycle, the
    // wraps turn no joint more than the clip's own stepping does (knees: up to 17° a frame).
    let n = p.end_frame - p.start_frame;
    for k in 1..p.cycles {
        let seam = p.start_frame + (k * n + p.cycles / 2) / p.cycles;
        let pop = joint_steps(&asm, seam - 2, seam + 2);
        eprintln!("walk: wrap {k} at frame {seam}: largest joint step {pop:.1}°");
        assert!(pop < 18.0, "wrap {k}: a joint turns {pop}° in one frame");
    }
    let travel = path[path.len() - 1].x - path[0].x;
    assert!(
        travel > 1.0 * p.cycles as f32,
        "{travel} m in {} cycles",
        p.cycles
    );
}

/// A library playing DeepMimic's looping walk on the spot (not along a path), with and
/// without its loop.
fn march_library(dir: &Path) -> ClipLibrary {
    let text = r#"{ "version": 1,
      "skeleton": { "format": "deepmimic-urdf", "file": "deepmimic/humanoid.urdf" },
      "actions": {
        "march": { "file": "deepmimic/humanoid3d_walk.txt", "moving": false, "cyclic": false },
        "march_once": { "file": "deepmimic/humanoid3d_walk.txt", "moving": false,
                        "cyclic": false, "loop": false } } }"#;
    let p = dir.join("march.json");
    std::fs::write(&p, text).unwrap();
    ClipLibrary::read_path(&p).unwrap()
}

#[test]
fn a_looping_clip_in_place_continues_from_where_it_ended() {
    if !have_data() {
        return;
    }
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("animate_variants");
    std::fs::create_dir_all(&dir).unwrap();
    let lib = march_library(&dir);
    let asm = run(&lib, &[event("march", 0.0, 4.0, 0.0, 0.0)]);
    let p = &asm.placements[0];
    assert_eq!(p.cycles, 3, "4 s of a 1.27 s loop");
    let path = root_path(&asm, p.start_frame, p.end_frame);
    let (back, longest) = steps(&path, Vec2::X);
    assert!(back < 1e-3, "root steps back {back} m across a wrap");
    assert!(longest < 0.1, "root jumps {longest} m in one frame");
    let travel = path[path.len() - 1].x - path[0].x;
    assert!(
        travel > 3.0 * 1.1,
        "three cycles carried forward: {travel} m"
    );
    // `"loop": false`: one cycle, slowed down to fill the action.
    let once = run(&lib, &[event("march_once", 0.0, 4.0, 0.0, 0.0)]);
    assert_eq!(once.placements[0].cycles, 1);
}

/// A looping clip built in code: the root advances 1 m per cycle along +X with a bob, and
/// turns nothing; `frames` frames at 30 fps.
fn synthetic_loop(frames: usize) -> ActionClip {
    let j = Joint::bare;
    let skeleton = Skeleton {
        joints: vec![
            j("root", None, Vec3::ZERO),
            j("spine", Some(0), Vec3::new(0.0, 0.5, 0.0)),
        ],
    };
    let frames: Vec<Pose> = (0..frames)
        .map(|k| {
            let u = k as f32 / (frames - 1) as f32;
            let mut p = Pose::rest(&skeleton);
            // Uneven progress within the cycle (fast then slow), like a stride.
            let x = u + 0.1 * (std::f32::consts::TAU * u).sin();
            p.translations[0] =
                Vec3::new(x, 0.9 + 0.03 * (std::f32::consts::TAU * 2.0 * u).cos(), 0.0);
            // A loop that does not close: the spine ends 20° away from where it starts.
            p.rotations[1] = Quat::from_rotation_z(0.35 * u);
            p
        })
        .collect();
    let clip = Clip {
        name: "stride".into(),
        skeleton,
        frame_time: 1.0 / 30.0,
        frames,
    };
    ActionClip {
        action: "stride".into(),
        variant: "stride".into(),
        moving: false,
        cyclic: false,
        looping: true,
        anchor: false,
        file: PathBuf::from("stride.bvh"),
        source_start_s: Some(0.0),
        source_span_s: (0.0, clip.duration()),
        clip,
        effort: None,
        alternatives: Vec::new(),
        ranges: None,
        mirrored: None,
    }
}

#[test]
fn a_synthetic_loop_wraps_without_snapping_back() {
    // A 4-s stride event over whatever clip the library holds for it.
    let play = |clips: &BTreeMap<_, _>| {
        assemble(
            &[event("stride", 0.0, 4.0, 0.0, 0.0)],
            None,
            clips,
            Vec3::X,
            &AssembleOptions::default(),
        )
        .unwrap()
    };
    let mut clips = BTreeMap::new();
    clips.insert("stride".to_string(), synthetic_loop(31));
    let asm = play(&clips);
    let p = &asm.placements[0];
    assert_eq!(p.cycles, 4, "4 s of a 1 s loop");
    let path = root_path(&asm, p.start_frame, p.end_frame);
    let (back, longest) = steps(&path, Vec2::X);
    assert!(back < 1e-4, "root steps back {back} m");
    assert!(longest < 0.1, "root jumps {longest} m in one frame");
    // By the end of the hold: the root eases to a stop over the join with the held pose
    // (`ROOT_EASE_S`), so the action's last frame is a few centimetres short of it.
    let whole = root_path(&asm, p.start_frame, asm.clip.len() - 1);
    let travel = whole[whole.len() - 1].x - whole[0].x;
    assert!((travel - 4.0).abs() < 0.05, "4 cycles of 1 m: {travel} m");
    // The spine's 20° mismatch is spread over each cycle: no pop at the wraps.
    let pop = joint_steps(&asm, p.start_frame, p.end_frame);
    assert!(pop < 2.0, "a joint turns {pop}° in one frame");
    // Without the loop the same event plays the clip once, slowly.
    let mut once = synthetic_loop(31);
    once.looping = false;
    clips.insert("stride".to_string(), once);
    let slow = play(&clips);
    let p = &slow.placements[0];
    let path = root_path(&slow, p.start_frame, p.end_frame);
    assert!((path[path.len() - 1].x - path[0].x - 1.0).abs() < 0.05);
}

#[test]
fn with_a_motion_graph_the_graph_effort_picks_the_variant() {
    use figurine_host::anim::graph_cuts::GraphGuide;
    use figurine_host::anim::variants::choose_variant;
    use figurine_host::graph::effort::Effort;
    use figurine_host::graph::roles::RoleOverrides;
    use figurine_host::graph::source::load_clips;
    use figurine_host::graph::{build_graph, BuildParams};
    if !have_data() {
        return;
    }
    let dir = figurine_host::data::data_dir().join("deepmimic");
    let files: Vec<PathBuf> = ["kick", "spinkick", "walk", "punch"]
        .iter()
        .map(|n| dir.join(format!("humanoid3d_{n}.txt")))
        .collect();
    let clips = load_clips(&files, &RoleOverrides::new()).unwrap();
    let (g, _) = build_graph(&clips, &BuildParams::default()).unwrap();
    let guide = GraphGuide::new(g);
    let lib = ClipLibrary::default_library().unwrap();
    let loaded = lib.load(["kick", "jump"]).unwrap();
    let kick = &loaded["kick"];
    let e = |v: f32| Effort { time: v, weight: v };
    let (strong, cs) = choose_variant(kick, e(0.8), Some(&guide));
    let (light, cl) = choose_variant(kick, e(-0.8), Some(&guide));
    let (cs, cl) = (cs.unwrap(), cl.unwrap());
    eprintln!(
        "graph: strong → {} {cs:?}; light → {} {cl:?}",
        strong.variant, light.variant
    );
    assert!(cs.by_graph && cl.by_graph);
    assert_eq!(
        (strong.variant.as_str(), light.variant.as_str()),
        ("spinkick", "kick")
    );
    // The jump's backflip is not in this graph: its variants fall back to their own features.
    let (_, cj) = choose_variant(&loaded["jump"], e(0.8), Some(&guide));
    assert!(!cj.unwrap().by_graph);
}

/// The shipped LAFAN1 library: three real gait cycles and three dance stretches of different
/// vigour.
#[test]
fn lafan_walk_variants_follow_vigour_and_loop_seamlessly() {
    if figurine_host::data::data_file("bvh", "lafan_test.bvh").is_none()
        || figurine_host::data::data_file("bvh", "lafan_dance1.bvh").is_none()
    {
        eprintln!("skipping: LAFAN1 BVH files missing — run `cargo xtask setup`");
        return;
    }
    let lib = ClipLibrary::read_path(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/lafan_clips.json"
    )))
    .unwrap();
    let walk = &lib.load(["walk"]).unwrap()["walk"];
    let speed = |c: &ActionClip| {
        let r = c.clip.root_path();
        let d = r[r.len() - 1] - r[0];
        Vec2::new(d.x, d.z).length() / c.clip.duration()
    };
    let mut by_speed: Vec<&ActionClip> = walk.variants().collect();
    by_speed.sort_by(|a, b| speed(a).total_cmp(&speed(b)));
    let order: Vec<&str> = by_speed.iter().map(|c| c.variant.as_str()).collect();
    assert_eq!(order, ["stroll", "walk", "stride"]);
    // The LMA Weight estimate rises with the walk's speed.
    let w: Vec<f32> = by_speed.iter().map(|c| c.effort.unwrap().weight).collect();
    assert!(w[0] < w[1] && w[1] < w[2], "weights {w:?}");
    let events = [
        event("walk", 0.0, 4.0, -0.8, -0.8),
        event("walk", 4.5, 8.5, 0.8, 0.8),
    ];
    let asm = run(&lib, &events);
    let names: Vec<&str> = asm
        .placements
        .iter()
        .map(|p| p.variant.as_ref().unwrap().name.as_str())
        .collect();
    assert_eq!(names, ["stroll", "stride"]);
    // The dance stretches standing in for a wave: the calmest and the wildest.
    let wave = &lib.load(["wave"]).unwrap()["wave"];
    let pick = |v: f32| {
        let e = figurine_host::graph::effort::Effort { time: v, weight: v };
        figurine_host::anim::variants::choose_variant(wave, e, None)
            .0
            .variant
            .clone()
    };
    assert_eq!((pick(0.8), pick(-0.8)), ("wild".into(), "sway".into()));
    for p in &asm.placements {
        assert!(p.cycles >= 2);
        let path = root_path(&asm, p.start_frame, p.end_frame);
        let dir = (path[path.len() - 1] - path[0]).normalize();
        let (back, longest) = steps(&path, dir);
        assert!(back < 0.01 && longest < 0.15, "{back} {longest}");
    }
}

#[test]
fn clip_variants_lists_what_each_effort_plays() {
    if !have_data() {
        return;
    }
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_figurine"))
        .args(["clip", "variants"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("sudden-strong → spinkick") && text.contains("sustained-light → kick"),
        "{text}"
    );
    // A malformed variant list: the error names the file and line.
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("animate_variants");
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("empty_variants.json");
    std::fs::write(&bad, "{ \"version\": 1,\n\"actions\": { \"kick\": [] } }").unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_figurine"))
        .args(["clip", "variants", "--clips"])
        .arg(&bad)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("empty_variants.json:2:") && err.contains("empty variant list"),
        "{err}"
    );
}
