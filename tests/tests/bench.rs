//! Firmware figures (run by `cargo xtask bench`; ignored by `cargo test`):
//!
//! ```text
//! cargo test -p figurine-e2e --release --test bench -- --ignored --nocapture --test-threads 1
//! ```
//!
//! * flash and static RAM of both boards' images (capacity: 32 actions);
//! * recognizer instructions per pose sample on the emulated Cortex-M4F, deterministic
//!   (`-icount shift=0`: 1 instruction = 1 ns of virtual time, SysTick at 25 MHz, so
//!   instructions = cycles × 40), with 1, 8 and 32 actions loaded;
//! * pose-in → event-out latency over the emulated link, and the highest sustained pose rate
//!   without drops (both bound by this machine's emulation speed, not the MCU's).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Duration;

use figurine_e2e::defmt_log::{cycle_reports, decode};
use figurine_e2e::elf::{image_size, newer_source};
use figurine_e2e::{firmware_elf, Qemu, QemuOptions};
use figurine_host::link::blobs::{self, Blobs};
use figurine_host::link::cli::upload_to;
use figurine_host::link::{replay_log, ReplayOptions};
use figurine_host::poselog::PoseLog;
use figurine_host::recognize::eval::learn_synth_library;
use figurine_host::recognize::library::LibraryFile;
use figurine_host::recognize::simulate::simulate_log;
use figurine_host::synth::knobs::Knobs;
use figurine_host::synth::sequence::sequence;
use figurine_recognizer::EffortModel;

/// Emulated instructions per SysTick cycle under `-icount shift=0` (1 GHz / 25 MHz).
const INSNS_PER_CYCLE: u64 = 40;

/// A warning when a firmware source changed after image `elf` was built (empty otherwise).
fn stale(elf: &Path) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    newer_source(&root, elf).map_or_else(String::new, |src| {
        format!(
            "\n  STALE: {} changed after this image was built; `cargo xtask firmware --board \
             qemu` (and `--board nrf52840`) rebuild it",
            src.strip_prefix(&root).unwrap_or(&src).display()
        )
    })
}

fn nrf_elf() -> PathBuf {
    std::env::var_os("FIGURINE_NRF_ELF").map_or_else(
        || {
            Path::new(env!("CARGO_MANIFEST_DIR")).join(
                "../firmware/app/target/nrf52840/thumbv7em-none-eabihf/release/figurine-firmware",
            )
        },
        PathBuf::from,
    )
}

/// The 12 learnt synthetic actions.
fn learnt() -> &'static LibraryFile {
    static LIB: OnceLock<LibraryFile> = OnceLock::new();
    LIB.get_or_init(|| learn_synth_library(7, 3, &Knobs::default()).expect("learn"))
}

/// A library of `n` actions (the learnt ones, repeated under new names past 12).
fn blobs_with(n: usize) -> Blobs {
    let base = learnt();
    let mut lib = LibraryFile::default();
    for i in 0..n {
        let mut a = base.actions[i % base.actions.len()].clone();
        if i >= base.actions.len() {
            a.name = format!("{}-{}", a.name, i / base.actions.len() + 1);
        }
        lib.actions.push(a);
    }
    Blobs {
        names: lib.names(),
        library: lib.blob().expect("library blob"),
        effort: blobs::load(None, None).expect("default effort").effort,
    }
}

fn bench_log() -> PoseLog {
    sequence(1, &Knobs::default(), 4, None).log
}

#[test]
#[ignore = "benchmark: run by `cargo xtask bench`"]
fn figure_image_sizes() {
    println!("firmware image (goal: flash <= 64 KiB, static RAM <= 24 KiB; capacity 32 actions)");
    for (board, elf) in [
        ("qemu mps2-an386", firmware_elf().ok()),
        ("nrf52840", Some(nrf_elf()).filter(|p| p.is_file())),
    ] {
        match elf.as_deref().map(|p| (image_size(p), p)) {
            Some((Ok(s), p)) => println!(
                "  {board:<16} flash {:>7} B ({:.1} KiB)   static RAM {:>6} B ({:.1} KiB){}",
                s.flash,
                s.flash as f64 / 1024.0,
                s.static_ram,
                s.static_ram as f64 / 1024.0,
                stale(p)
            ),
            Some((Err(e), _)) => println!("  {board:<16} {e}"),
            None => println!("  {board:<16} not built (cargo xtask firmware --board ...)"),
        }
    }
}

