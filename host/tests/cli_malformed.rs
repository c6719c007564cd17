//! Malformed input to every file-taking CLI command: a clear error naming the file and a
//! non-zero exit, never a panic or a backtrace. Inputs that are odd but legal (NaN samples,
//! huge numbers) may succeed — the recognizer counts and skips them — but must not panic.

mod malformed;

use malformed::{bad_files, figurine, name_of, scratch};

/// Runs one case and checks it failed cleanly, naming `file`.
fn assert_clean_failure(args: &[&std::ffi::OsStr], file: &std::path::Path, case: &str) {
    malformed::assert_clean_failure(args, &name_of(file), case);
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
#[cfg(feature = "render")]
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
