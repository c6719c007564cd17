//! Fuzzes the BVH importer: any text gives a clip or an error, never a panic; an imported
//! clip exports to BVH that imports again with the same joint and frame counts.
#![no_main]

use std::path::Path;

use figurine_host::motion::bvh_export::write_bvh_string;
use figurine_host::motion::bvh_import::read_bvh;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(imported) = read_bvh(text, Path::new("fuzz.bvh")) {
        let clip = imported.clip;
        if let Ok(again) = write_bvh_string(&clip) {
            let back = read_bvh(&again, Path::new("again.bvh")).expect("re-import of our own BVH");
            assert_eq!(back.clip.skeleton.joints.len(), clip.skeleton.joints.len());
            assert_eq!(back.clip.frames.len(), clip.frames.len());
        }
    }
});
