//! Fetching the real motion data from the package registries into `target/figurine-data/`.
//!
//! Nothing here is committed: LAFAN1-derived files are CC BY-NC-ND and may not be
//! redistributed, so every machine fetches its own copy, once (a `.complete` marker per
//! package makes re-runs instant). Layout and names follow the project's data notes:
//!
//! | folder | files | registry package |
//! |---|---|---|
//! | `bvh/` | `lafan_dance1.bvh`, `lafan_test.bvh`, `blender_gestures.bvh` | PyPI sdist `bvhTools==1.6.0` |
//! | `bvh/` | `mixamo_walk_turn.bvh`, `mocapbank_kneel.bvh` | PyPI sdist `bvhtoolbox==0.1.3` |
//! | `bvh/` | `sword_attack.bvh` | crates.io `bvh_anim_parser==1.0.1` |
//! | `deepmimic/` | `humanoid3d_*.txt`, `humanoid.urdf` | PyPI wheel `pybullet==3.2.7` |
//! | `pose6d/` | `tum_fr1_xyz_groundtruth.txt`, `tum_fr2_desk_groundtruth.txt`, `euroc_v102_groundtruth.csv` | PyPI sdist `evo==1.38.1` |

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};

use crate::util::{root, run, step};

/// Where the data goes (the host's `figurine_host::data::data_dir()` default).
pub fn data_dir() -> PathBuf {
    std::env::var_os("FIGURINE_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target/figurine-data"))
}

struct Sdist {
    spec: &'static str,
    archive_prefix: &'static str,
    files: &'static [(&'static str, &'static str)],
}

const SDISTS: &[Sdist] = &[
    Sdist {
        spec: "bvhTools==1.6.0",
        archive_prefix: "bvhtools-1.6.0",
        files: &[
            ("testBvhFiles/test2.bvh", "bvh/lafan_dance1.bvh"),
            ("testBvhFiles/test.bvh", "bvh/lafan_test.bvh"),
            ("testBvhFiles/test3.bvh", "bvh/blender_gestures.bvh"),
        ],
    },
    Sdist {
        spec: "bvhtoolbox==0.1.3",
        archive_prefix: "bvhtoolbox-0.1.3",
        files: &[
            (
                "tests/example_files/test_freebvh.bvh",
                "bvh/mixamo_walk_turn.bvh",
            ),
            (
                "tests/example_files/test_mocapbank.bvh",
                "bvh/mocapbank_kneel.bvh",
            ),
        ],
    },
    Sdist {
        spec: "evo==1.38.1",
        archive_prefix: "evo-1.38.1",
        files: &[
            (
                "test/data/freiburg1_xyz-groundtruth.txt",
                "pose6d/tum_fr1_xyz_groundtruth.txt",
            ),
            (
                "test/data/fr2_desk_groundtruth.txt",
                "pose6d/tum_fr2_desk_groundtruth.txt",
            ),
            (
                "test/data/V102_groundtruth.csv",
                "pose6d/euroc_v102_groundtruth.csv",
            ),
        ],
    },
];

const DEEPMIMIC_CLIPS: &[&str] = &[
    "backflip",
    "cartwheel",
    "crawl",
    "dance_a",
    "dance_b",
    "getup_facedown",
    "getup_faceup",
    "jump",
    "kick",
    "punch",
    "roll",
    "run",
    "spin",
    "spinkick",
    "walk",
];

fn marker(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!(".{name}.complete"))
}

fn pip_download(args: &[&str], dest: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dest)?;
    let mut cmd = Command::new("python3");
    cmd.args(["-m", "pip", "download", "-q", "--no-deps", "-d"])
        .arg(dest)
        .args(args);
    run(&mut cmd).context(
        "pip download failed: the package registry may be unreachable (tests that need real \
         data will say they skip)",
    )?;
    let spec = args.last().copied().unwrap_or_default();
    let stem = spec.split("==").next().unwrap_or(spec).to_ascii_lowercase();
    let found = std::fs::read_dir(dest)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| {
            p.file_name().and_then(|n| n.to_str()).is_some_and(|n| {
                n.to_ascii_lowercase()
                    .replace('_', "-")
                    .starts_with(&stem.replace('_', "-"))
            })
        });
    found.with_context(|| {
        format!(
            "pip reported success but no archive for {spec} is in {}",
            dest.display()
        )
    })
}

