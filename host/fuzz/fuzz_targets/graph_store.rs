//! Fuzzes the feature store readers (JOB/features.arrow) that every tile and the merge run. An
//! input is a frame count (u32, little-endian), a plan id (u64) and the file's bytes; the store
//! is opened for that plan and frame count, then read as a tile reads it (its five search
//! columns) and as the merge does (the LMA column of a one-clip library's windows). Whatever
//! the bytes: values or an error naming the file, never a panic or a runaway allocation.
#![no_main]

use figurine_host::graph::lma::MEASUREMENTS;
use figurine_host::graph::store::{Store, BATCH_ROWS};
use figurine_host::graph::WINDOW;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (Some(frames), Some(plan), Some(file)) = (
        data.get(..4).and_then(|b| b.try_into().ok()),
        data.get(4..12).and_then(|b| b.try_into().ok()),
        data.get(12..),
    ) else {
        return;
    };
    // At most two record batches: enough for every code path, bounded memory.
    let frames = u32::from_le_bytes(frames) as usize % (2 * BATCH_ROWS + 1);
    let plan = u64::from_le_bytes(plan);
    // The readers take a path: each process writes its inputs to a file of its own.
    let dir = std::env::temp_dir().join(format!("figurine-fuzz-store-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let path = dir.join("features.arrow");
    std::fs::write(&path, file).expect("temporary file");
    let named = |e: figurine_host::graph::GraphError| {
        let text = e.to_string();
        assert!(text.contains("features.arrow"), "{text}");
    };
    let store = match Store::open(&path, plan, frames) {
        Ok(s) => s,
        Err(e) => return named(e),
    };
    match store.rows(0..frames) {
        Ok(rows) => assert_eq!(rows.clip_of.len(), frames),
        Err(e) => named(e),
    }
    let windows = (frames + 1).saturating_sub(WINDOW);
    match store.measurements(windows) {
        Ok((m, _)) => assert_eq!(m.len(), windows * MEASUREMENTS),
        Err(e) => named(e),
    }
});
