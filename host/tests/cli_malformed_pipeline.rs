//! Malformed input to the later pipeline commands — `train-effort`, `animate`,
//! `graph build|synth|eval`, `upload`, `replay`: a clear error naming the file (or folder, or
//! port), exit status 1, never a panic or a backtrace, and quickly (a malformed file fails
//! fast). None of these tests needs the fetched data: valid fixtures are generated here.

mod malformed;

use std::io::{Read, Write};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use malformed::{assert_clean_failure, bad_files, name_of, scratch, write_ok_log, MAX_REFUSAL};

/// The four state folders `train-effort` expects.
const STATES: [&str; 4] = [
    "sudden-strong",
    "sudden-light",
    "sustained-strong",
    "sustained-light",
];

/// A valid BVH of a 22-joint humanoid with Mixamo-style names, `frames` frames at 30 fps,
/// swinging its limbs (centimetres, as BVH files usually are).
fn humanoid_bvh(frames: usize) -> String {
    // (name, parent index, offset); every joint has 3 rotation channels, the root 6.
    let joints: [(&str, Option<usize>, [f32; 3]); 18] = [
        ("Hips", None, [0.0, 95.0, 0.0]),
        ("Spine", Some(0), [0.0, 10.0, 0.0]),
        ("Spine1", Some(1), [0.0, 15.0, 0.0]),
        ("Neck", Some(2), [0.0, 20.0, 0.0]),
        ("Head", Some(3), [0.0, 10.0, 0.0]),
        ("LeftArm", Some(2), [18.0, 15.0, 0.0]),
        ("LeftForeArm", Some(5), [28.0, 0.0, 0.0]),
        ("LeftHand", Some(6), [25.0, 0.0, 0.0]),
        ("RightArm", Some(2), [-18.0, 15.0, 0.0]),
        ("RightForeArm", Some(8), [-28.0, 0.0, 0.0]),
        ("RightHand", Some(9), [-25.0, 0.0, 0.0]),
        ("LeftUpLeg", Some(0), [9.0, -5.0, 0.0]),
        ("LeftLeg", Some(11), [0.0, -42.0, 0.0]),
        ("LeftFoot", Some(12), [0.0, -40.0, 0.0]),
        ("RightUpLeg", Some(0), [-9.0, -5.0, 0.0]),
        ("RightLeg", Some(14), [0.0, -42.0, 0.0]),
        ("RightFoot", Some(15), [0.0, -40.0, 0.0]),
        ("LeftToeBase", Some(13), [0.0, -5.0, 12.0]),
    ];
    fn write_joint(out: &mut String, joints: &[(&str, Option<usize>, [f32; 3])], j: usize) {
        let (name, parent, o) = joints[j];
        let kw = if parent.is_none() { "ROOT" } else { "JOINT" };
        let ch = if parent.is_none() {
            "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
        } else {
            "CHANNELS 3 Zrotation Xrotation Yrotation"
        };
        out.push_str(&format!(
            "{kw} {name}\n{{\nOFFSET {} {} {}\n{ch}\n",
            o[0], o[1], o[2]
        ));
        let children: Vec<usize> = (0..joints.len())
            .filter(|&c| joints[c].1 == Some(j))
            .collect();
        if children.is_empty() {
            out.push_str("End Site\n{\nOFFSET 0 -5 0\n}\n");
        }
        for c in children {
            write_joint(out, joints, c);
        }
        out.push_str("}\n");
    }
    let mut text = String::from("HIERARCHY\n");
    write_joint(&mut text, &joints, 0);
    text.push_str(&format!(
        "MOTION\nFrames: {frames}\nFrame Time: 0.0333333\n"
    ));
    // Frame values in the hierarchy's depth-first order (the order written above).
    let mut order = Vec::new();
    fn dfs(joints: &[(&str, Option<usize>, [f32; 3])], j: usize, order: &mut Vec<usize>) {
        order.push(j);
        for c in (0..joints.len()).filter(|&c| joints[c].1 == Some(j)) {
            dfs(joints, c, order);
        }
    }
    dfs(&joints, 0, &mut order);
    for f in 0..frames {
        let ph = f as f32 * 0.21;
        let mut vals = vec![0.0, 95.0 + 3.0 * (2.0 * ph).sin(), f as f32 * 2.0];
        for &j in &order {
            let swing = match joints[j].0 {
                "LeftUpLeg" | "RightArm" => 30.0 * ph.sin(),
                "RightUpLeg" | "LeftArm" => -30.0 * ph.sin(),
                "LeftLeg" | "RightLeg" => 20.0 + 20.0 * ph.cos(),
                "LeftForeArm" | "RightForeArm" => 15.0 * (ph * 1.7).sin(),
                _ => 3.0 * (ph * 0.5).sin(),
            };
            vals.extend([0.0, swing, 0.0]);
        }
        let line: Vec<String> = vals.iter().map(|v| format!("{v:.3}")).collect();
        text.push_str(&line.join(" "));
        text.push('\n');
    }
    text
}

