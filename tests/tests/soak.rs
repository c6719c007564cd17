//! Soak: a 1 kHz pose stream into the real firmware in QEMU, for minutes, with a learnt
//! library loaded. Outside the normal suite (`#[ignore]`); run it with
//!
//! ```text
//! FIGURINE_SOAK_SECONDS=600 cargo test -p figurine-e2e --test soak -- --ignored --nocapture
//! ```
//!
//! `FIGURINE_SOAK_SECONDS` (default 600) is the duration, `FIGURINE_SOAK_RATE_HZ` (default
//! 1000) the pose rate. Asserts 0 dropped samples, 0 sequence gaps and that every sample
//! sent arrived; prints the queue high-water marks, the worst per-sample cycle count and how
//! late the host ever was against the schedule.

use std::time::{Duration, Instant};

use figurine_e2e::{Qemu, QemuOptions};
use figurine_host::link::blobs::{self, Blobs};
use figurine_host::link::cli::upload_to;
use figurine_host::recognize::eval::learn_synth_library;
use figurine_host::synth::knobs::Knobs;
use figurine_host::synth::sequence::sequence;
use figurine_protocol::{HostToDevice, Pose, Stats};

/// Seconds to stream unless `FIGURINE_SOAK_SECONDS` says otherwise.
const DEFAULT_SECONDS: u64 = 600;
/// Poses per second unless `FIGURINE_SOAK_RATE_HZ` says otherwise.
const DEFAULT_RATE_HZ: u64 = 1000;
/// Seconds between progress lines (each one a `GetStats` round trip).
const REPORT_EVERY_S: u64 = 10;

fn env_u64(name: &str, default: u64) -> u64 {
    match std::env::var(name) {
        Ok(v) => v
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("{name}={v:?} is not a whole number")),
        Err(_) => default,
    }
}

fn line(s: &Stats) -> String {
    format!(
        "samples {} (invalid {}), dropped {}, seq gaps {}, events {}, frames ok {} rejected {}, \
         pose queue high-water {}, tx queue high-water {}, worst sample {} cycles",
        s.samples,
        s.invalid_samples,
        s.samples_dropped,
        s.seq_gaps,
        s.events,
        s.frames_ok,
        s.crc_errors + s.cobs_errors + s.decode_errors + s.oversize,
        s.pose_queue_high_water,
        s.tx_queue_high_water,
        s.worst_sample_cycles
    )
}

#[test]
#[ignore = "minutes long: run with --ignored (cargo xtask soak)"]
fn soak_1khz_pose_stream() {
    let seconds = env_u64("FIGURINE_SOAK_SECONDS", DEFAULT_SECONDS);
    let rate = env_u64("FIGURINE_SOAK_RATE_HZ", DEFAULT_RATE_HZ).max(1);
    let total = seconds * rate;
    let period = Duration::from_nanos(1_000_000_000 / rate);

    // The device works as in use: a learnt library and the default effort model.
    let mut lib = learn_synth_library(7, 3, &Knobs::default()).expect("learn library");
    let defaults = blobs::load(None, None).expect("default effort model");
    let blobs = Blobs {
        names: lib.names(),
        library: lib.blob().expect("library blob"),
        effort: defaults.effort,
    };
    // Motion: a long synthetic doodle, resampled at `rate` (sample-and-hold), looped.
    let doodle = sequence(11, &Knobs::default(), 60, None).log;
    let log = &doodle.samples;
    assert!(log.len() > 1, "empty synthetic doodle");
    let (t_first, t_last) = (log[0].t, log[log.len() - 1].t);
    let span = (t_last - t_first).max(1.0);

    let mut q = Qemu::start(&QemuOptions::default()).expect("start QEMU");
    let mut dev = q.connect().expect("connect");
    upload_to(&mut dev, &blobs, true).expect("upload");
    dev.reset().expect("reset");
    let base = dev.stats().expect("stats");
    println!(
        "soak: {seconds} s at {rate} Hz = {total} poses, {} actions loaded",
        blobs.names.len()
    );

    let start = Instant::now();
    let mut worst_late = Duration::ZERO;
    let mut cursor = 0usize;
    let mut events = 0usize;
    let mut next_report = REPORT_EVERY_S;
    for i in 0..total {
        let due = start + period * i as u32;
        let now = Instant::now();
        if due > now {
            std::thread::sleep(due - now);
        } else {
            worst_late = worst_late.max(now - due);
        }
        let t = i as f64 / rate as f64;
        let t_log = t_first + t % span;
        if t_log < log[cursor].t {
            cursor = 0;
        }
        while cursor + 1 < log.len() && log[cursor + 1].t <= t_log {
            cursor += 1;
        }
        let s = &log[cursor];
        let pose = Pose::quantize(i as u16, t, s.pos, s.quat).expect("pose in range");
        dev.send(&HostToDevice::Pose(pose)).expect("send pose");
        if (i + 1) % (REPORT_EVERY_S * rate) == 0 {
            events += dev.take_events().expect("events").len();
            let s = dev.stats().unwrap_or_else(|e| {
                panic!(
                    "after {} poses ({:.1} s): the device fell behind, GetStats unanswered \
                     ({e}); host worst lateness {worst_late:.2?}",
                    i + 1,
                    start.elapsed().as_secs_f64()
                )
            });
            println!(
                "soak {:>5} s: {}, host worst lateness {:.2?}",
                next_report,
                line(&s),
                worst_late
            );
            next_report += REPORT_EVERY_S;
            assert_eq!(s.samples_dropped, base.samples_dropped, "samples dropped");
        }
    }
    dev.ping().expect("final ping");
    events += dev.take_events().expect("events").len();
    let s = dev.stats().expect("stats");
    let elapsed = start.elapsed();
    println!(
        "soak done: {total} poses in {:.1} s ({:.0} Hz achieved), {events} events; {}; host \
         worst lateness {worst_late:.2?}",
        elapsed.as_secs_f64(),
        total as f64 / elapsed.as_secs_f64(),
        line(&s)
    );
    assert_eq!(s.samples_dropped, 0, "dropped samples: {s:?}");
    assert_eq!(s.seq_gaps, 0, "sequence gaps: {s:?}");
    assert_eq!(u64::from(s.samples), total, "samples lost: {s:?}");
    assert_eq!(
        s.crc_errors + s.cobs_errors + s.decode_errors + s.oversize,
        0,
        "{s:?}"
    );
    assert!(q.exited().unwrap().is_none(), "the firmware died");
}
