//! Fuzzes the graph job manifest reader (JOB/manifest.json): a checked manifest or an error
//! naming the file, never a panic; an accepted manifest's tiles list their kernel tiles.
#![no_main]

use std::path::Path;

use figurine_host::graph::plan::parse_manifest;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("JOB/manifest.json");
    match parse_manifest(data, path) {
        Ok(m) => {
            for t in m.tiles.iter().take(4) {
                let _ = m.kernels(t);
            }
        }
        Err(e) => assert!(e.to_string().contains("manifest.json"), "{e}"),
    }
});