/// One valid event line for action `action` from `start` to `end` seconds.
fn event(action: &str, start: f64, end: f64) -> String {
    format!(
        r#"{{"action":"{action}","start":{start},"end":{end},"time":0.5,"weight":-0.5,"distance":0}}"#
    )
}

/// A clip library mapping `jump` onto `clip_file` (relative to the library).
fn clip_library(clip_file: &str, extra: &str) -> String {
    format!(
        r#"{{"version":1,"forward":[0,0,1],"actions":{{"jump":{{"file":"{clip_file}","moving":true,"cyclic":false{extra}}}}}}}"#
    )
}

/// Writes `n` valid one-gesture logs into each state folder of `root`.
fn effort_tree(root: &Path, n: usize) {
    for (s, state) in STATES.iter().enumerate() {
        let d = root.join(state);
        std::fs::create_dir_all(&d).unwrap();
        for k in 0..n {
            write_ok_log(&d.join(format!("g{k}.csv")), 1.0 + 0.2 * (s + k) as f64);
        }
    }
}

#[test]
fn train_effort_refuses_bad_folders_and_files() {
    let dir = scratch("effort");
    let out = dir.join("effort.json");
    let run = |d: &Path, named: &str, case: &str| {
        assert_clean_failure(
            &[
                "train-effort".as_ref(),
                "--out".as_ref(),
                out.as_os_str(),
                d.as_os_str(),
            ],
            named,
            case,
        );
    };

    run(&dir.join("no-such-dir"), "no-such-dir", "missing folder");
    let empty = dir.join("empty-dir");
    std::fs::create_dir_all(&empty).unwrap();
    run(&empty, "empty-dir", "empty folder");
    let file = dir.join("a-file");
    std::fs::write(&file, "t,x\n").unwrap();
    run(&file, "a-file", "a file, not a folder");

    // Only some classes present: the error names the missing class folder.
    let partial = dir.join("partial");
    effort_tree(&partial, 1);
    std::fs::remove_dir_all(partial.join("sustained-light")).unwrap();
    run(&partial, "sustained-light", "missing class folder");

    // All class folders present but empty, or holding only logs without motion.
    let hollow = dir.join("hollow-tree");
    for state in STATES {
        std::fs::create_dir_all(hollow.join(state)).unwrap();
    }
    run(&hollow, "hollow-tree", "empty class folders");
    let still = dir.join("still-tree");
    for state in STATES {
        std::fs::create_dir_all(still.join(state)).unwrap();
        std::fs::write(
            still.join(state).join("still.csv"),
            "t,x,y,z,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.01,0,0,0,1,0,0,0\n0.02,0,0,0,1,0,0,0\n",
        )
        .unwrap();
    }
    run(&still, "still-tree", "logs without motion");

    // A malformed CSV among valid ones: the error names that file.
    let junk_src = dir.join("junk");
    std::fs::create_dir_all(&junk_src).unwrap();
    for (case, bad) in bad_files(&junk_src, "csv") {
        if case == "missing" {
            continue;
        }
        let tree = dir.join(format!("tree-{case}"));
        effort_tree(&tree, 1);
        let target = tree.join("sudden-light").join(name_of(&bad));
        if bad.is_dir() {
            std::fs::create_dir_all(&target).unwrap();
        } else {
            std::fs::copy(&bad, &target).unwrap();
        }
        run(&tree, &name_of(&bad), &case);
    }
}

