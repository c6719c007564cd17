//! Exports checked by independent tools: Python's `bvh` package (PyPI) reads our BVH, and
//! Khronos' `gltf-validator` (npm) reports 0 errors on our .glb.
//!
//! Set-up (done by `cargo xtask setup`): `pip install bvh` and
//! `npm install --prefix target/npm gltf-validator`. Without them the tests print a skip line.

use std::path::{Path, PathBuf};
use std::process::Command;

use figurine_host::data::data_file;
use figurine_host::motion::{
    read_bvh_path, read_deepmimic_path, write_bvh_path, write_glb_path, Clip,
};

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("export_validate");
    let _ = std::fs::create_dir_all(&dir);
    dir.join(name)
}

/// A whole assembled animation: a synthetic doodle of four actions with its true labels.
fn assembled() -> Clip {
    use figurine_host::anim::assemble::{assemble, AssembleOptions};
    use figurine_host::anim::library::ClipLibrary;
    let d = figurine_host::synth::sequence::sequence(5, &Default::default(), 4, None);
    let events = figurine_host::anim::cli::label_events(d.labels.clone());
    let lib = ClipLibrary::default_library().unwrap();
    let clips = lib.load(events.iter().map(|e| e.action.as_str())).unwrap();
    let mut clip = assemble(
        &events,
        Some(&d.log),
        &clips,
        lib.forward(),
        &AssembleOptions::default(),
    )
    .unwrap()
    .clip;
    clip.name = "assembled".into();
    clip
}

fn clips() -> Vec<(Clip, f32)> {
    let mut out = Vec::new();
    if let (Some(walk), Some(urdf)) = (
        data_file("deepmimic", "humanoid3d_walk.txt"),
        data_file("deepmimic", "humanoid.urdf"),
    ) {
        out.push((read_deepmimic_path(&walk, &urdf).unwrap().clip, 1.0));
        out.push((assembled(), 1.0));
    }
    for (name, scale) in [
        ("blender_gestures.bvh", 1.0),
        ("mixamo_walk_turn.bvh", 0.01),
        ("sword_attack.bvh", 0.01),
    ] {
        if let Some(p) = data_file("bvh", name) {
            let mut c = read_bvh_path(&p).unwrap().clip;
            c.frames.truncate(120);
            out.push((c, scale));
        }
    }
    if out.is_empty() {
        eprintln!("skipping real clips: data missing — run `cargo xtask setup`");
    }
    out
}

/// The Python that `cargo xtask setup` prepared (a venv with `bvh`), else `python3`.
fn python() -> PathBuf {
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/tools/pyenv/bin/python");
    std::env::var_os("FIGURINE_PYTHON")
        .map(PathBuf::from)
        .unwrap_or(if venv.exists() {
            venv
        } else {
            PathBuf::from("python3")
        })
}

fn python_has_bvh() -> bool {
    Command::new(python())
        .args(["-c", "import bvh"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

#[test]
fn python_bvh_package_reads_our_bvh() {
    if !python_has_bvh() {
        eprintln!("skipping: python3 with the `bvh` package not found — `pip install bvh`");
        return;
    }
    for (clip, _) in clips() {
        let path = tmp(&format!("{}.bvh", clip.name));
        write_bvh_path(&clip, &path).unwrap();
        let script = r#"
import sys, json
from bvh import Bvh
with open(sys.argv[1]) as f:
    m = Bvh(f.read())
names = m.get_joints_names()
first = [float(x) for x in m.frames[0]]
print(json.dumps({"nframes": m.nframes, "frame_time": m.frame_time, "names": names,
                  "nvalues": len(first), "first": first}))
"#;
        let out = Command::new(python())
            .arg("-c")
            .arg(script)
            .arg(&path)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["nframes"].as_u64().unwrap() as usize, clip.len());
        assert!((v["frame_time"].as_f64().unwrap() - clip.frame_time as f64).abs() < 1e-6);
        let sk = &clip.skeleton;
        let ours: Vec<&str> = sk
            .dfs_order()
            .into_iter()
            .filter(|&j| !sk.joints[j].end_site)
            .map(|j| sk.joints[j].name.as_str())
            .collect();
        let theirs: Vec<&str> = v["names"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_str().unwrap())
            .collect();
        assert_eq!(ours, theirs, "{}", clip.name);
        // Their first frame must equal the values our importer reads back.
        let back = read_bvh_path(&path).unwrap().clip;
        let nchan: usize = back.skeleton.joints.iter().map(|j| j.channels.len()).sum();
        assert_eq!(v["nvalues"].as_u64().unwrap() as usize, nchan);
        let root_t = back.frames[0].translations[0];
        let first = v["first"].as_array().unwrap();
        let x0 = first[0].as_f64().unwrap() as f32;
        assert!(
            (x0 - root_t.x).abs() < 1e-4 * root_t.x.abs().max(1.0),
            "{x0} vs {root_t}"
        );
    }
}

fn validator_dir() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("GLTF_VALIDATOR_NODE_PATH").map(PathBuf::from),
        Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/tools/node/node_modules")),
        Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/npm/node_modules")),
    ];
    candidates
        .into_iter()
        .flatten()
        .find(|d| d.join("gltf-validator").is_dir())
}

#[test]
fn khronos_gltf_validator_accepts_our_glb() {
    let Some(node_path) = validator_dir() else {
        eprintln!(
            "skipping: gltf-validator not found — `npm install --prefix target/npm gltf-validator` \
             (or set GLTF_VALIDATOR_NODE_PATH to a node_modules folder holding it)"
        );
        return;
    };
    let script = r#"
const v = require('gltf-validator'); const fs = require('fs');
const data = new Uint8Array(fs.readFileSync(process.argv[1]));
v.validateBytes(data).then(r => { console.log(JSON.stringify(r.issues)); })
 .catch(e => { console.error(e); process.exit(2); });
"#;
    for (clip, scale) in clips() {
        let path = tmp(&format!("{}.glb", clip.name));
        write_glb_path(&clip, scale, &path).unwrap();
        let out = Command::new("node")
            .arg("-e")
            .arg(script)
            .arg(&path)
            .env("NODE_PATH", &node_path)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let issues: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(
            issues["numErrors"], 0,
            "{}: {}",
            clip.name, issues["messages"]
        );
        eprintln!(
            "{}: gltf-validator errors={} warnings={} infos={}",
            clip.name, issues["numErrors"], issues["numWarnings"], issues["numInfos"]
        );
    }
}
