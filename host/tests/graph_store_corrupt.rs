//! A feature store whose record batch names a column buffer outside the batch's body (found by
//! `cargo +nightly fuzz run graph_store`; kept as a fuzz seed) is refused with an error naming
//! the file. The IPC decoder slices buffers unchecked: before, this input panicked inside it.

use figurine_host::graph::store::{Store, BATCH_ROWS};
use figurine_host::graph::WINDOW;

#[test]
fn a_buffer_outside_its_batch_is_an_error_naming_the_file() {
    // The fuzz input: frame count (u32 LE), plan id (u64 LE), then the file's bytes.
    let seed = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fuzz/seeds/graph_store/buffer-outside-body.bin"
    );
    let data = std::fs::read(seed).unwrap();
    let frames = u32::from_le_bytes(data[..4].try_into().unwrap()) as usize % (2 * BATCH_ROWS + 1);
    let plan = u64::from_le_bytes(data[4..12].try_into().unwrap());
    let dir = std::env::temp_dir().join(format!("figurine-store-corrupt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("features.arrow");
    std::fs::write(&path, &data[12..]).unwrap();
    let store = Store::open(&path, plan, frames).unwrap();
    let rows = store.rows(0..frames).unwrap_err().to_string();
    assert!(
        rows.contains("features.arrow") && rows.contains("outside its batch"),
        "{rows}"
    );
    let windows = (frames + 1).saturating_sub(WINDOW);
    let lma = store.measurements(windows).unwrap_err().to_string();
    assert!(lma.contains("features.arrow"), "{lma}");
    let _ = std::fs::remove_dir_all(&dir);
}
