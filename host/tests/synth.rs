//! End-to-end properties of `figurine synth`: determinism, label consistency, the invariance
//! knobs, effort directions, file round trips and the CLI.

use std::path::PathBuf;
use std::process::Command;

use figurine_host::poselog::{PoseLog, PoseSample};
use figurine_host::synth::knobs::Range;
use figurine_host::synth::sampling::SignMode;
use figurine_host::synth::{
    effort_set, examples, gesture, sequence, Action, Effort, Knobs, Label, TimeClass, WeightClass,
};
use glam::{DQuat, DVec3};

fn bytes(log: &PoseLog) -> Vec<u8> {
    let mut b = Vec::new();
    log.write(&mut b).unwrap();
    b
}

fn pos(s: &PoseSample) -> DVec3 {
    DVec3::from_array(s.pos)
}

fn quat(s: &PoseSample) -> DQuat {
    DQuat::from_xyzw(s.quat[1], s.quat[2], s.quat[3], s.quat[0])
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("figurine-synth-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Largest distance of any sample from the first one, metres.
fn extent(log: &PoseLog) -> f64 {
    let p0 = pos(&log.samples[0]);
    log.samples
        .iter()
        .map(|s| (pos(s) - p0).length())
        .fold(0.0, f64::max)
}

/// Radius of the toy's extremities (metres) for [`kinematics`]: a figurine is ~20 cm tall.
const TOY_RADIUS_M: f64 = 0.1;

/// Linear speeds (m/s) and peak-style accelerations (m/s²) of a clean, evenly sampled log by
/// finite differences. The acceleration is that of the toy's extremities: |a| + r·|α|, so
/// rotation gestures (turn, wave) count their angular impacts too.
fn kinematics(log: &PoseLog) -> (Vec<f64>, Vec<f64>) {
    let s = &log.samples;
    let v: Vec<DVec3> = s
        .windows(2)
        .map(|w| (pos(&w[1]) - pos(&w[0])) / (w[1].t - w[0].t))
        .collect();
    let w: Vec<DVec3> = s
        .windows(2)
        .map(|p| {
            let d = quat(&p[1]) * quat(&p[0]).inverse();
            let d = if d.w < 0.0 { -d } else { d };
            d.to_scaled_axis() / (p[1].t - p[0].t)
        })
        .collect();
    let a: Vec<f64> = (1..v.len())
        .map(|i| {
            let dt = (s[i + 1].t - s[i - 1].t) / 2.0;
            ((v[i] - v[i - 1]) / dt).length() + TOY_RADIUS_M * ((w[i] - w[i - 1]) / dt).length()
        })
        .collect();
    (v.iter().map(|x| x.length()).collect(), a)
}

fn max(v: &[f64]) -> f64 {
    v.iter().cloned().fold(0.0, f64::max)
}

#[test]
fn same_seed_same_bytes_other_seed_other_bytes() {
    let k = Knobs::default();
    let e: Effort = "sudden-light".parse().unwrap();
    let a = gesture(11, &k, Action::Kick, e);
    let b = gesture(11, &k, Action::Kick, e);
    let c = gesture(12, &k, Action::Kick, e);
    assert_eq!(bytes(&a.log), bytes(&b.log));
    assert_ne!(bytes(&a.log), bytes(&c.log));
    let s1 = sequence(5, &k, 6, None);
    let s2 = sequence(5, &k, 6, None);
    assert_eq!(bytes(&s1.log), bytes(&s2.log));
    assert_eq!(s1.labels, s2.labels);
}

#[test]
fn labels_are_ordered_inside_the_log_and_cover_the_motion() {
    for seed in 0..4 {
        let d = sequence(seed, &Knobs::default(), 7, None);
        let (t_first, t_last) = (d.log.samples[0].t, d.log.samples.last().unwrap().t);
        assert!(d.log.samples.windows(2).all(|w| w[1].t > w[0].t));
        assert_eq!(d.labels.len(), 7);
        for l in &d.labels {
            assert!(l.start < l.end, "{l:?}");
            assert!(
                l.start >= t_first && l.end <= t_last,
                "{l:?} vs {t_first}..{t_last}"
            );
            assert!(matches!(
                l.time_class,
                TimeClass::Sudden | TimeClass::Sustained
            ));
            assert!(matches!(
                l.weight_class,
                WeightClass::Strong | WeightClass::Light
            ));
            assert!(l.action.parse::<Action>().is_ok());
        }
        for w in d.labels.windows(2) {
            assert!(w[0].end < w[1].start, "overlap {:?} {:?}", w[0], w[1]);
        }
    }
    // On a clean log, the figurine is still outside the labels and moves inside each one.
    let d = sequence(9, &Knobs::canonical(), 6, None);
    let inside = |t: f64, l: &[Label]| l.iter().any(|x| t >= x.start - 1e-9 && t <= x.end + 1e-9);
    for w in d.log.samples.windows(2) {
        let moved = (pos(&w[1]) - pos(&w[0])).length() + quat(&w[1]).angle_between(quat(&w[0]));
        if !inside(w[0].t, &d.labels) && !inside(w[1].t, &d.labels) {
            assert!(moved < 1e-9, "motion outside labels at t={}", w[0].t);
        }
    }
    for l in &d.labels {
        let travelled: f64 = d
            .log
            .samples
            .windows(2)
            .filter(|w| w[0].t >= l.start && w[1].t <= l.end)
            .map(|w| (pos(&w[1]) - pos(&w[0])).length() + quat(&w[1]).angle_between(quat(&w[0])))
            .sum();
        assert!(travelled > 0.05, "{l:?} barely moves: {travelled}");
    }
}

#[test]
fn scale_multiplies_the_spatial_extent() {
    for (i, action) in Action::ALL.into_iter().enumerate() {
        let at = |scale: f64| {
            let k = Knobs {
                scale: Range::fixed(scale),
                ..Knobs::canonical()
            };
            extent(&gesture(i as u64, &k, action, Effort::NEUTRAL).log)
        };
        let (one, half, two) = (at(1.0), at(0.5), at(2.0));
        assert!(one > 0.005, "{action}: {one}");
        assert!((two / one - 2.0).abs() < 1e-9, "{action}: {}", two / one);
        assert!((half / one - 0.5).abs() < 1e-9, "{action}: {}", half / one);
    }
}

#[test]
fn heading_rotates_path_and_orientation() {
    for (i, action) in Action::ALL.into_iter().enumerate() {
        let at = |deg: f64| {
            let k = Knobs {
                heading_deg: Range::fixed(deg),
                ..Knobs::canonical()
            };
            gesture(100 + i as u64, &k, action, Effort::STATES[i % 4]).log
        };
        let (a, b) = (at(0.0), at(90.0));
        let r = DQuat::from_rotation_y(90f64.to_radians());
        let (a0, b0) = (pos(&a.samples[0]), pos(&b.samples[0]));
        assert_eq!(a.samples.len(), b.samples.len());
        for (sa, sb) in a.samples.iter().zip(&b.samples) {
            assert!(
                ((r * (pos(sa) - a0)) - (pos(sb) - b0)).length() < 1e-9,
                "{action}"
            );
            assert!((r * quat(sa)).dot(quat(sb)).abs() > 1.0 - 1e-9, "{action}");
        }
    }
}

#[test]
fn rate_changes_sample_count_not_the_path() {
    let at = |rate: f64| {
        let k = Knobs {
            rate_hz: Range::fixed(rate),
            ..Knobs::canonical()
        };
        gesture(3, &k, Action::Walk, Effort::NEUTRAL).log
    };
    let (slow, fast) = (at(30.0), at(240.0));
    let ratio = fast.samples.len() as f64 / slow.samples.len() as f64;
    assert!((ratio - 8.0).abs() < 0.1, "{ratio}");
    assert_eq!(slow.samples[0].t, fast.samples[0].t);
    // Every 8th fast sample is the same instant and pose as a slow one.
    for (i, s) in slow.samples.iter().enumerate() {
        let f = &fast.samples[i * 8];
        assert!((s.t - f.t).abs() < 1e-9);
        assert!((pos(s) - pos(f)).length() < 1e-9);
    }
    let hi = Knobs {
        rate_hz: Range::fixed(1000.0),
        jitter: Range::fixed(0.3),
        ..Knobs::default()
    };
    let d = gesture(4, &hi, Action::Spin, Effort::NEUTRAL);
    let dur = d.log.samples.last().unwrap().t - d.log.samples[0].t;
    let n = d.log.samples.len() as f64;
    assert!((n / dur - 1000.0).abs() < 30.0, "{}", n / dur);
}

#[test]
fn effort_classes_differ_in_the_intended_direction() {
    let k = Knobs {
        rate_hz: Range::fixed(240.0),
        ..Knobs::canonical()
    };
    let e = |s: &str| s.parse::<Effort>().unwrap();
    for seed in 0..3u64 {
        for action in Action::ALL {
            let run = |s: &str| gesture(seed, &k, action, e(s));
            let summary = |name: &str| {
                let d = run(name);
                let (v, a) = kinematics(&d.log);
                let l = &d.labels[0];
                (l.end - l.start, max(&v), max(&a))
            };
            for w in ["strong", "light"] {
                let (d_sud, v_sud, _) = summary(&format!("sudden-{w}"));
                let (d_sus, v_sus, _) = summary(&format!("sustained-{w}"));
                assert!(d_sud < d_sus, "{action} {w}: duration {d_sud} vs {d_sus}");
                assert!(v_sud > v_sus, "{action} {w}: peak speed {v_sud} vs {v_sus}");
            }
            for t in ["sudden", "sustained"] {
                let (_, _, a_strong) = summary(&format!("{t}-strong"));
                let (_, _, a_light) = summary(&format!("{t}-light"));
                assert!(
                    a_strong > a_light,
                    "{action} {t}: peak accel {a_strong} vs {a_light}"
                );
            }
        }
    }
}

#[test]
fn quaternions_are_unit_and_both_signs_occur() {
    let flips = Knobs {
        sign: Some(SignMode::Flips),
        ..Knobs::default()
    };
    let d = sequence(21, &flips, 5, None);
    let mut neg_w = 0;
    for s in &d.log.samples {
        let n: f64 = s.quat.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((n - 1.0).abs() < 1e-9, "{n}");
        neg_w += usize::from(s.quat[0] < 0.0);
    }
    assert!(neg_w > 0);
    let sign_jumps = d
        .log
        .samples
        .windows(2)
        .filter(|w| quat(&w[0]).dot(quat(&w[1])) < 0.0)
        .count();
    assert!(sign_jumps > 0);
}

#[test]
fn files_round_trip_through_the_pose_log_reader() {
    let dir = scratch("roundtrip");
    let d = sequence(8, &Knobs::default(), 4, None);
    let csv = dir.join("seq.csv");
    let json = dir.join("seq.json");
    d.write_csv(&csv).unwrap();
    d.write_labels(&json).unwrap();
    let back = PoseLog::read_path(&csv).unwrap();
    assert_eq!(back.samples.len(), d.log.samples.len());
    for (a, b) in back.samples.iter().zip(&d.log.samples) {
        assert!((a.t - b.t).abs() < 1e-6 && (pos(a) - pos(b)).length() < 1e-5);
    }
    assert!(back.samples.windows(2).all(|w| w[1].t > w[0].t));
    let labels: Vec<Label> =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(labels.len(), d.labels.len());
    for (a, b) in labels.iter().zip(&d.labels) {
        assert_eq!(
            (&a.action, a.time_class, a.weight_class),
            (&b.action, b.time_class, b.weight_class)
        );
        assert!((a.start - b.start).abs() < 1e-9 && (a.end - b.end).abs() < 1e-9);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sets_cover_every_action_and_state() {
    let k = Knobs::default();
    let set = effort_set(2, &k, 3);
    assert_eq!(set.len(), 12);
    let mut seen: Vec<&str> = set
        .iter()
        .map(|(_, d)| d.labels[0].action.as_str())
        .collect();
    seen.sort_unstable();
    seen.dedup();
    assert_eq!(seen.len(), 12, "{seen:?}");
    for (state, d) in &set {
        assert_eq!(d.labels[0].time_class, state.time);
        assert_eq!(d.labels[0].weight_class, state.weight);
    }
    let ex = examples(4, &k, Action::Bow, 3, None);
    assert_eq!(ex.len(), 3);
    assert!(ex.iter().all(|d| d.labels[0].action == "bow"));
    assert_ne!(bytes(&ex[0].log), bytes(&ex[1].log));
}

#[test]
fn cli_writes_readable_logs_and_rejects_bad_flags() {
    let dir = scratch("cli");
    let exe = env!("CARGO_BIN_EXE_figurine");
    let run = |args: &[&str]| Command::new(exe).args(args).output().unwrap();
    let seq = dir.join("seq.csv");
    let lab = dir.join("seq.json");
    let out = run(&[
        "synth",
        "sequence",
        "--seed",
        "3",
        "--count",
        "3",
        "--out",
        seq.to_str().unwrap(),
        "--labels",
        lab.to_str().unwrap(),
        "--rate",
        "60",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let log = PoseLog::read_path(&seq).unwrap();
    assert!(log.samples.len() > 100);
    let labels: Vec<Label> = serde_json::from_str(&std::fs::read_to_string(&lab).unwrap()).unwrap();
    assert_eq!(labels.len(), 3);

    let set = dir.join("set");
    let out = run(&[
        "synth",
        "effort-set",
        "--seed",
        "1",
        "--per-class",
        "2",
        "--out",
        set.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for state in [
        "sudden-strong",
        "sudden-light",
        "sustained-strong",
        "sustained-light",
    ] {
        let n = std::fs::read_dir(set.join(state)).unwrap().count();
        assert_eq!(n, 2, "{state}");
    }
    let ex = dir.join("ex");
    let out = run(&[
        "synth",
        "examples",
        "--action",
        "wave",
        "--count",
        "3",
        "--seed",
        "2",
        "--out",
        ex.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(PoseLog::read_path(&ex.join("wave_3.csv")).is_ok());
    let png = dir.join("seq.png");
    let out = run(&[
        "synth",
        "plot",
        seq.to_str().unwrap(),
        "--labels",
        lab.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);

    for bad in [
        vec!["synth", "gesture", "--action", "moonwalk", "--out", "x.csv"],
        vec![
            "synth", "gesture", "--action", "jump", "--effort", "fast", "--out", "x.csv",
        ],
        vec![
            "synth", "gesture", "--action", "jump", "--rate", "1e9", "--out", "x.csv",
        ],
        vec![
            "synth", "sequence", "--count", "0", "--out", "x.csv", "--labels", "x.json",
        ],
    ] {
        let out = run(&bad);
        assert!(!out.status.success(), "{bad:?} should fail");
        assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
    }
    let _ = std::fs::remove_dir_all(&dir);
}
