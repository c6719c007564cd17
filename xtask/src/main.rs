//! `cargo xtask`: figurine's build automation (work in progress in this commit).
fn main() {}
