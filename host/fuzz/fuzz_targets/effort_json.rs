//! Fuzzes the effort-model JSON loader (EFFORT.json): a validated model or an error, never a
//! panic; whatever it accepts must produce a model and a device blob.
#![no_main]

use figurine_host::recognize::effort_model::EffortFile;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(f) = EffortFile::from_json(text) {
        assert!(f.model().is_ok(), "an accepted effort model must load");
        assert!(f.blob().is_ok(), "an accepted effort model must build its blob");
    }
});
