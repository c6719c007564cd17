//! The board: serial link, clock, flash. Exactly one board module is compiled, chosen by
//! cargo feature (`qemu`, the default, or `nrf52840`). Each provides the same items:
//!
//! * `NAME`, `init() -> Board` (peripherals, stopwatch, logging);
//! * `SerialRx::read` / `SerialTx::write_all` (async byte link to the host);
//! * `Flash` (an `embedded_storage` `NorFlash`) with `LIBRARY_STORE` / `EFFORT_STORE`
//!   slot layouts inside it and `mapped_flash` to read a stored blob in place;
//! * `Stopwatch` (core clock cycles, for the per-sample processing time in `Stats`).

use figurine_store::TwoSlotStore;

/// Bytes of one library slot: the recognizer's largest library (12,296 B) + header, in
/// whole 4 KiB pages.
pub const LIBRARY_SLOT: u32 = 16 * 1024;
/// Bytes of one effort-model slot (largest model 560 B + header).
pub const EFFORT_SLOT: u32 = 4 * 1024;
/// Library slots at the start of the board's store region.
pub const LIBRARY_STORE: TwoSlotStore = TwoSlotStore::new(0, LIBRARY_SLOT);
/// Effort slots right after the library slots.
pub const EFFORT_STORE: TwoSlotStore = TwoSlotStore::new(2 * LIBRARY_SLOT, EFFORT_SLOT);
/// Bytes of the store region the two stores use (fits both boards' STORE regions).
pub const STORE_USED: u32 = 2 * LIBRARY_SLOT + 2 * EFFORT_SLOT;
const _: () = assert!(
    STORE_USED as usize <= STORE_SIZE,
    "blob stores exceed the STORE region"
);

#[cfg(all(feature = "qemu", feature = "nrf52840"))]
compile_error!("choose one board: `qemu` (default) or `nrf52840` with --no-default-features");

#[cfg(feature = "qemu")]
mod qemu;
#[cfg(feature = "qemu")]
pub use qemu::*;

#[cfg(all(feature = "nrf52840", not(feature = "qemu")))]
mod nrf52840;
#[cfg(all(feature = "nrf52840", not(feature = "qemu")))]
pub use nrf52840::*;

/// What `init` hands to `main`.
pub struct Board {
    /// Serial link, receive half.
    pub rx: SerialRx,
    /// Serial link, transmit half.
    pub tx: SerialTx,
    /// The blob store's flash.
    pub flash: Flash,
}
