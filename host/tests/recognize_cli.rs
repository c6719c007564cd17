//! The recognition commands end to end, as a user runs them: `synth` → `learn` →
//! `train-effort` → `simulate`, plus the error a malformed log gives.

use std::path::Path;
use std::process::{Command, Output};

use figurine_host::events::read_events;

mod scratch;
use scratch::Scratch;

fn figurine(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_figurine"))
        .args(args)
        .output()
        .unwrap()
}

/// A scratch folder unique to one test, removed when it passes.
fn tmp(name: &str) -> Scratch {
    Scratch::new("recog", name)
}

fn csvs(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .map(|p| p.display().to_string())
        .collect();
    v.sort();
    v
}

/// `figurine synth examples`: `count` performances of `action` at `seed` into `dir`, whose
/// CSV files it returns.
fn synth_examples(action: &str, count: usize, seed: u64, dir: &Path) -> Vec<String> {
    let (count, seed) = (count.to_string(), seed.to_string());
    let out = figurine(&[
        "synth",
        "examples",
        "--action",
        action,
        "--count",
        &count,
        "--seed",
        &seed,
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    csvs(dir)
}

/// `figurine learn` of action `name` into `lib` from `files`.
fn learn(lib: &Path, name: &str, files: &[String]) -> Output {
    let mut args = vec!["learn", "--library", lib.to_str().unwrap(), "--name", name];
    args.extend(files.iter().map(String::as_str));
    figurine(&args)
}

#[test]
fn learning_from_many_examples_names_the_odd_ones_it_left_out() {
    // Twelve sidesteps: the pattern keeps what three of them show alike, and an example it
    // then does not read is named as an odd one, not as a reason to add more.
    let d = tmp("many");
    let files = synth_examples("sidestep", 12, 3, &d.join("sidestep"));
    let out = learn(&d.join("lib.json"), "sidestep", &files);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let read = err.matches("read back as `sidestep`\n").count();
    let odd = err
        .matches("of 12 examples the pattern keeps what 3 show alike")
        .count();
    assert!(odd >= 1 && read + odd == 12, "{err}");
    assert!(!err.contains("add examples"), "{err}");
}

#[test]
fn learn_then_simulate_a_sequence() {
    let d = tmp("learn");
    let lib = d.join("lib.json");
    for action in ["jump", "spin"] {
        let files = synth_examples(action, 3, 5, &d.join(action));
        let out = learn(&lib, action, &files);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        // Each example is read back through the device with the library as written.
        let back = format!("read back as `{action}`\n");
        assert_eq!(err.matches(&back).count(), files.len(), "{err}");
    }
    let text = std::fs::read_to_string(&lib).unwrap();
    for key in [
        "\"name\": \"jump\"",
        "\"regex\"",
        "\"compiled\"",
        "\"record_hex\"",
        "\"blob_hex\"",
    ] {
        assert!(text.contains(key), "LIB.json lacks {key}");
    }
    // Learning the same examples under another name warns and names the other action.
    let out = learn(&lib, "hop", &csvs(&d.join("jump")));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("warning") && err.contains("`jump`"), "{err}");
    // … and its examples read back as the action learnt first, which the user is told.
    assert!(
        err.contains("read back as `jump` — not as one `hop`"),
        "{err}"
    );

    let log = d.join("seq.csv");
    let labels = d.join("seq.json");
    let out = figurine(&[
        "synth",
        "sequence",
        "--seed",
        "9",
        "--count",
        "4",
        "--out",
        log.to_str().unwrap(),
        "--labels",
        labels.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = figurine(&[
        "simulate",
        "--library",
        lib.to_str().unwrap(),
        "--jsonl",
        log.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let events = read_events(&out.stdout[..], Path::new("stdout")).unwrap();
    for e in &events {
        assert!(
            ["jump", "spin", "hop"].contains(&e.action.as_str()),
            "{e:?}"
        );
        assert!((-1.0..=1.0).contains(&e.time) && (-1.0..=1.0).contains(&e.weight));
        // Efforts are the device's i8 values / 127 (serde_json's default float parser may be
        // one ulp off, so compare the numerators).
        assert!(
            ((e.time * 127.0).round() - e.time * 127.0).abs() < 1e-9,
            "{e:?}"
        );
        assert!(
            ((e.weight * 127.0).round() - e.weight * 127.0).abs() < 1e-9,
            "{e:?}"
        );
    }
    // The table form works with the shipped library and effort model.
    let out = figurine(&["simulate", log.to_str().unwrap()]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("samples accepted"));
}

#[test]
fn train_effort_writes_model_and_report() {
    let d = tmp("effort");
    let set = d.join("set");
    let out = figurine(&[
        "synth",
        "effort-set",
        "--seed",
        "3",
        "--per-class",
        "8",
        "--out",
        set.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let model = d.join("effort.json");
    let out = figurine(&[
        "train-effort",
        "--out",
        model.to_str().unwrap(),
        set.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("Time:") && stdout.contains("Weight:"),
        "{stdout}"
    );
    let png = image::open(d.join("effort.png")).unwrap();
    assert!(png.width() > 500);
    // The model loads into simulate.
    let log = csvs(&set.join("sudden-strong")).remove(0);
    let out = figurine(&[
        "simulate",
        "--effort",
        model.to_str().unwrap(),
        "--jsonl",
        &log,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn malformed_logs_name_file_and_line() {
    let d = tmp("bad");
    let bad = d.join("bad.csv");
    std::fs::write(
        &bad,
        "t,x,y,z,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.01,0,zz,0,1,0,0,0\n",
    )
    .unwrap();
    let out = figurine(&["simulate", "--jsonl", bad.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.csv:3"), "{err}");
    // NaNs and time going backwards are counted and skipped, not errors.
    let odd = d.join("odd.csv");
    std::fs::write(
        &odd,
        "t,x,y,z,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.01,NaN,0,0,1,0,0,0\n0.005,0,0,0,1,0,0,0\n0.02,0,0,0,0,0,0,0\n",
    )
    .unwrap();
    let out = figurine(&["simulate", odd.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn eval_over_seed_pairs_prints_each_pair_and_the_mean() {
    let out = figurine(&[
        "eval",
        "--pairs",
        "2",
        "--isolated",
        "2",
        "--sequences",
        "1",
        "--effort-per-class",
        "4",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Pair k trains with seed 1 + (k − 1) and tests on 1000 + 1000·(k − 1).
    let rows: Vec<Vec<&str>> = text
        .lines()
        .map(|l| l.split_whitespace().collect::<Vec<_>>())
        .filter(|w| {
            w.iter().any(|x| x.ends_with('%'))
                && w.first()
                    .is_some_and(|f| *f == "mean" || f.parse::<u32>().is_ok())
        })
        .collect();
    assert_eq!(rows.len(), 3, "{text}");
    assert_eq!(&rows[0][..3], ["1", "1", "1000"], "{text}");
    assert_eq!(&rows[1][..3], ["2", "2", "2000"], "{text}");
    let pct = |w: &str| -> f64 { w.trim_end_matches('%').parse().unwrap() };
    for (row, first) in rows.iter().zip([3, 3, 1]) {
        for w in &row[first..first + 5] {
            assert!((0.0..=100.0).contains(&pct(w)), "{w} in {text}");
        }
    }
    // The mean of the two isolated figures.
    let mean = (pct(rows[0][3]) + pct(rows[1][3])) / 2.0;
    assert!((pct(rows[2][1]) - mean).abs() < 0.06, "{text}");
    assert!(text.contains("range: isolated"), "{text}");
    assert!(text.contains("counts over the pairs: isolated "), "{text}");

    // Pairs learn anew: a given library is refused, with the reason.
    let out = figurine(&["eval", "--pairs", "2", "--library", "lib.json"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--pairs") && err.contains("--library"),
        "{err}"
    );
}

/// A pose log at 100 Hz: still 0.6 s, one stroke of 5 cm to the figurine's left lasting
/// `stroke_s` (minimum-jerk-like), then still.
fn left_stroke(path: &Path, stroke_s: f64) {
    stroke_of(path, stroke_s, 0.05);
}

/// [`left_stroke`] of `metres` along +X (the figurine's left; negative: its right).
fn stroke_of(path: &Path, stroke_s: f64, metres: f64) {
    let mut csv = String::from("t,x,y,z,qw,qx,qy,qz\n");
    for i in 0..((1.4 + stroke_s) * 100.0) as usize {
        let t = i as f64 / 100.0;
        let u = ((t - 0.6) / stroke_s).clamp(0.0, 1.0);
        let x = metres * (u - (std::f64::consts::TAU * u).sin() / std::f64::consts::TAU);
        csv += &format!("{t:.4},{x:.5},1.0,0.0,1,0,0,0\n");
    }
    std::fs::write(path, csv).unwrap();
}

#[test]
fn simulate_why_names_the_rule_that_dropped_a_match() {
    let d = tmp("why");
    let lib = d.join("left.json");
    std::fs::write(
        &lib,
        r#"{"format":"figurine-library","version":1,
            "actions":[{"name":"left","regex":"l","max_edits":0,"examples":[]}]}"#,
    )
    .unwrap();
    let why = |log: &Path| {
        let out = figurine(&[
            "simulate",
            "--why",
            "--library",
            lib.to_str().unwrap(),
            log.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    // A flick of a tenth of a second spells `l`, and is dropped as a flicker.
    let flick = d.join("flick.csv");
    left_stroke(&flick, 0.12);
    let text = why(&flick);
    assert!(text.contains("0 actions"), "{text}");
    let dropped: Vec<&str> = text.lines().filter(|l| l.contains("dropped:")).collect();
    assert_eq!(dropped.len(), 1, "{text}");
    assert!(
        dropped[0].starts_with("left") && dropped[0].contains("briefer than 0.15 s"),
        "{text}"
    );
    // A stroke of 0.4 s is the action, and nothing was dropped.
    let stroke = d.join("stroke.csv");
    left_stroke(&stroke, 0.4);
    let text = why(&stroke);
    assert!(text.contains("1 actions"), "{text}");
    assert!(
        text.contains("every match committed was reported"),
        "{text}"
    );
    // A stroke to the right is read as nothing: said so, with the tokens it moved.
    let right = d.join("right.csv");
    stroke_of(&right, 0.4, -0.05);
    let text = why(&right);
    assert!(text.contains("0 actions"), "{text}");
    assert!(
        text.lines()
            .any(|l| l.starts_with("(none)") && l.contains("moved (`r`), but no action read it")),
        "{text}"
    );
    // A figurine that never moved: nothing stood out of the noise.
    let still = d.join("still.csv");
    stroke_of(&still, 0.4, 0.0);
    let text = why(&still);
    assert!(text.contains("nothing moved"), "{text}");
    // ... and it names the speed a stroke must pass: the 7 cm/s floor for a noiseless log.
    assert!(text.contains("must pass 7.0 cm/s"), "{text}");
    // The notes are for the table; the JSON lines stay events only.
    let out = figurine(&["simulate", "--why", "--jsonl", flick.to_str().unwrap()]);
    assert!(!out.status.success());
}

/// `simulate --why` names each stretch the tracker gave no sample for, with how far the
/// figurine turned across it either way round, and says when the recognizer started afresh.
#[test]
fn simulate_why_names_the_samples_the_tracker_lost() {
    let d = tmp("lost");
    // 30 Hz, still 1 s, then turning 0.5 rad a frame about +Y; frames 36-39 lost (0.17 s),
    // across which it turns 2.5 rad (143°); then a 0.4 s gap at rest.
    let mut csv = String::from("t,x,y,z,qw,qx,qy,qz\n");
    for k in 0..90u32 {
        if (36..40).contains(&k) || (70..82).contains(&k) {
            continue;
        }
        let yaw = 0.5 * f64::from(k.clamp(30, 50) - 30);
        let t = f64::from(k) / 30.0;
        csv += &format!(
            "{t:.4},0,1,0,{:.6},0,{:.6},0\n",
            (yaw / 2.0).cos(),
            (yaw / 2.0).sin()
        );
    }
    let log = d.join("lost.csv");
    std::fs::write(&log, csv).unwrap();
    let out = figurine(&["simulate", "--why", log.to_str().unwrap()]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let lost: Vec<&str> = text.lines().filter(|l| l.starts_with("(lost)")).collect();
    assert_eq!(lost.len(), 2, "{text}");
    assert!(
        lost[0].contains("no sample for 0.17 s (4 of its 30 Hz samples)")
            && lost[0].contains("turned 143° (or 217° the other way round)"),
        "{text}"
    );
    assert!(lost[1].contains("starts afresh"), "{text}");
}

/// `eval --verbose` names every misread gesture with the command that plays it again — under
/// the evaluation's own tracker — and says why the decision stage dropped what it dropped.
#[test]
fn eval_verbose_hints_regenerate_the_misread_gesture() {
    let out = figurine(&["eval", "--noise", "3", "--sequences", "1", "--verbose"]);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = err.lines().collect();
    let hints: Vec<(usize, &str)> = lines
        .iter()
        .enumerate()
        .filter_map(|(i, l)| {
            let at = l.find("(figurine synth examples ")?;
            Some((i, l[at + 1..].trim_end_matches(')')))
        })
        .collect();
    assert!(!hints.is_empty(), "no misread at noise ×3?\n{err}");
    // The first hint with an event: the gesture's span is printed beside it.
    let (i, hint) = hints
        .iter()
        .copied()
        .find(|(i, _)| lines.get(i + 1).is_some_and(|l| l.contains("(gesture ")))
        .expect("a misread with an event");
    assert!(hint.ends_with("--noise 3"), "{hint}");
    let span = lines[i + 1].split("(gesture ").nth(1).unwrap();
    let (a, b) = span.trim_end_matches(')').split_once('-').unwrap();
    let d = tmp("hint");
    let args: Vec<&str> = hint.split_whitespace().skip(1).collect();
    let mut cmd = args.clone();
    cmd.extend(["--out", d.to_str().unwrap()]);
    let again = figurine(&cmd);
    assert!(again.status.success(), "{hint}");
    // `synth examples` prints the label it wrote: the same span, to the hundredth.
    let said = String::from_utf8_lossy(&again.stdout);
    let label = said.lines().find(|l| l.contains(" .. ")).unwrap_or("");
    let nums: Vec<f64> = label
        .split_whitespace()
        .filter_map(|w| w.parse::<f64>().ok())
        .collect();
    let [t0, t1] = nums[..] else { panic!("{said}") };
    assert_eq!(
        (format!("{t0:.2}"), format!("{t1:.2}")),
        (a.to_string(), b.to_string()),
        "{hint}: {said}"
    );
}

#[test]
fn learn_says_why_an_example_that_read_as_nothing_was_left_out() {
    let d = tmp("learn-still");
    let (big, tiny, tiny2) = (d.join("big.csv"), d.join("tiny.csv"), d.join("tiny2.csv"));
    stroke_of(&big, 0.3, 0.05);
    // 2 mm in a second: 0.4 cm/s at its fastest, under the 7 cm/s floor.
    stroke_of(&tiny, 1.0, 0.002);
    stroke_of(&tiny2, 1.0, -0.002);
    let learn = |lib: &Path, examples: &[&Path]| {
        let mut args = vec![
            "learn",
            "--library",
            lib.to_str().unwrap(),
            "--name",
            "left",
        ];
        args.extend(examples.iter().map(|p| p.to_str().unwrap()));
        figurine(&args)
    };
    let out = learn(&d.join("lib.json"), &[&big, &tiny]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let line = err
        .lines()
        .find(|l| l.contains("tiny.csv"))
        .unwrap_or_else(|| panic!("no line for the still example: {err}"));
    assert!(
        line.contains("left out, nothing moved: a stroke must pass 7.0 cm/s"),
        "{line}"
    );
    assert!(err.contains("big.csv: l  [matched"), "{err}");
    // Every example still: an error that says so for each, and no library written.
    let lib2 = d.join("lib2.json");
    let out = learn(&lib2, &[&tiny, &tiny2]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("no example moved enough to read"), "{err}");
    assert_eq!(
        err.matches("nothing moved: a stroke must pass").count(),
        2,
        "{err}"
    );
    assert!(!lib2.exists());
}
