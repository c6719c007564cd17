//! Shared helpers of the malformed-input CLI tests (`cli_malformed*.rs`): the binary, scratch
//! folders, a set of malformed files, and the clean-failure check.
// Each test binary that includes this module uses a subset of it.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// Longest a refusal may take (debug build on a loaded 2-core machine; a malformed file must
/// fail fast, typically well under a second).
pub const MAX_REFUSAL: Duration = Duration::from_secs(10);

/// The `figurine` binary, with panic backtraces on so that a panic would be visible (error
/// backtraces off: `anyhow` would print one for every ordinary error under `RUST_BACKTRACE`).
pub fn figurine() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_figurine"));
    c.env("RUST_BACKTRACE", "1").env("RUST_LIB_BACKTRACE", "0");
    c
}

#[path = "../scratch/mod.rs"]
mod scratch;
pub use scratch::Scratch;

/// A scratch folder unique to one test, removed when it passes.
pub fn scratch(name: &str) -> Scratch {
    Scratch::new("cli", name)
}

/// Malformed contents, by name, written into `dir` with extension `ext`; plus a path that
/// does not exist and a directory where a file is expected.
pub fn bad_files(dir: &Path, ext: &str) -> Vec<(String, PathBuf)> {
    let junk: Vec<u8> = (0..2048u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    let header = "t,x,y,z,qw,qx,qy,qz\n";
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("empty", Vec::new()),
        ("binary", junk),
        ("wrong-columns", b"time;pos;rot\n1;2;3\n".to_vec()),
        (
            "truncated",
            format!("{header}0.0,1,2,3,1,0,0,0\n0.01,1,2").into_bytes(),
        ),
        (
            "text-in-numbers",
            format!("{header}0.0,one,2,3,1,0,0,0\n").into_bytes(),
        ),
        (
            "json-newer-version",
            br#"{"format":"figurine-library","version":99,"actions":[]}"#.to_vec(),
        ),
        (
            "json-truncated",
            br#"{"format":"figurine-library","version":1,"act"#.to_vec(),
        ),
        (
            "bvh-truncated",
            b"HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition".to_vec(),
        ),
    ];
    let mut out: Vec<(String, PathBuf)> = cases
        .into_iter()
        .map(|(name, bytes)| {
            let p = dir.join(format!("{name}.{ext}"));
            std::fs::write(&p, bytes).unwrap();
            (name.to_string(), p)
        })
        .collect();
    out.push(("missing".into(), dir.join(format!("does-not-exist.{ext}"))));
    let d = dir.join(format!("a-directory.{ext}"));
    std::fs::create_dir_all(&d).unwrap();
    out.push(("directory".into(), d));
    out
}

/// Runs `figurine ARGS` and checks it failed cleanly and quickly: exit status 1, no panic or
/// backtrace, stderr naming `named` (a file, folder or port). Returns stderr.
pub fn assert_clean_failure<S: AsRef<OsStr>>(args: &[S], named: &str, case: &str) -> String {
    let args: Vec<&OsStr> = args.iter().map(AsRef::as_ref).collect();
    let t0 = Instant::now();
    let out = figurine().args(&args).output().unwrap();
    let took = t0.elapsed();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let shown = format!(
        "figurine {:?} [{case}]: status {:?} after {:.2} s\nstderr: {stderr}",
        args,
        out.status,
        took.as_secs_f64()
    );
    assert!(!stderr.contains("panicked"), "panic: {shown}");
    assert!(
        !stderr.to_lowercase().contains("backtrace"),
        "backtrace: {shown}"
    );
    assert!(!out.status.success(), "accepted malformed input: {shown}");
    assert_eq!(out.status.code(), Some(1), "{shown}");
    assert!(
        stderr.contains(named),
        "error does not name {named:?}: {shown}"
    );
    assert!(took < MAX_REFUSAL, "too slow to refuse: {shown}");
    stderr
}

/// The file name of `p` (what an error message must contain).
pub fn name_of(p: &Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}

/// A small valid pose log: a figurine hopping forward along +Z for `seconds` at 100 Hz.
pub fn write_ok_log(path: &Path, seconds: f64) {
    let mut text = String::from("t,x,y,z,qw,qx,qy,qz\n");
    let n = (seconds * 100.0) as usize;
    for i in 0..=n {
        let t = i as f64 / 100.0;
        let y = 0.1 * (t * std::f64::consts::PI * 2.0).sin().abs();
        text.push_str(&format!("{t:.2},0,{y:.4},{:.4},1,0,0,0\n", 0.3 * t));
    }
    std::fs::write(path, text).unwrap();
}
