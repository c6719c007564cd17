//! Fuzzes the clip library (`figurine animate --clips LIB.json`): which clip files play which
//! action, cut, scaled, looped, mirrored or retargeted how. Any text gives a library or an
//! error naming its file, never a panic; a library that loads gives clips an animation can be
//! made of — frames to play, a positive frame time, finite joint offsets and translations —
//! and its actions (when its characters are person-sized, see `size_warnings`), played one
//! after another with strong and light effort in turn, assemble into a finite animation or an
//! error, as `figurine animate` would.
//!
//! The clips it names are read from a folder the target writes once: `a.bvh`, a small rig
//! walking, and `b.bvh`, the same rig swaying on the spot. An input naming a path with a folder
//! in it is skipped — which files a user's library may read is theirs to choose, and the
//! readers of those files have targets of their own (`bvh_import`, `deepmimic_import`).
#![no_main]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use figurine_host::anim::assemble::{assemble, AssembleOptions};
use figurine_host::anim::library::{size_warnings, ClipLibrary};
use figurine_host::events::ActionRecord;
use figurine_host::motion::Clip;
use libfuzzer_sys::fuzz_target;

/// The rig's joints: name, parent (index into this list), offset from it in centimetres.
/// Named as Mixamo names them, so every body role the variants' effort features need is found.
const JOINTS: [(&str, Option<usize>, [f32; 3]); 18] = [
    ("Hips", None, [0.0, 90.0, 0.0]),
    ("Spine", Some(0), [0.0, 10.0, 0.0]),
    ("Spine1", Some(1), [0.0, 15.0, 0.0]),
    ("Neck", Some(2), [0.0, 20.0, 0.0]),
    ("Head", Some(3), [0.0, 10.0, 0.0]),
    ("LeftArm", Some(2), [15.0, 15.0, 0.0]),
    ("LeftForeArm", Some(5), [25.0, 0.0, 0.0]),
    ("LeftHand", Some(6), [25.0, 0.0, 0.0]),
    ("RightArm", Some(2), [-15.0, 15.0, 0.0]),
    ("RightForeArm", Some(8), [-25.0, 0.0, 0.0]),
    ("RightHand", Some(9), [-25.0, 0.0, 0.0]),
    ("LeftUpLeg", Some(0), [10.0, 0.0, 0.0]),
    ("LeftLeg", Some(11), [0.0, -42.0, 0.0]),
    ("LeftFoot", Some(12), [0.0, -42.0, 0.0]),
    ("RightUpLeg", Some(0), [-10.0, 0.0, 0.0]),
    ("RightLeg", Some(14), [0.0, -42.0, 0.0]),
    ("RightFoot", Some(15), [0.0, -42.0, 0.0]),
    ("Tail", Some(0), [0.0, 0.0, -5.0]),
];

/// A BVH take of the rig: 12 frames at 30 Hz, the hips going `step` cm forward and swaying
/// `sway` cm a frame, the legs and arms swinging.
fn take(step: f32, sway: f32) -> String {
    fn joint(out: &mut String, i: usize, depth: usize) {
        let (name, parent, [x, y, z]) = JOINTS[i];
        let pad = "  ".repeat(depth);
        let kind = if parent.is_none() { "ROOT" } else { "JOINT" };
        let channels = if parent.is_none() {
            "6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
        } else {
            "3 Zrotation Xrotation Yrotation"
        };
        out.push_str(&format!(
            "{pad}{kind} {name}\n{pad}{{\n{pad}  OFFSET {x} {y} {z}\n{pad}  CHANNELS {channels}\n"
        ));
        let children: Vec<usize> = (0..JOINTS.len())
            .filter(|&c| JOINTS[c].1 == Some(i))
            .collect();
        if children.is_empty() {
            out.push_str(&format!(
                "{pad}  End Site\n{pad}  {{\n{pad}    OFFSET 0 5 0\n{pad}  }}\n"
            ));
        }
        for c in children {
            joint(out, c, depth + 1);
        }
        out.push_str(&format!("{pad}}}\n"));
    }
    let mut out = String::from("HIERARCHY\n");
    joint(&mut out, 0, 0);
    out.push_str("MOTION\nFrames: 12\nFrame Time: 0.0333333\n");
    for f in 0..12 {
        let phase = f as f32 * 0.5;
        let swing = 25.0 * phase.sin();
        let mut row = vec![
            sway * phase.sin(),
            90.0 + 2.0 * (2.0 * phase).sin(),
            step * f as f32,
        ];
        row.extend([0.0, 3.0 * phase.sin(), 0.0]);
        for (name, _, _) in &JOINTS[1..] {
            let x = match *name {
                "LeftUpLeg" | "RightArm" => swing,
                "RightUpLeg" | "LeftArm" => -swing,
                "LeftLeg" | "RightLeg" => 20.0 + 10.0 * phase.cos(),
                _ => 0.0,
            };
            row.extend([0.0, x, 0.0]);
        }
        let line: Vec<String> = row.iter().map(|v| format!("{v:.3}")).collect();
        out.push_str(&line.join(" "));
        out.push('\n');
    }
    out
}

