//! The device's events are identical to in-process `figurine simulate` on the same log,
//! library and effort model: same actions, same start/end, same Lt/Lw bits.

use std::time::Instant;

use figurine_e2e::{pose6d, Qemu, QemuOptions};
use figurine_host::data::data_file;
use figurine_host::link::blobs::{self, Blobs};
use figurine_host::link::cli::upload_to;
use figurine_host::link::{replay_log, Device, ReplayOptions};
use figurine_host::poselog::PoseLog;
use figurine_host::recognize::eval::learn_synth_library;
use figurine_host::recognize::real_bench::{real_takes, take_doodle};
use figurine_host::recognize::simulate::simulate_log;
use figurine_host::synth::knobs::{Knobs, Range};
use figurine_host::synth::sequence::sequence;
use figurine_host::synth::{rest_log, RestKind, RestSpec, TrackerLevel};
use figurine_recognizer::EffortModel;

/// Samples of each real stream replayed (keeps the test within seconds).
const REAL_LIMIT: usize = 3000;

fn check_identical(dev: &mut Device, blobs: &Blobs, log: &PoseLog, what: &str) -> usize {
    let effort = EffortModel::from_bytes(&blobs.effort).expect("effort blob");
    let sim = simulate_log(log, &blobs.names, &blobs.library, Some(effort)).expect("simulate");
    let t = Instant::now();
    let got =
        replay_log(dev, log, &blobs.names, ReplayOptions::default(), |_, _| {}).expect("replay");
    eprintln!(
        "{what}: {} samples, {} events, replayed in {:.2} s",
        log.samples.len(),
        got.records.len(),
        t.elapsed().as_secs_f64()
    );
    assert_eq!(got.stats.samples_dropped, 0, "{what}: {:?}", got.stats);
    assert_eq!(got.unsendable, sim.unsendable, "{what}");
    assert_eq!(
        u64::from(got.stats.invalid_samples),
        u64::from(sim.stats.intake.skipped()),
        "{what}: invalid samples"
    );
    assert_eq!(got.records.len(), sim.records.len(), "{what}: event count");
    // The recognizer counts every emission, revisions included.
    let sim_revised = sim.stats.events - sim.events.len() as u32;
    assert_eq!(got.revised, sim_revised, "{what}: revisions");
    eprintln!("{what}: {sim_revised} revisions");
    for (i, (d, s)) in got.records.iter().zip(&sim.records).enumerate() {
        assert_eq!(d, s, "{what}: event {i}");
    }
    for ((d, _), s) in got.events.iter().zip(&sim.events) {
        assert_eq!(d.time, s.time_q, "{what}: Lt bits");
        assert_eq!(d.weight, s.weight_q, "{what}: Lw bits");
        assert_eq!(d.distance, s.distance);
        assert_eq!(d.end_seq, s.end_seq as u16);
        assert_eq!(u32::from(d.len), s.end_seq - s.start_seq);
    }
    got.records.len()
}

#[test]
fn device_events_match_simulation_on_synthetic_and_real_logs() {
    // A library learnt from synthetic examples (3 per action, as a user would), the default
    // effort model: the blobs a user's `figurine learn` + `upload` would put on the device.
    let t = Instant::now();
    let mut lib = learn_synth_library(7, 3, &Knobs::default()).expect("learn library");
    let defaults = blobs::load(None, None).expect("default effort model");
    let blobs = Blobs {
        names: lib.names(),
        library: lib.blob().expect("library blob"),
        effort: defaults.effort,
    };
    eprintln!(
        "learnt {} actions in {:.1} s",
        blobs.names.len(),
        t.elapsed().as_secs_f64()
    );
    let mut q = Qemu::start(&QemuOptions::default()).expect("start QEMU");
    let mut dev = q.connect().expect("connect");
    upload_to(&mut dev, &blobs, true).expect("upload");
    assert_eq!(dev.hello().library_crc, blobs::crc32(&blobs.library));

    let mut events = 0;
    let knobs = Knobs::default();
    for seed in [1u64, 2, 3] {
        let doodle = sequence(seed, &knobs, 4, None);
        events += check_identical(
            &mut dev,
            &blobs,
            &doodle.log,
            &format!("synthetic seed {seed}"),
        );
    }
    assert!(
        events > 0,
        "the synthetic sequences produced no events at all"
    );
    // A noisy tracker: the learnt noise floor (a 3×3 covariance, its inverse, medians) must
    // come out bit for bit the same on the device, or the events would differ.
    let noisy = Knobs {
        noise: Range::fixed(3.0),
        ..Knobs::default()
    };
    let mut noisy_events = 0;
    for seed in [4u64, 5] {
        let doodle = sequence(seed, &noisy, 4, None);
        noisy_events += check_identical(
            &mut dev,
            &blobs,
            &doodle.log,
            &format!("noise ×3, seed {seed}"),
        );
    }
    assert!(noisy_events > 0, "the noisy sequences produced no events");
    let rest = rest_log(
        6,
        &RestSpec {
            seconds: 60.0,
            kind: Some(RestKind::Hand),
            tracker: TrackerLevel::by_name("webcam-far"),
            ..RestSpec::default()
        },
    );
    check_identical(
        &mut dev,
        &blobs,
        &rest.log,
        "a minute held in a hand, webcam tag",
    );
    // A sequence with revised events (a cyclic action going on after a pause, or an action
    // reported early and then taken over by a longer one): the device's `Revised` messages
    // must match the simulation's.
    let defaults = blobs::load(None, None).expect("default blobs");
    let effort = EffortModel::from_bytes(&defaults.effort).expect("effort blob");
    let revised = (4u64..60)
        .map(|seed| sequence(seed, &knobs, 6, None))
        .find(|d| {
            let sim = simulate_log(&d.log, &defaults.names, &defaults.library, Some(effort))
                .expect("simulate");
            sim.stats.events > sim.events.len() as u32
        })
        .expect("no synthetic sequence with a revised event");
    upload_to(&mut dev, &defaults, true).expect("upload the default library");
    check_identical(&mut dev, &defaults, &revised.log, "revised events");
    // Real doodles: people's motion capture as figurine logs (`figurine eval real`).
    for take in real_takes().expect("real takes") {
        match take_doodle(&take) {
            Ok((d, _)) => {
                check_identical(&mut dev, &defaults, &d.log, &take.take);
            }
            Err(e) => eprintln!("skipping {}: {e}", take.take),
        }
    }
    upload_to(&mut dev, &blobs, true).expect("upload");

    for name in ["tum_fr1_xyz_groundtruth.txt", "euroc_v102_groundtruth.csv"] {
        let Some(path) = data_file("pose6d", name) else {
            eprintln!("skipping pose6d/{name}: run `cargo xtask setup`");
            continue;
        };
        let log = pose6d::read(&path, REAL_LIMIT).expect("pose6d log");
        check_identical(&mut dev, &blobs, &log, name);
    }
    assert!(q.exited().unwrap().is_none(), "the firmware died");
}