#[test]
fn animate_refuses_bad_events_doodles_labels_and_clip_libraries() {
    let dir = scratch("animate");
    let out = dir.join("out.bvh");
    let doodle = dir.join("doodle.csv");
    write_ok_log(&doodle, 3.0);
    let events = dir.join("events.jsonl");
    std::fs::write(&events, event("jump", 0.5, 1.5) + "\n").unwrap();
    let clip = dir.join("clip.bvh");
    std::fs::write(&clip, humanoid_bvh(40)).unwrap();
    let clips = dir.join("clips.json");
    std::fs::write(&clips, clip_library("clip.bvh", "")).unwrap();
    let animate = |extra: &[&Path], flags: &[&str], named: &str, case: &str| {
        let mut args: Vec<std::ffi::OsString> = vec!["animate".into()];
        for (flag, p) in flags.iter().zip(extra) {
            args.push(flag.into());
            args.push(p.as_os_str().into());
        }
        args.push("--out".into());
        args.push(out.as_os_str().into());
        assert_clean_failure(&args, named, case);
    };

    for (case, bad) in bad_files(&dir, "jsonl") {
        animate(
            &[&bad, &doodle, &clips],
            &["--events", "--doodle", "--clips"],
            &name_of(&bad),
            &case,
        );
    }
    let backwards = dir.join("backwards.jsonl");
    std::fs::write(&backwards, event("jump", 2.0, 1.0)).unwrap();
    animate(
        &[&backwards, &doodle, &clips],
        &["--events", "--doodle", "--clips"],
        "backwards.jsonl",
        "end before start",
    );
    for (case, bad) in bad_files(&dir, "csv") {
        animate(
            &[&events, &bad, &clips],
            &["--events", "--doodle", "--clips"],
            &name_of(&bad),
            &case,
        );
    }
    for (case, bad) in bad_files(&dir, "json") {
        animate(
            &[&events, &doodle, &bad],
            &["--events", "--doodle", "--clips"],
            &name_of(&bad),
            &case,
        );
        animate(
            &[&bad, &doodle, &clips],
            &["--labels", "--doodle", "--clips"],
            &name_of(&bad),
            &case,
        );
    }
    // A valid clip library whose clip is malformed or missing: the error names the clip.
    for (case, bad) in bad_files(&dir, "bvh") {
        let lib = dir.join(format!("lib-{case}.json"));
        std::fs::write(&lib, clip_library(&name_of(&bad), "")).unwrap();
        animate(
            &[&events, &doodle, &lib],
            &["--events", "--doodle", "--clips"],
            &name_of(&bad),
            &case,
        );
    }
    // A frame range outside the clip, an action the library lacks.
    let range = dir.join("lib-range.json");
    std::fs::write(&range, clip_library("clip.bvh", r#","frames":[5000,6000]"#)).unwrap();
    animate(
        &[&events, &doodle, &range],
        &["--events", "--doodle", "--clips"],
        "lib-range.json",
        "frame range outside the clip",
    );
    let other = dir.join("other-action.jsonl");
    std::fs::write(&other, event("cartwheel", 0.5, 1.5)).unwrap();
    animate(
        &[&other, &doodle, &clips],
        &["--events", "--doodle", "--clips"],
        "clips.json",
        "action missing from the clip library",
    );
}

#[test]
fn animate_refuses_events_with_absurd_times() {
    let dir = scratch("animate-huge");
    let out = dir.join("out.bvh");
    let doodle = dir.join("doodle.csv");
    write_ok_log(&doodle, 3.0);
    std::fs::write(dir.join("clip.bvh"), humanoid_bvh(40)).unwrap();
    let clips = dir.join("clips.json");
    std::fs::write(&clips, clip_library("clip.bvh", "")).unwrap();
    for (case, start, end) in [
        ("a year long", 0.5, 3.2e7),
        ("far in the future", 1e15, 1e15 + 1.0),
        ("far in the past", -1e15, 1.0),
    ] {
        let events = dir.join("huge.jsonl");
        std::fs::write(&events, event("jump", start, end)).unwrap();
        let mut args: Vec<std::ffi::OsString> = vec!["animate".into(), "--events".into()];
        args.extend([events.as_os_str().into(), "--doodle".into()]);
        args.extend([doodle.as_os_str().into(), "--clips".into()]);
        args.extend([
            clips.as_os_str().into(),
            "--out".into(),
            out.as_os_str().into(),
        ]);
        assert_clean_failure(&args, "huge.jsonl", case);
    }
}

#[test]
fn animate_warns_of_a_clip_read_in_the_wrong_unit() {
    let dir = scratch("animate-unit");
    let doodle = dir.join("doodle.csv");
    write_ok_log(&doodle, 3.0);
    let events = dir.join("events.jsonl");
    std::fs::write(&events, event("jump", 0.5, 1.5) + "\n").unwrap();
    std::fs::write(dir.join("clip.bvh"), humanoid_bvh(40)).unwrap();
    let clips = dir.join("clips.json");
    let out = dir.join("out.bvh");
    let stderr_with = |extra: &str| {
        std::fs::write(&clips, clip_library("clip.bvh", extra)).unwrap();
        let done = malformed::figurine()
            .arg("animate")
            .arg("--events")
            .arg(&events)
            .arg("--doodle")
            .arg(&doodle)
            .arg("--clips")
            .arg(&clips)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&done.stderr).into_owned();
        assert!(done.status.success(), "{extra}: {stderr}");
        stderr
    };
    // The fixture is in centimetres, as BVH's default scale has it.
    let fine = stderr_with("");
    assert!(!fine.contains("warning"), "{fine}");
    // Read as metres: still animated, with a warning naming the library, clip and height.
    let metres = stderr_with(r#","scale":1"#);
    assert!(
        metres.contains("warning: ")
            && metres.contains("clips.json")
            && metres.contains("clip.bvh")
            && metres.contains("m tall"),
        "{metres}"
    );
}

/// Builds a small valid graph from generated clips; returns its path.
fn small_graph(dir: &Path) -> PathBuf {
    let clips = dir.join("clips");
    std::fs::create_dir_all(&clips).unwrap();
    std::fs::write(clips.join("walk_a.bvh"), humanoid_bvh(90)).unwrap();
    std::fs::write(clips.join("walk_b.bvh"), humanoid_bvh(70)).unwrap();
    let g = dir.join("g.bin");
    let out = malformed::figurine()
        .args(["graph", "build", "--quiet", "--out"])
        .arg(&g)
        .arg(&clips)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "graph build of generated clips: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    g
}

#[test]
fn graph_build_refuses_junk_clips() {
    let dir = scratch("graph-build");
    let g = dir.join("g.bin");
    for (case, bad) in bad_files(&dir, "bvh") {
        assert_clean_failure(
            &[
                "graph".as_ref(),
                "build".as_ref(),
                "--out".as_ref(),
                g.as_os_str(),
                bad.as_os_str(),
            ],
            &name_of(&bad),
            &case,
        );
    }
    // A folder with one junk clip among good ones.
    let folder = dir.join("folder");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("good.bvh"), humanoid_bvh(60)).unwrap();
    std::fs::write(
        folder.join("junk.bvh"),
        "HIERARCHY\nROOT a\n{\nOFFSET 0 0\n",
    )
    .unwrap();
    assert_clean_failure(
        &[
            "graph".as_ref(),
            "build".as_ref(),
            "--out".as_ref(),
            g.as_os_str(),
            folder.as_os_str(),
        ],
        "junk.bvh",
        "junk clip in a folder",
    );
    // Nothing usable: an empty folder; only clips shorter than a window.
    let empty = dir.join("empty-folder");
    std::fs::create_dir_all(&empty).unwrap();
    assert_clean_failure(
        &[
            "graph".as_ref(),
            "build".as_ref(),
            "--out".as_ref(),
            g.as_os_str(),
            empty.as_os_str(),
        ],
        "empty-folder",
        "empty folder",
    );
    let short = dir.join("short.bvh");
    std::fs::write(&short, humanoid_bvh(3)).unwrap();
    assert_clean_failure(
        &[
            "graph".as_ref(),
            "build".as_ref(),
            "--out".as_ref(),
            g.as_os_str(),
            short.as_os_str(),
        ],
        "short.bvh",
        "only a too-short clip",
    );
}

#[test]
fn graph_synth_and_eval_refuse_bad_graphs_and_labels() {
    let dir = scratch("graph-use");
    let g = small_graph(&dir);
    let bytes = std::fs::read(&g).unwrap();
    let out = dir.join("out.bvh");
    let labels = dir.join("labels.json");
    std::fs::write(&labels, r#"{"walk_a":"calm","walk_b":"lively"}"#).unwrap();

    let mut graphs = bad_files(&dir, "bin");
    for (case, cut) in [("cut-header", 4), ("cut-half", bytes.len() / 2)] {
        let p = dir.join(format!("{case}.bin"));
        std::fs::write(&p, &bytes[..cut]).unwrap();
        graphs.push((case.into(), p));
    }
    let flipped = dir.join("flipped.bin");
    let mut f = bytes.clone();
    for b in f.iter_mut().skip(8).step_by(7) {
        *b ^= 0xA5;
    }
    std::fs::write(&flipped, f).unwrap();
    graphs.push(("flipped bits".into(), flipped));
    for (case, bad) in &graphs {
        let named = name_of(bad);
        assert_clean_failure(
            &[
                "graph".as_ref(),
                "synth".as_ref(),
                bad.as_os_str(),
                "--out".as_ref(),
                out.as_os_str(),
            ],
            &named,
            case,
        );
        assert_clean_failure(
            &[
                "graph".as_ref(),
                "eval".as_ref(),
                bad.as_os_str(),
                "--labels".as_ref(),
                labels.as_os_str(),
            ],
            &named,
            case,
        );
    }

    let mut bad_labels = bad_files(&dir, "json");
    let partial = dir.join("partial-labels.json");
    std::fs::write(&partial, r#"{"walk_a":"calm"}"#).unwrap();
    bad_labels.push(("a clip without a label".into(), partial));
    let wrong_type = dir.join("list-labels.json");
    std::fs::write(&wrong_type, r#"["calm","lively"]"#).unwrap();
    bad_labels.push(("a list, not an object".into(), wrong_type));
    for (case, bad) in &bad_labels {
        assert_clean_failure(
            &[
                "graph".as_ref(),
                "eval".as_ref(),
                g.as_os_str(),
                "--labels".as_ref(),
                bad.as_os_str(),
            ],
            &name_of(bad),
            case,
        );
    }
    // synth --example with a junk reference clip.
    for (case, bad) in bad_files(&dir, "bvh") {
        assert_clean_failure(
            &[
                "graph".as_ref(),
                "synth".as_ref(),
                g.as_os_str(),
                "--out".as_ref(),
                out.as_os_str(),
                "--example".as_ref(),
                bad.as_os_str(),
            ],
            &name_of(&bad),
            &case,
        );
    }
}

#[test]
fn upload_and_replay_refuse_bad_files_before_touching_a_port() {
    let dir = scratch("link-files");
    let log = dir.join("ok.csv");
    write_ok_log(&log, 1.0);
    // Nothing listens on port 1: files must be refused before the port is tried.
    let port = "tcp:127.0.0.1:1";
    for (case, bad) in bad_files(&dir, "json") {
        let named = name_of(&bad);
        let b = bad.as_os_str();
        assert_clean_failure(
            &[
                "upload".as_ref(),
                "--port".as_ref(),
                port.as_ref(),
                "--library".as_ref(),
                b,
            ],
            &named,
            &case,
        );
        assert_clean_failure(
            &[
                "upload".as_ref(),
                "--port".as_ref(),
                port.as_ref(),
                "--effort".as_ref(),
                b,
            ],
            &named,
            &case,
        );
        assert_clean_failure(
            &[
                "replay".as_ref(),
                "--port".as_ref(),
                port.as_ref(),
                "--library".as_ref(),
                b,
                log.as_os_str(),
            ],
            &named,
            &case,
        );
    }
    for (case, bad) in bad_files(&dir, "csv") {
        assert_clean_failure(
            &[
                "replay".as_ref(),
                "--port".as_ref(),
                port.as_ref(),
                bad.as_os_str(),
            ],
            &name_of(&bad),
            &case,
        );
    }
}

/// A local TCP server that accepts one connection and then stays silent (`junk` = false) or
/// answers everything with junk bytes; runs until the test process ends.
fn fake_device(junk: bool) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            std::thread::spawn(move || {
                let mut s = stream;
                let _ = s.set_read_timeout(Some(Duration::from_millis(50)));
                let mut buf = [0u8; 256];
                let mut x: u32 = 0x9E37_79B9;
                loop {
                    if let Ok(0) = s.read(&mut buf) {
                        return; // the client hung up
                    }
                    if junk {
                        let bytes: Vec<u8> = (0..64)
                            .map(|_| {
                                x ^= x << 13;
                                x ^= x >> 17;
                                x ^= x << 5;
                                x as u8
                            })
                            .collect();
                        if s.write_all(&bytes).is_err() {
                            return;
                        }
                    }
                }
            });
        }
    });
    format!("tcp:{addr}")
}