/// The folder holding the clips (written on the first input).
fn clips_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("figurine-fuzz-clips-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a folder for the fuzz clips");
        std::fs::write(dir.join("a.bvh"), take(5.0, 0.0)).expect("a.bvh");
        // The same rig, another take: the hips sway on the spot.
        std::fs::write(dir.join("b.bvh"), take(0.0, 4.0)).expect("b.bvh");
        // Nothing else resolves: `KIND/NAME` clips would come from the data folder.
        std::env::set_var("FIGURINE_DATA_DIR", dir.join("no-data"));
        dir
    })
}

/// What a renderer relies on in a loaded clip.
fn check(clip: &Clip, what: &str) {
    assert!(!clip.frames.is_empty(), "{what}: no frames");
    assert!(
        clip.frame_time.is_finite() && clip.frame_time > 0.0,
        "{what}: frame time {}",
        clip.frame_time
    );
    for j in &clip.skeleton.joints {
        assert!(
            j.offset.is_finite(),
            "{what}: joint {} offset {}",
            j.name,
            j.offset
        );
    }
    for (i, p) in clip.frames.iter().enumerate() {
        assert_eq!(
            p.translations.len(),
            clip.skeleton.len(),
            "{what}: frame {i}"
        );
        assert_eq!(p.rotations.len(), clip.skeleton.len(), "{what}: frame {i}");
        for t in &p.translations {
            assert!(t.is_finite(), "{what}: frame {i} translation {t}");
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let dir = clips_dir();
    let lib = match ClipLibrary::parse(text, Path::new("LIB.json"), Some(dir.to_path_buf())) {
        Ok(lib) => lib,
        Err(e) => {
            assert!(e.to_string().contains("LIB.json"), "{e}");
            return;
        }
    };
    // Checked on the parsed names: JSON may spell a slash `\u002f`.
    let named = lib
        .actions
        .values()
        .flat_map(|e| e.variants.iter().map(|v| &v.file));
    if named
        .chain(lib.skeleton.iter().map(|s| &s.file))
        .any(|f| f.contains(['/', '\\']))
    {
        return;
    }
    let _ = lib.forward();
    let names: Vec<String> = lib.actions.keys().cloned().collect();
    let Ok(loaded) = lib.load(names.iter().map(String::as_str)) else {
        return;
    };
    for (action, ac) in &loaded {
        for v in ac.variants() {
            check(&v.clip, &format!("{action} / {}", v.variant));
            if let Some(m) = &v.mirrored {
                check(&m.clip, &format!("{action} / {} mirrored", v.variant));
            }
        }
    }
    // A character `animate` warns is not person-sized is slowed to a person's speed: a clip
    // read 100 times too large animates for minutes of frames, which this target would spend
    // its time (and the 10 s an input may take) on.
    if !size_warnings(&loaded).is_empty() {
        return;
    }
    let events: Vec<ActionRecord> = loaded
        .keys()
        .enumerate()
        .map(|(i, action)| {
            let sign = if i % 2 == 0 { 0.8 } else { -0.8 };
            ActionRecord {
                action: action.clone(),
                start: 1.5 * i as f64,
                end: 1.5 * i as f64 + 1.0,
                time: sign,
                weight: -sign,
                distance: 0,
            }
        })
        .collect();
    if let Ok(asm) = assemble(
        &events,
        None,
        &loaded,
        lib.forward(),
        &AssembleOptions::default(),
    ) {
        check(&asm.clip, "the animation");
    }
});
