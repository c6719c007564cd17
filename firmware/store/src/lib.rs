//! figurine's power-fail-safe blob store: the action library and the effort model live in
//! NOR flash so the figurine recognises actions straight after power-up.
//!
//! One [`TwoSlotStore`] holds one kind of blob in two equal slots of whole erase pages:
//!
//! ```text
//! slot = header (32 B) ‖ blob bytes ‖ erased (0xFF) up to the slot end
//! header = magic "FGB1" ‖ generation u32 ‖ len u32 ‖ crc32(blob) u32 ‖ crc32(first 16 B) u32 ‖ 0xFF…
//! ```
//!
//! An upload erases the *spare* slot (never the active one), writes the blob, checks its
//! CRC-32 by reading the flash back, and writes the header **last**: the header is the commit
//! record. At boot, [`TwoSlotStore::active`] takes the slot whose header and blob both pass
//! their CRCs and whose generation is newest. So a power cut at any point of an upload (during
//! the erase, a blob write or the header write, even one leaving a word half-programmed) leaves
//! either the previous blob or the complete new one active, never a mixture; the host tests
//! in [`store`](crate::store) cut the power at 1000 random points to check exactly that.
//!
//! Why a crate of its own: the firmware binary builds only for the thumb target, while this
//! logic must be tested on the host; it sits in the root workspace and the firmware depends
//! on it by path. It is generic over `embedded_storage::nor_flash::NorFlash`, which the
//! nRF52840's NVMC driver implements and the QEMU board's RAM-backed flash implements too.
#![no_std]
#![forbid(unsafe_code)]

#[cfg(test)]
extern crate std;

pub mod error;
pub mod header;
pub mod store;

pub use error::StoreError;
pub use header::{SlotHeader, HEADER_LEN};
pub use store::{ActiveBlob, TwoSlotStore, Upload};

/// The CRC of blobs and headers (CRC-32/ISO-HDLC, as zlib's and the wire protocol's).
pub const CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);