#[test]
fn upload_and_replay_refuse_unusable_ports() {
    let dir = scratch("link-ports");
    let log = dir.join("ok.csv");
    write_ok_log(&log, 1.0);
    let regular = dir.join("not-a-tty");
    std::fs::write(&regular, "hello").unwrap();
    // A port nobody listens on: bind, note the address, close.
    let refused = {
        let l = TcpListener::bind("127.0.0.1:0").unwrap();
        format!("tcp:{}", l.local_addr().unwrap())
    };
    let ports: Vec<(String, &str)> = vec![
        ("/dev/figurine-does-not-exist".into(), "nonexistent device"),
        (regular.display().to_string(), "a regular file"),
        (dir.display().to_string(), "a directory"),
        ("tcp:nonsense".into(), "malformed tcp address"),
        (refused, "connection refused"),
        (fake_device(false), "silent device"),
        (fake_device(true), "device answering junk"),
    ];
    for (port, case) in &ports {
        let t0 = Instant::now();
        assert_clean_failure(&["upload", "--port", port], port, case);
        assert_clean_failure(
            &[
                "replay".as_ref(),
                "--port".as_ref(),
                port.as_ref(),
                log.as_os_str(),
            ],
            port,
            case,
        );
        assert!(t0.elapsed() < 2 * MAX_REFUSAL, "{case}");
    }
}
