//! Puts the chosen board's memory map (`memory.x`) first on the linker search path and adds the
//! linker scripts. Without this, a dependency's own `memory.x` (systick-timer ships one) could
//! be linked silently instead of the board's.

use std::{env, fs, path::PathBuf};

fn main() {
    let qemu = env::var_os("CARGO_FEATURE_QEMU").is_some();
    let nrf = env::var_os("CARGO_FEATURE_NRF52840").is_some();
    let manifest =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let root = manifest.join("../..");
    let memory = match (qemu, nrf) {
        (true, false) => root.join("hw/mps2-an386/memory.x"),
        (false, true) => root.join("memory.x"),
        _ => panic!("choose exactly one board feature: `qemu` (default) or `nrf52840` (with --no-default-features)"),
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::copy(&memory, out.join("memory.x")).expect("copy memory.x");
    if qemu {
        // cortex-m-rt's `device` feature includes device.x; this board's vector table is
        // complete in Rust (board/qemu/vectors.rs), so it needs no extra symbols.
        fs::write(
            out.join("device.x"),
            "/* mps2-an386: interrupts defined in Rust */\n",
        )
        .expect("write device.x");
    }
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory.display());
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
