//! Fuzzes the graph tile reader (JOB/tiles/tile-NNNNN.bin): a tile or an error naming the file,
//! never a panic; whatever it accepts encodes back to the same bytes.
#![no_main]

use std::path::Path;

use figurine_host::graph::tile::{encode_tile, parse_tile};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("tiles/tile-00000.bin");
    match parse_tile(data, path) {
        Ok(t) => assert_eq!(encode_tile(&t), data, "accepted tiles round-trip"),
        Err(e) => assert!(e.to_string().contains("tile-00000.bin"), "{e}"),
    }
});
