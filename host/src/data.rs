//! Where the real data fetched by `cargo xtask setup` lives.
//!
//! `cargo xtask setup` (also run by `cargo xtask test` and `demo`) downloads registry packages
//! (see `xtask/src/data.rs`) and extracts the files into
//! `<workspace>/target/figurine-data/{bvh,deepmimic,pose6d}/`, with the same file names as the
//! project's data notes (`lafan_dance1.bvh`, `humanoid3d_walk.txt`, `tum_fr1_xyz_groundtruth.txt` …).
//! Set `FIGURINE_DATA_DIR` to use another folder.

use std::path::PathBuf;

/// Environment variable that overrides the data folder.
pub const DATA_DIR_ENV: &str = "FIGURINE_DATA_DIR";

/// The folder holding `bvh/`, `deepmimic/` and `pose6d/`.
pub fn data_dir() -> PathBuf {
    match std::env::var_os(DATA_DIR_ENV) {
        Some(dir) => PathBuf::from(dir),
        None => PathBuf::from(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../target/figurine-data"
        )),
    }
}

/// Path of one data file, e.g. `data_file("bvh", "lafan_dance1.bvh")`, if it is present.
pub fn data_file(kind: &str, name: &str) -> Option<PathBuf> {
    let p = data_dir().join(kind).join(name);
    p.is_file().then_some(p)
}

/// Path of one data file, or an error telling the user to run `cargo xtask setup`.
pub fn require_data_file(kind: &str, name: &str) -> anyhow::Result<PathBuf> {
    data_file(kind, name).ok_or_else(|| {
        anyhow::anyhow!(
            "data file {kind}/{name} not found under {}: run `cargo xtask setup` to fetch it \
             from the package registries (or set {DATA_DIR_ENV})",
            data_dir().display()
        )
    })
}