#[test]
#[ignore = "benchmark: run by `cargo xtask bench`"]
fn figure_instructions_per_sample() {
    let elf = firmware_elf().expect("QEMU firmware");
    let log = bench_log();
    println!(
        "recognizer instructions per pose sample, Cortex-M4F in QEMU -icount shift=0 \
         ({} samples of a synthetic 4-action sequence; goal <= 5000 at 32 actions){}",
        log.samples.len(),
        stale(&elf)
    );
    for n in [1usize, 8, 32] {
        let blobs = blobs_with(n);
        let mut q = Qemu::start(&QemuOptions {
            icount: true,
            ..QemuOptions::default()
        })
        .expect("start QEMU");
        let mut dev = q.connect().expect("connect");
        upload_to(&mut dev, &blobs, true).expect("upload");
        let r = replay_log(
            &mut dev,
            &log,
            &blobs.names,
            ReplayOptions::default(),
            |_, _| {},
        )
        .expect("replay");
        drop(dev);
        let path = q.log_path().to_path_buf();
        drop(q);
        let reports = decode(&elf, &path).and_then(|t| cycle_reports(&t));
        match reports.as_deref().map(|r| r.last()) {
            Ok(Some(c)) if c.samples > 0 => println!(
                "  {n:>2} actions: mean {:>6} instructions/sample, worst {:>7}  ({} samples, {} events)",
                c.total_cycles * INSNS_PER_CYCLE / c.samples,
                c.worst_cycles * INSNS_PER_CYCLE,
                c.samples,
                r.records.len()
            ),
            other => println!(
                "  {n:>2} actions: worst {:>7} instructions/sample (mean needs defmt-print: {other:?})",
                u64::from(r.stats.worst_sample_cycles) * INSNS_PER_CYCLE
            ),
        }
    }
}

#[test]
#[ignore = "benchmark: run by `cargo xtask bench`"]
fn figure_latency_and_sustained_rate() {
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "link figures (wall-clock, depend on this machine's load; load average {})",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    );
    let blobs = blobs_with(32);
    let log = bench_log();
    let effort = EffortModel::from_bytes(&blobs.effort).expect("effort");
    let sim = simulate_log(&log, &blobs.names, &blobs.library, Some(effort)).expect("simulate");
    let mut q = Qemu::start(&QemuOptions::default()).expect("start QEMU");
    let mut dev = q.connect().expect("connect");
    upload_to(&mut dev, &blobs, true).expect("upload");

    // Latency: real-time replay; an event's latency is its arrival minus the moment the
    // sample on which the recognizer decided it was sent.
    let r = replay_log(
        &mut dev,
        &log,
        &blobs.names,
        ReplayOptions {
            speed: Some(1.0),
            ..ReplayOptions::default()
        },
        |_, _| {},
    )
    .expect("real-time replay");
    let mut lat: Vec<f64> = r
        .events
        .iter()
        .zip(&sim.events)
        .filter_map(|((_, arrived), s)| {
            let sent = r.sent_at.get(s.decided_seq as usize).copied().flatten()?;
            let ms = arrived.saturating_duration_since(sent).as_secs_f64() * 1e3;
            let last = r.sent_at.iter().rposition(|x| x.is_some_and(|t| t <= *arrived));
            eprintln!(
                "    event decided at sample {} (end {}), arrived {ms:.2} ms later; last sample sent before arrival: {last:?}",
                s.decided_seq, s.end_seq
            );
            Some(ms)
        })
        .collect();
    lat.sort_by(f64::total_cmp);
    if lat.is_empty() {
        println!("pose-in -> event-out latency: no events decided in this log");
    } else {
        println!(
            "pose-in -> event-out latency over the emulated UART (32 actions, {} events): \
             median {:.2} ms, max {:.2} ms",
            lat.len(),
            lat[lat.len() / 2],
            lat[lat.len() - 1]
        );
    }

    // Sustained rate: replay on the clock alone at growing speed; the device drops what it
    // cannot process (its queue holds 32 messages). Past the emulated UART's byte rate the
    // frames queue up in front of the link instead, which ends the search too.
    let duration = log.samples.last().map_or(1.0, |s| s.t) - log.samples[0].t;
    let mut best = None;
    for speed in [1.0, 2.0, 4.0, 8.0, 12.0, 16.0, 20.0, 24.0, 32.0, 48.0, 64.0] {
        let rate = log.samples.len() as f64 / (duration / speed);
        let opts = ReplayOptions {
            speed: Some(speed),
            flow_control: false,
        };
        let r = match replay_log(&mut dev, &log, &blobs.names, opts, |_, _| {}) {
            Ok(r) => r,
            Err(e) => {
                println!("  {rate:>8.0} poses/s: link saturated ({e})");
                break;
            }
        };
        println!(
            "  {rate:>8.0} poses/s: {} dropped, queue high water {}",
            r.stats.samples_dropped, r.stats.pose_queue_high_water
        );
        if r.stats.samples_dropped > 0 {
            break;
        }
        best = Some(rate);
        std::thread::sleep(Duration::from_millis(100));
    }
    match best {
        Some(rate) => println!(
            "highest sustained pose rate with no drops over the emulated link: {rate:.0} poses/s \
             (32 actions)"
        ),
        None => println!("highest sustained pose rate with no drops: below the log's own rate"),
    }
}
