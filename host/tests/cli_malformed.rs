//! Malformed input to every file-taking CLI command: a clear error naming the file and a
//! non-zero exit, never a panic or a backtrace. Inputs that are odd but legal (NaN samples,
//! huge numbers) may succeed — the recognizer counts and skips them — but must not panic.

use std::path::{Path, PathBuf};
use std::process::Command;

fn figurine() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_figurine"));
    c.env("RUST_BACKTRACE", "1");
    c
}

/// A scratch folder unique to one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("figurine-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Malformed contents, by name. `None` contents = the path does not exist.
fn bad_files(dir: &Path, ext: &str) -> Vec<(String, PathBuf)> {
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

/// Runs one case and checks it failed cleanly, naming `file`.
fn assert_clean_failure(args: &[&std::ffi::OsStr], file: &Path, case: &str) {
    let out = figurine().args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let shown = format!(
        "figurine {:?} [{case}]: status {:?}\nstderr: {stderr}",
        args, out.status
    );
    assert!(!stderr.contains("panicked"), "panic: {shown}");
    assert!(!stderr.contains("stack backtrace"), "backtrace: {shown}");
    assert!(!out.status.success(), "accepted malformed input: {shown}");
    assert_eq!(out.status.code(), Some(1), "{shown}");
    let name = file.file_name().unwrap().to_string_lossy();
    assert!(
        stderr.contains(name.as_ref()),
        "error does not name the file: {shown}"
    );
}

#[test]
fn simulate_and_tokens_refuse_malformed_logs() {
    let dir = scratch("logs");
    for (case, file) in bad_files(&dir, "csv") {
        let f = file.as_os_str();
        assert_clean_failure(&["simulate".as_ref(), "--jsonl".as_ref(), f], &file, &case);
        assert_clean_failure(&["tokens".as_ref(), f], &file, &case);
    }
}

#[test]
fn simulate_refuses_malformed_library_and_effort_files() {
    let dir = scratch("libs");
    let log = dir.join("ok.csv");
    std::fs::write(
        &log,
        "t,x,y,z,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.01,0,0,0,1,0,0,0\n",
    )
    .unwrap();
    for (case, file) in bad_files(&dir, "json") {
        let f = file.as_os_str();
        assert_clean_failure(
            &[
                "simulate".as_ref(),
                "--library".as_ref(),
                f,
                log.as_os_str(),
            ],
            &file,
            &case,
        );
        assert_clean_failure(
            &["simulate".as_ref(), "--effort".as_ref(), f, log.as_os_str()],
            &file,
            &case,
        );
    }
}

#[test]
fn learn_refuses_malformed_examples() {
    let dir = scratch("learn");
    let lib = dir.join("lib.json");
    for (case, file) in bad_files(&dir, "csv") {
        let f = file.as_os_str();
        assert_clean_failure(
            &[
                "learn".as_ref(),
                "--library".as_ref(),
                lib.as_os_str(),
                "--name".as_ref(),
                "hop".as_ref(),
                f,
                f,
                f,
            ],
            &file,
            &case,
        );
    }
}

#[test]
fn render_refuses_malformed_bvh() {
    let dir = scratch("render");
    let out = dir.join("out.gif");
    for (case, file) in bad_files(&dir, "bvh") {
        let f = file.as_os_str();
        assert_clean_failure(
            &[
                "render".as_ref(),
                f,
                "--out".as_ref(),
                out.as_os_str(),
                "--size".as_ref(),
                "64x48".as_ref(),
            ],
            &file,
            &case,
        );
    }
}

#[test]
fn nan_and_huge_values_in_a_log_are_survived() {
    let dir = scratch("nan");
    let mut text = String::from("t,x,y,z,qw,qx,qy,qz\n");
    for i in 0..400 {
        let t = i as f64 / 100.0;
        let row = match i % 50 {
            7 => format!("{t},NaN,0,0,1,0,0,0"),
            8 => format!("{t},1e300,0,0,1,0,0,0"),
            9 => format!("{t},0,0,0,0,0,0,0"),
            10 => format!("{},0,0,0,1,0,0,0", t - 5.0),
            11 => format!("{t},0,inf,0,1,0,0,0"),
            _ => format!("{t},{},0.5,0,1,0,0,0", (t * 3.0).sin() * 0.2),
        };
        text.push_str(&row);
        text.push('\n');
    }
    let log = dir.join("nan.csv");
    std::fs::write(&log, text).unwrap();
    for args in [vec!["simulate", "--jsonl"], vec!["tokens"]] {
        let out = figurine().args(&args).arg(&log).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        if !out.status.success() {
            assert!(stderr.contains("nan.csv"), "{args:?}: {stderr}");
        }
    }
}
