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
            let d = gesture(i as u64, &k, action, Effort::NEUTRAL);
            let l = &d.labels[0];
            (extent(&d.log), l.end - l.start)
        };
        let ((one, t_one), (half, _), (two, t_two)) = (at(1.0), at(0.5), at(2.0));
        let grow = 2f64.powf(figurine_host::synth::gesture::DURATION_SCALE_EXPONENT);
        // Strokes take scale^0.4 longer; still holds inside a gesture do not stretch.
        let stretch = t_two / t_one;
        assert!(
            stretch > 1.15 && stretch < grow + 1e-4,
            "{action}: {stretch}"
        );
        assert!(one > 0.005, "{action}: {one}");
        // Same path; bigger doodles also take longer, so sample instants differ (≤ 1 %).
        // Turns, spins, bows and waves move the tracked point mostly through the toy's own
        // size (the grip, the feet it pivots about), which does not grow with the doodle.
        if matches!(
            action,
            Action::Turn | Action::Spin | Action::Bow | Action::Wave
        ) {
            assert!(two >= one && two / one < 2.02, "{action}: {}", two / one);
            assert!(
                half <= one && half / one > 0.495,
                "{action}: {}",
                half / one
            );
        } else {
            assert!((two / one - 2.0).abs() < 0.02, "{action}: {}", two / one);
            assert!((half / one - 0.5).abs() < 0.005, "{action}: {}", half / one);
        }
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

