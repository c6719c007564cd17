//! Soak: a 1 kHz pose stream into the real firmware in QEMU, for minutes, with a learnt
//! library loaded. Outside the normal suite (`#[ignore]`); run it with
//!
//! ```text
//! FIGURINE_SOAK_SECONDS=600 cargo test -p figurine-e2e --test soak -- --ignored --nocapture
//! ```
//!
//! `FIGURINE_SOAK_SECONDS` (default 600) is the duration, `FIGURINE_SOAK_RATE_HZ` (default
//! 1000) the pose rate. Asserts 0 dropped samples, 0 sequence gaps and that every sample
//! sent arrived; prints the queue high-water marks, the worst per-sample cycle count, how
//! late the host ever was against the schedule, and how far the device fell behind.
//!
//! Statistics are asked for without pausing the stream, and the time each answer takes is
//! the device's lag. On QEMU the lag is the emulator's, not the firmware's: the CMSDK UART
//! model holds one byte, so each byte is a hand-over between QEMU's I/O and CPU threads, and
//! at 1 kHz (≈ 25 bytes a pose) that takes about one host core. When the host is busy the
//! bytes wait in the socket and the lag grows; nothing is lost. The firmware's own margin shows
//! in the pose-queue high-water mark: the queue never fills, so samples are never dropped.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use figurine_e2e::{Qemu, QemuOptions};
use figurine_host::link::blobs::{self, Blobs};
use figurine_host::link::cli::upload_to;
use figurine_host::recognize::eval::learn_synth_library;
use figurine_host::synth::knobs::Knobs;
use figurine_host::synth::sequence::sequence;
use figurine_protocol::{DeviceToHost, HostToDevice, Pose, Stats};

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

/// Seconds the host waits, once the stream has ended, for the device to answer the final
/// `GetStats` (it answers after every pose sent before it has been processed).
const DRAIN_TIMEOUT_S: u64 = 120;

/// Keeps every host core busy at the lowest priority while the stream runs (one
/// `nice -n 19` spinning shell per core), and stops them when dropped.
///
/// Why: QEMU hands each received byte from its I/O thread to its CPU thread (the emulated UART
/// holds one byte), ≈ 50 000 thread wake-ups a second at 1 kHz. On a virtual machine whose
/// cores are idle, each wake-up first has to bring a sleeping core back (a hypervisor exit),
/// and the emulator then moved only ≈ 700 poses/s: the device's lag grew by ≈ 3 s every 10 s.
/// With the cores kept awake by work of the lowest priority, which yields to QEMU and the
/// sender at once, the same run caught up (see RELIABILITY.md). Set
/// `FIGURINE_SOAK_KEEP_AWAKE=0` to measure without it.
struct KeepAwake(Vec<std::process::Child>);

impl KeepAwake {
    fn start() -> KeepAwake {
        if std::env::var("FIGURINE_SOAK_KEEP_AWAKE").is_ok_and(|v| v.trim() == "0") {
            return KeepAwake(Vec::new());
        }
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let spinners = (0..cores)
            .filter_map(|_| {
                std::process::Command::new("nice")
                    .args(["-n", "19", "sh", "-c", "while :; do :; done"])
                    .stdin(std::process::Stdio::null())
                    .spawn()
                    .ok()
            })
            .collect::<Vec<_>>();
        println!(
            "soak: {} lowest-priority spinners keep the host cores awake",
            spinners.len()
        );
        KeepAwake(spinners)
    }
}

impl Drop for KeepAwake {
    fn drop(&mut self) {
        for c in &mut self.0 {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// What the device has reported so far.
#[derive(Default)]
struct Progress {
    /// `GetStats` requests in flight: when sent, and after how many poses (answered in order).
    asked: VecDeque<(Instant, u64)>,
    /// Latest statistics.
    last: Option<Stats>,
    /// Action events received.
    events: usize,
    /// Longest time a `GetStats` waited for its answer: how far the device fell behind.
    worst_lag: Duration,
    /// That wait for the latest answer.
    last_lag: Duration,
}

impl Progress {
    /// Takes one message from the device; a `Stats` answer prints a progress line and checks
    /// that nothing was dropped.
    fn take(&mut self, m: DeviceToHost, base_dropped: u32, worst_late: Duration) {
        match m {
            DeviceToHost::Event(_) | DeviceToHost::Revised(_) => self.events += 1,
            DeviceToHost::Stats(s) => {
                let (asked, poses) = self.asked.pop_front().expect("an unasked Stats");
                self.last_lag = asked.elapsed();
                self.worst_lag = self.worst_lag.max(self.last_lag);
                println!(
                    "soak {poses:>7} poses: {}, host worst lateness {worst_late:.2?}, device \
                     lag {:.2?}",
                    line(&s),
                    self.last_lag
                );
                assert_eq!(s.samples_dropped, base_dropped, "samples dropped: {s:?}");
                self.last = Some(s);
            }
            DeviceToHost::Hello(_) => panic!("the device rebooted during the soak"),
            DeviceToHost::Error(e) => panic!("device error during the soak: {e:?}"),
            _ => {}
        }
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

    let _awake = KeepAwake::start();
    let start = Instant::now();
    let mut worst_late = Duration::ZERO;
    let mut cursor = 0usize;
    let mut progress = Progress::default();
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
            // Asked without waiting: the stream goes on, and the answer's delay is how far
            // the device's processing is behind what the host has sent.
            dev.send(&HostToDevice::GetStats).expect("send GetStats");
            progress.asked.push_back((Instant::now(), i + 1));
        }
        while let Some(m) = dev.poll(Duration::ZERO).expect("link") {
            progress.take(m, base.samples_dropped, worst_late);
        }
    }
    dev.send(&HostToDevice::GetStats).expect("send GetStats");
    progress.asked.push_back((Instant::now(), total));
    let drain_end = Instant::now() + Duration::from_secs(DRAIN_TIMEOUT_S);
    while !progress.asked.is_empty() {
        let left = drain_end.saturating_duration_since(Instant::now());
        match dev.poll(left).expect("link") {
            Some(m) => progress.take(m, base.samples_dropped, worst_late),
            None => panic!(
                "the device did not work through its backlog within {DRAIN_TIMEOUT_S} s \
                 after the stream ended"
            ),
        }
    }
    let s = progress.last.expect("final statistics");
    let elapsed = start.elapsed();
    println!(
        "soak done: {total} poses in {:.1} s ({:.0} Hz achieved), {} events; {}; host \
         worst lateness {worst_late:.2?}; device lag worst {:.2?}, at the end {:.2?}",
        elapsed.as_secs_f64(),
        total as f64 / elapsed.as_secs_f64(),
        progress.events,
        line(&s),
        progress.worst_lag,
        progress.last_lag,
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
