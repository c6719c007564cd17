//! The store's one error enum (hand-written `Display`: no_std).

use core::fmt;

/// Why a store operation failed. The active blob is never affected by any of these.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StoreError {
    /// The slot geometry does not fit the flash (size not a multiple of the erase page,
    /// beyond the capacity, or a write granule larger than 16 bytes).
    Geometry,
    /// The blob is larger than a slot can hold; the payload is the capacity, bytes.
    TooLarge(u32),
    /// A chunk did not start where the previous one ended; the payload is the expected offset.
    OutOfOrder(u32),
    /// More bytes were written than announced at [`crate::TwoSlotStore::begin`].
    Overrun,
    /// Fewer bytes were written than announced; the payload is the count received.
    Incomplete(u32),
    /// The bytes read back from flash do not match the announced CRC-32.
    Crc,
    /// The flash driver reported an error (or the power failed under a simulated flash).
    Flash,
}

impl fmt::Display for StoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StoreError::Geometry => f.write_str("slot geometry does not fit the flash"),
            StoreError::TooLarge(cap) => write!(f, "blob larger than the slot ({cap} bytes)"),
            StoreError::OutOfOrder(next) => {
                write!(f, "chunk out of order (expected offset {next})")
            }
            StoreError::Overrun => f.write_str("more bytes than announced"),
            StoreError::Incomplete(got) => write!(f, "upload incomplete ({got} bytes received)"),
            StoreError::Crc => f.write_str("blob CRC-32 mismatch after writing"),
            StoreError::Flash => f.write_str("flash operation failed"),
        }
    }
}
