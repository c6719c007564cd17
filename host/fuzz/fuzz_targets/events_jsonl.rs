//! Fuzzes the JSON-lines event reader: events or an error naming a line, never a panic.
#![no_main]

use std::path::Path;

use figurine_host::events::read_events;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(events) = read_events(data, Path::new("fuzz.jsonl")) {
        for e in &events {
            assert!(e.start.is_finite() && e.end >= e.start);
        }
    }
});