fn extract_tar(archive: &Path, member: &str, out: &Path) -> Result<()> {
    let bytes = Command::new("tar")
        .arg("-xzOf")
        .arg(archive)
        .arg(member)
        .output()
        .with_context(|| format!("running tar on {}", archive.display()))?;
    if !bytes.status.success() || bytes.stdout.is_empty() {
        bail!("{} has no member {member}", archive.display());
    }
    std::fs::write(out, bytes.stdout)?;
    Ok(())
}

fn fetch_sword(dir: &Path, dl: &Path) -> Result<()> {
    let scratch = dl.join("bvh_anim_parser_fetch");
    std::fs::create_dir_all(scratch.join("src"))?;
    std::fs::write(
        scratch.join("Cargo.toml"),
        "[package]\nname = \"fetch-bvh-anim-parser\"\nversion = \"0.0.0\"\nedition = \"2021\"\n\
         [dependencies]\nbvh_anim_parser = \"=1.0.1\"\n[workspace]\n",
    )?;
    std::fs::write(scratch.join("src/lib.rs"), "")?;
    let mut cmd = Command::new("cargo");
    cmd.arg("fetch")
        .arg("--manifest-path")
        .arg(scratch.join("Cargo.toml"));
    run(&mut cmd)?;
    let cargo_home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")))
        .context("neither CARGO_HOME nor HOME is set")?;
    let src = cargo_home.join("registry/src");
    for index in std::fs::read_dir(&src)?.filter_map(|e| e.ok()) {
        let f = index
            .path()
            .join("bvh_anim_parser-1.0.1/examples/test_anim_sword_attack.bvh");
        if f.is_file() {
            std::fs::copy(&f, dir.join("bvh/sword_attack.bvh"))?;
            return Ok(());
        }
    }
    bail!(
        "bvh_anim_parser 1.0.1 fetched but its example file was not found under {}",
        src.display()
    )
}

/// Fetches every data file that is not there yet.
pub fn fetch() -> Result<()> {
    step("setup: real motion data from the package registries");
    let dir = data_dir();
    let dl = dir.join("downloads");
    for sub in ["bvh", "deepmimic", "pose6d"] {
        std::fs::create_dir_all(dir.join(sub))?;
    }
    for s in SDISTS {
        if marker(&dir, s.spec).exists() {
            continue;
        }
        println!("fetching {}", s.spec);
        let archive = pip_download(&["--no-binary", ":all:", s.spec], &dl)?;
        for (member, out) in s.files {
            extract_tar(
                &archive,
                &format!("{}/{member}", s.archive_prefix),
                &dir.join(out),
            )?;
        }
        std::fs::write(marker(&dir, s.spec), "")?;
    }
    if !marker(&dir, "pybullet").exists() {
        println!("fetching pybullet==3.2.7 (a 100 MB wheel; once)");
        let wheel = pip_download(
            &[
                "--only-binary",
                ":all:",
                "--python-version",
                "3.11",
                "--platform",
                "manylinux2014_x86_64",
                "pybullet==3.2.7",
            ],
            &dl,
        )?;
        let mut members: Vec<String> = DEEPMIMIC_CLIPS
            .iter()
            .map(|c| format!("pybullet_data/data/motions/humanoid3d_{c}.txt"))
            .collect();
        members.push("pybullet_data/humanoid/humanoid.urdf".into());
        let script = "import sys, zipfile, os\nz = zipfile.ZipFile(sys.argv[1])\nfor m in sys.argv[3:]:\n    \
                      open(os.path.join(sys.argv[2], os.path.basename(m)), 'wb').write(z.read(m))\n";
        let mut cmd = Command::new("python3");
        cmd.args(["-c", script])
            .arg(&wheel)
            .arg(dir.join("deepmimic"))
            .args(&members);
        run(&mut cmd)?;
        std::fs::write(marker(&dir, "pybullet"), "")?;
        // The wheel is large and everything needed is extracted.
        let _ = std::fs::remove_file(&wheel);
    }
    if !marker(&dir, "bvh_anim_parser").exists() {
        println!("fetching bvh_anim_parser==1.0.1 (crates.io)");
        fetch_sword(&dir, &dl)?;
        std::fs::write(marker(&dir, "bvh_anim_parser"), "")?;
    }
    println!("data ready in {}", dir.display());
    Ok(())
}
