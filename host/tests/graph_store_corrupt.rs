//! Feature stores that fuzzing found to panic inside the Arrow IPC decoder (`cargo +nightly
//! fuzz run graph_store`; each kept as a fuzz seed) are refused with an error naming the file:
//! a record batch naming a column buffer outside its body (the decoder slices buffers
//! unchecked), and one declaring a fixed-size list column longer than its body could hold
//! (arrow-data multiplies that length by the list's width and panics on the overflow).

use figurine_host::graph::store::{Store, BATCH_ROWS};
use figurine_host::graph::WINDOW;

/// Opens the store in fuzz seed `name` (frame count as u32 LE, plan id as u64 LE, then the
/// file's bytes) and returns the errors of a tile's read and of the merge's.
fn read_seed(name: &str) -> (String, String) {
    let seed = format!(
        "{}/fuzz/seeds/graph_store/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    let data = std::fs::read(seed).unwrap();
    let frames = u32::from_le_bytes(data[..4].try_into().unwrap()) as usize % (2 * BATCH_ROWS + 1);
    let plan = u64::from_le_bytes(data[4..12].try_into().unwrap());
    let dir = std::env::temp_dir().join(format!(
        "figurine-store-corrupt-{}-{name}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("features.arrow");
    std::fs::write(&path, &data[12..]).unwrap();
    let store = Store::open(&path, plan, frames).unwrap();
    let rows = store.rows(0..frames).unwrap_err().to_string();
    let windows = (frames + 1).saturating_sub(WINDOW);
    let lma = store.measurements(windows).unwrap_err().to_string();
    let _ = std::fs::remove_dir_all(&dir);
    (rows, lma)
}

/// The store in seed `name` is refused by a tile's read with an error naming the file and
/// saying `why`, and by the merge's with one naming the file.
fn refused(name: &str, why: &str) {
    let (rows, lma) = read_seed(name);
    assert!(
        rows.contains("features.arrow") && rows.contains(why),
        "{name}: {rows}"
    );
    assert!(lma.contains("features.arrow"), "{name}: {lma}");
}

#[test]
fn a_buffer_outside_its_batch_is_an_error_naming_the_file() {
    refused("buffer-outside-body.bin", "outside its batch");
}

#[test]
fn a_column_longer_than_its_body_is_an_error_naming_the_file() {
    refused("column-longer-than-body.bin", "longer than its batch");
}
