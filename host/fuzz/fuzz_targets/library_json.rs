//! Fuzzes the library JSON loader (LIB.json): a validated library or an error, never a panic;
//! whatever it accepts must compile to a device blob again.
#![no_main]

use figurine_host::recognize::library::LibraryFile;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(mut lib) = LibraryFile::from_json(text) {
        assert!(lib.blob().is_ok(), "an accepted library must build its blob");
    }
});
