//! Fuzzes the blob decoders: arbitrary bytes as a library or effort blob never panic, and a
//! library that decodes can drive the recognizer.
#![no_main]

use figurine_recognizer::{EffortModel, Library, Recognizer, Sample};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = EffortModel::from_bytes(data);
    if let Ok(lib) = Library::from_bytes(data) {
        let mut rec = Recognizer::new(lib, None);
        for i in 0..300u32 {
            let a = i as f32 * 0.05;
            let s = Sample {
                seq: i,
                t_us: u64::from(i) * 8_000,
                pos: [libm::sinf(a) * 0.2, 1.0 + libm::cosf(a * 1.7) * 0.1, a * 0.05],
                quat: [libm::cosf(a * 0.3), 0.0, libm::sinf(a * 0.3), 0.0],
            };
            rec.push(&s, |_| {});
        }
        rec.flush(|_| {});
    }
});
