//! Recognizer throughput: host ns per pose sample with 32 loaded actions, and `simulate`
//! samples per second (wire quantisation + recognizer + event conversion).
//!
//! Run: `cargo bench -p figurine-host --bench recognizer`. Criterion prints the throughput
//! (elements = pose samples); ns/sample = 1e9 / (elements/s).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use figurine_host::recognize::feed::log_samples;
use figurine_host::recognize::library::LibraryFile;
use figurine_host::recognize::simulate::{load_effort, load_library, simulate_log};
use figurine_host::synth::{self, Knobs};
use figurine_recognizer::{Library, Recognizer};

/// The default 12 actions repeated (as a0, a1 …) up to the device's 32.
fn library_32() -> Vec<u8> {
    let base = LibraryFile::default_library().unwrap();
    let mut lib = LibraryFile::default();
    for i in 0..32 {
        let mut a = base.actions[i % base.actions.len()].clone();
        a.name = format!("a{i}");
        lib.actions.push(a);
    }
    lib.blob().unwrap()
}

fn bench(c: &mut Criterion) {
    // ~2 minutes of play: 40 actions with pauses, 30–240 Hz.
    let d = synth::sequence(77, &Knobs::default(), 40, None);
    let (samples, _) = log_samples(&d.log);
    let blob = library_32();
    let lib = Library::from_bytes(&blob).unwrap();
    let effort = load_effort(None).unwrap();

    let mut g = c.benchmark_group("recognizer");
    g.throughput(Throughput::Elements(samples.len() as u64));
    g.bench_function("push_32_actions", |b| {
        b.iter(|| {
            let mut rec = Recognizer::new(lib, Some(effort));
            let mut n = 0u32;
            for (_, s) in &samples {
                rec.push(s, |_| n += 1);
            }
            n
        })
    });
    let (names, default_blob) = {
        let (l, b) = load_library(None).unwrap();
        (l.names(), b)
    };
    g.throughput(Throughput::Elements(d.log.samples.len() as u64));
    g.bench_function("simulate_log_default_library", |b| {
        b.iter(|| {
            simulate_log(&d.log, &names, &default_blob, Some(effort))
                .unwrap()
                .records
                .len()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