#[test]
fn glitches_only_when_asked_and_they_survive_the_file_format() {
    let clean = sequence(31, &Knobs::default(), 3, None);
    assert!(clean
        .log
        .samples
        .iter()
        .all(|s| s.pos.iter().chain(&s.quat).all(|v| v.is_finite())));
    let k = Knobs {
        glitch: Range::fixed(0.05),
        ..Knobs::default()
    };
    let d = sequence(31, &k, 3, None);
    let s = &d.log.samples;
    let nan_rows = s.iter().filter(|x| x.pos[0].is_nan()).count();
    let zero_q = s.iter().filter(|x| x.quat == [0.0; 4]).count();
    let not_increasing = s.windows(2).filter(|w| w[1].t <= w[0].t).count();
    assert!(nan_rows > 0 && zero_q > 0 && not_increasing > 0);
    let dir = scratch("glitch");
    let csv = dir.join("g.csv");
    d.write_csv(&csv).unwrap();
    let back = PoseLog::read_path(&csv).unwrap();
    assert_eq!(back.samples.len(), s.len());
    assert_eq!(
        back.samples.iter().filter(|x| x.pos[0].is_nan()).count(),
        nan_rows
    );
    // Same path otherwise: glitches draw from their own stream.
    assert_eq!(d.labels, clean.labels);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn long_sequences_stay_in_the_room() {
    let k = Knobs {
        scale: Range::fixed(2.0),
        rate_hz: Range::fixed(30.0),
        ..Knobs::default()
    };
    let d = sequence(77, &k, 300, None);
    let far = d
        .log
        .samples
        .iter()
        .map(|s| s.pos[0].abs().max(s.pos[2].abs()))
        .fold(0.0, f64::max);
    // Room half-size 2 m + margin 0.3 m + the longest single run at scale 2 (≈ 3.5 m).
    assert!(far < 6.0, "wandered {far} m from the centre");
    assert_eq!(d.labels.len(), 300);
}

/// Unwrapped heading change (radians) of the figurine's front over a log.
fn total_yaw(log: &PoseLog) -> f64 {
    let mut total = 0.0;
    let mut prev: Option<f64> = None;
    for s in &log.samples {
        let f = quat(s) * DVec3::Z;
        let yaw = f.x.atan2(f.z);
        if let Some(p) = prev {
            let d = (yaw - p + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            total += d;
        }
        prev = Some(yaw);
    }
    total
}

#[test]
fn actions_move_the_way_the_conventions_say() {
    // Object frame: +Z front, +Y up, +X left; quaternion maps object to world.
    let k = Knobs {
        heading_deg: Range::fixed(37.0),
        ..Knobs::canonical()
    };
    for seed in 0..5 {
        let run = |a: Action| gesture(seed, &k, a, Effort::NEUTRAL).log;
        let first = |l: &PoseLog| l.samples[0];
        let last = |l: &PoseLog| *l.samples.last().unwrap();

        let walk = run(Action::Walk);
        let front = quat(&first(&walk)) * DVec3::Z;
        let moved = pos(&last(&walk)) - pos(&first(&walk));
        assert!(moved.normalize().dot(front) > 0.9, "walk goes forward");
        assert!(walk
            .samples
            .iter()
            .any(|s| s.pos[1] > walk.samples[0].pos[1] + 0.01));

        let side = run(Action::Sidestep);
        let left = quat(&first(&side)) * DVec3::X;
        let moved = pos(&last(&side)) - pos(&first(&side));
        assert!(
            moved.normalize().dot(left).abs() > 0.9,
            "sidestep goes sideways"
        );

        let jump = run(Action::Jump);
        let y0 = jump.samples[0].pos[1];
        let top = jump
            .samples
            .iter()
            .map(|s| s.pos[1])
            .fold(f64::MIN, f64::max);
        assert!(top - y0 > 0.1, "jump rises {}", top - y0);

        let crouch = run(Action::Crouch);
        let low = crouch
            .samples
            .iter()
            .map(|s| s.pos[1])
            .fold(f64::MAX, f64::min);
        assert!(crouch.samples[0].pos[1] - low > 0.03, "crouch sinks");

        let bow = run(Action::Bow);
        let deepest = bow
            .samples
            .iter()
            .map(|s| (quat(s) * DVec3::Z).y)
            .fold(f64::MAX, f64::min);
        assert!(deepest < -0.4, "bow tips the front down: {deepest}");

        let turn = total_yaw(&run(Action::Turn)).abs().to_degrees();
        assert!((85.0..=185.0).contains(&turn), "turn {turn}°");
        let spin = total_yaw(&run(Action::Spin)).abs().to_degrees();
        assert!((315.0..=405.0).contains(&spin), "spin {spin}°");

        let wave = run(Action::Wave);
        let rolls: Vec<f64> = wave
            .samples
            .iter()
            .map(|s| (quat(s) * DVec3::Y).dot(quat(&wave.samples[0]) * DVec3::X))
            .collect();
        let swings = rolls
            .windows(2)
            .filter(|w| (w[0] > 0.05 && w[1] <= 0.05) || (w[0] < -0.05 && w[1] >= -0.05))
            .count();
        assert!(swings >= 4, "wave swings {swings}");
        let drift = (pos(&last(&wave)) - pos(&first(&wave))).length();
        assert!(drift < 0.01, "wave stays put: {drift}");

        let punch = run(Action::Punch);
        let front = quat(&first(&punch)) * DVec3::Z;
        let reach = punch
            .samples
            .iter()
            .map(|s| (pos(s) - pos(&punch.samples[0])).dot(front))
            .fold(f64::MIN, f64::max);
        assert!(reach > 0.08, "punch reaches forward {reach}");
    }
}

/// Speed of a log smoothed by central differences over ±`h` seconds, m/s, with sample times.
fn smoothed_speed(s: &[PoseSample], h: f64) -> Vec<f64> {
    let n = s.len();
    (0..n)
        .map(|i| {
            let j = (0..=i).rev().find(|&j| s[i].t - s[j].t >= h).unwrap_or(0);
            let k = (i..n).find(|&k| s[k].t - s[i].t >= h).unwrap_or(n - 1);
            if s[k].t > s[j].t {
                (pos(&s[k]) - pos(&s[j])).length() / (s[k].t - s[j].t)
            } else {
                0.0
            }
        })
        .collect()
}

/// Best accuracy of a single threshold on `x` separating `y`, either direction.
fn threshold_accuracy(mut xy: Vec<(f64, bool)>) -> f64 {
    xy.sort_by(|a, b| a.0.total_cmp(&b.0));
    let n = xy.len();
    let positives = xy.iter().filter(|p| p.1).count();
    let mut best = 0;
    let mut pos_below = 0;
    for i in 0..=n {
        if i > 0 && xy[i - 1].1 {
            pos_below += 1;
        }
        let right = (i - pos_below) + (positives - pos_below);
        best = best.max(right.max(n - right));
    }
    best as f64 / n as f64
}

#[test]
fn effort_classes_are_learnable_from_scale_free_cues() {
    // Default (wide, noisy) knobs, pooled over all actions: Time shows in the duration, Weight
    // in how abruptly strokes stop compared with how they start (peak deceleration over peak
    // acceleration of the smoothed speed). One threshold per cue must already separate them.
    let set = effort_set(99, &Knobs::default(), 30);
    let mut time = Vec::new();
    let mut weight = Vec::new();
    for (e, d) in &set {
        let l = &d.labels[0];
        let s: Vec<PoseSample> = d
            .log
            .samples
            .iter()
            .filter(|s| s.t >= l.start - 0.1 && s.t <= l.end + 0.1)
            .copied()
            .collect();
        let h = 0.015;
        let v = smoothed_speed(&s, h);
        let (mut up, mut down) = (0.0f64, 0.0f64);
        let n = s.len();
        for i in 0..n {
            let j = (0..=i).rev().find(|&j| s[i].t - s[j].t >= h).unwrap_or(0);
            let k = (i..n).find(|&k| s[k].t - s[i].t >= h).unwrap_or(n - 1);
            if s[k].t > s[j].t {
                let a = (v[k] - v[j]) / (s[k].t - s[j].t);
                up = up.max(a);
                down = down.max(-a);
            }
        }
        time.push(((l.end - l.start).ln(), e.time == TimeClass::Sudden));
        weight.push(((down / up).ln(), e.weight == WeightClass::Strong));
    }
    let (t, w) = (threshold_accuracy(time), threshold_accuracy(weight));
    eprintln!("single-threshold accuracy: Time {t:.3}, Weight {w:.3}");
    assert!(t >= 0.85, "Time from duration: {t}");
    assert!(w >= 0.75, "Weight from stop/start sharpness: {w}");
}

/// The golden doodle: `figurine synth gesture --action jump --effort sudden-strong --seed 1
/// --rate 30 --out host/tests/golden/synth_jump_seed1.csv`. Regenerate it (after an intended
/// change of the generator) with `FIGURINE_BLESS=1 cargo test -p figurine-host --test synth golden`.
#[test]
fn golden_doodle_is_unchanged() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden/synth_jump_seed1.csv");
    let k = Knobs {
        rate_hz: Range::fixed(30.0),
        ..Knobs::default()
    };
    let d = gesture(1, &k, Action::Jump, "sudden-strong".parse().unwrap());
    let scratch_dir = scratch("golden");
    let fresh = scratch_dir.join("fresh.csv");
    d.write_csv(&fresh).unwrap();
    let fresh_text = std::fs::read_to_string(&fresh).unwrap();
    let _ = std::fs::remove_dir_all(&scratch_dir);
    if std::env::var_os("FIGURINE_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &fresh_text).unwrap();
    }
    let golden = std::fs::read_to_string(&path).expect("golden file (bless with FIGURINE_BLESS=1)");
    assert_eq!(
        fresh_text, golden,
        "the generator's output changed for a fixed seed; if intended, re-bless the golden file"
    );
}

mod arbitrary_knobs {
    use super::*;
    use proptest::prelude::*;

    fn range(lo: f64, hi: f64) -> impl Strategy<Value = Range> {
        (lo..=hi, lo..=hi).prop_map(|(a, b)| Range::new(a, b))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Any valid knob setting gives a well-formed, labelled, finite log.
        #[test]
        fn any_valid_knobs_give_a_well_formed_log(
            seed in any::<u64>(),
            count in 1usize..4,
            rate in range(5.0, 400.0),
            jitter in range(0.0, 0.45),
            drop in range(0.0, 0.5),
            scale in range(0.01, 5.0),
            speed in range(0.05, 5.0),
            heading in range(-720.0, 720.0),
            tilt in range(0.0, 60.0),
            noise in range(0.0, 10.0),
            t0 in range(-1000.0, 1000.0),
            pause in range(0.0, 2.0),
        ) {
            let k = Knobs {
                rate_hz: rate, jitter, drop, scale, speed, heading_deg: heading, tilt_deg: tilt,
                noise, t0, pause_s: pause, lead_s: pause,
                ..Knobs::default()
            };
            prop_assert!(k.validate().is_ok());
            let d = sequence(seed, &k, count, None);
            let s = &d.log.samples;
            prop_assert!(s.len() >= 2);
            prop_assert!(s.windows(2).all(|w| w[1].t > w[0].t));
            for x in s {
                prop_assert!(x.pos.iter().chain(&x.quat).all(|v| v.is_finite()));
                let n: f64 = x.quat.iter().map(|v| v * v).sum::<f64>().sqrt();
                prop_assert!((n - 1.0).abs() < 1e-9);
            }
            prop_assert_eq!(d.labels.len(), count);
            for l in &d.labels {
                prop_assert!(l.start < l.end && l.start >= s[0].t && l.end <= s[s.len() - 1].t);
            }
        }
    }
}
