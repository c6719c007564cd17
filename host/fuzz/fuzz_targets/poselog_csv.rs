//! Fuzzes the pose-log CSV reader: any bytes give a log or an error naming a line, never a
//! panic; a log that reads back is written and re-read to the same number of samples.
#![no_main]

use std::path::Path;

use figurine_host::poselog::{PoseLog, PoseLogError};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    match PoseLog::read(data, Path::new("fuzz.csv")) {
        Ok(log) => {
            let mut out = Vec::new();
            log.write(&mut out).expect("writing to memory");
            let back = PoseLog::read(&out[..], Path::new("again.csv")).expect("re-read of our own output");
            assert_eq!(back.samples.len(), log.samples.len());
        }
        Err(PoseLogError::Malformed { line, .. }) => assert!(line >= 1),
        Err(PoseLogError::Io { .. }) => {}
    }
});
