//! Helpers shared by figurine's end-to-end tests: the firmware ELF, a QEMU `mps2-an386`
//! instance running it (reaped by a Drop guard, also when a test fails), and a connected
//! host-side [`figurine_host::link::Device`].

pub mod defmt_log;
pub mod elf;
pub mod pose6d;
pub mod qemu;

pub use qemu::{firmware_elf, Qemu, QemuOptions};
