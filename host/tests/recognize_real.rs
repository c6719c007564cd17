//! Real 6-DoF streams (a handheld camera, a drone): decimating them from their native rate to
//! 50 and 30 Hz leaves the token string stable, and nothing panics.
//!
//! Bound: the normalised edit distance between the token string at the native rate and at a
//! decimated rate (distance / longer length) stays ≤ [`MAX_TOKEN_DRIFT`] = 0.2. Measured
//! (2026-11): TUM fr1_xyz 0.069 at 50 Hz, 0.121 at 30 Hz; EuRoC V1_02 0.012 and 0.028.

use figurine_host::data::data_file;
use figurine_host::poselog::{PoseLog, PoseSample};
use figurine_host::recognize::columns::edit_distance;
use figurine_host::recognize::feed::{log_runs, log_samples};
use figurine_host::recognize::simulate::{load_effort, load_library, simulate_log};
use figurine_recognizer::token::{Token, STILL};

/// Largest accepted normalised token edit distance between rates.
const MAX_TOKEN_DRIFT: f64 = 0.2;

/// TUM RGB-D ground truth: `timestamp tx ty tz qx qy qz qw` (w last), '#' comments.
fn read_tum(text: &str) -> PoseLog {
    let samples = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .filter_map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .filter_map(|x| x.parse().ok())
                .collect();
            (v.len() >= 8).then(|| PoseSample {
                t: v[0],
                pos: [v[1], v[2], v[3]],
                quat: [v[7], v[4], v[5], v[6]],
            })
        })
        .collect();
    PoseLog { samples }
}

/// EuRoC ground truth CSV: `timestamp_ns, px, py, pz, qw, qx, qy, qz, …` (w first).
fn read_euroc(text: &str) -> PoseLog {
    let samples = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .filter_map(|l| {
            let v: Vec<f64> = l.split(',').filter_map(|x| x.trim().parse().ok()).collect();
            (v.len() >= 8).then(|| PoseSample {
                t: v[0] * 1e-9,
                pos: [v[1], v[2], v[3]],
                quat: [v[4], v[5], v[6], v[7]],
            })
        })
        .collect();
    PoseLog { samples }
}

/// Keeps samples at least `1/rate_hz` apart (real decimation of a jittery clock).
fn decimate(log: &PoseLog, rate_hz: f64) -> PoseLog {
    let mut out = Vec::new();
    let mut next = f64::NEG_INFINITY;
    for s in &log.samples {
        if s.t >= next - 1e-6 {
            out.push(*s);
            next = s.t + 1.0 / rate_hz;
        }
    }
    PoseLog { samples: out }
}

fn tokens(log: &PoseLog) -> Vec<Token> {
    let (samples, _) = log_samples(log);
    log_runs(&samples)
        .iter()
        .map(|r| r.token)
        .filter(|&t| t != STILL)
        .collect()
}

fn drift(a: &[Token], b: &[Token]) -> f64 {
    edit_distance(a, b) as f64 / a.len().max(b.len()).max(1) as f64
}

fn check(name: &str, log: PoseLog) {
    assert!(log.samples.len() > 1000, "{name}: parsed too few samples");
    let full = tokens(&log);
    assert!(full.len() > 10, "{name}: only {} tokens", full.len());
    for rate in [50.0, 30.0] {
        let low = tokens(&decimate(&log, rate));
        let d = drift(&full, &low);
        eprintln!(
            "{name}: {} tokens native, {} at {rate} Hz, drift {d:.3}",
            full.len(),
            low.len()
        );
        assert!(d <= MAX_TOKEN_DRIFT, "{name} at {rate} Hz: drift {d:.3}");
    }
    // The whole recognizer runs over it without panicking, and counts what it skips.
    let (lib, blob) = load_library(None).unwrap();
    let sim = simulate_log(&log, &lib.names(), &blob, Some(load_effort(None).unwrap())).unwrap();
    assert!(
        sim.stats.intake.accepted as usize + sim.stats.intake.skipped() as usize
            <= log.samples.len()
    );
}

#[test]
fn tum_handheld_camera_is_stable_under_decimation() {
    let Some(p) = data_file("pose6d", "tum_fr1_xyz_groundtruth.txt") else {
        eprintln!("skipping: pose6d/tum_fr1_xyz_groundtruth.txt absent; run `cargo xtask setup`");
        return;
    };
    check(
        "tum_fr1_xyz",
        read_tum(&std::fs::read_to_string(p).unwrap()),
    );
}

#[test]
fn euroc_drone_is_stable_under_decimation() {
    let Some(p) = data_file("pose6d", "euroc_v102_groundtruth.csv") else {
        eprintln!("skipping: pose6d/euroc_v102_groundtruth.csv absent; run `cargo xtask setup`");
        return;
    };
    check(
        "euroc_v102",
        read_euroc(&std::fs::read_to_string(p).unwrap()),
    );
}
