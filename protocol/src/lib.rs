//! figurine wire protocol, shared by the firmware and the host.
//!
//! Every message is a [postcard](https://docs.rs/postcard) value followed by a little-endian
//! CRC-16, the whole COBS-encoded and closed by a `0x00` delimiter:
//!
//! ```text
//! frame on the wire = COBS( postcard(message) ‖ crc16_le(postcard(message)) ) ‖ 0x00
//! ```
//!
//! * [`message`]: the messages both ways ([`HostToDevice`], [`DeviceToHost`]) with units.
//! * [`pose`]: the quantised pose sample (0.1 mm, smallest-three quaternion, µs) that keeps a
//!   pose frame within 32 bytes; host simulation uses the same quantisation.
//! * [`cobs`]: byte stuffing, never panics.
//! * [`frame`]: [`encode_frame`] and the streaming [`FrameDecoder`] that takes arbitrary byte
//!   chunks, resynchronises at the next delimiter after any corrupt frame, counts what it
//!   rejected, never allocates and hands back unconsumed bytes.
//!
//! Changing the encoding of any message changes the golden bytes in `tests/golden.rs` and must
//! bump [`PROTOCOL_VERSION`]; peers with another version are refused at the `Hello` handshake.
#![no_std]
#![forbid(unsafe_code)]

#[cfg(feature = "std")]
extern crate std;

pub mod cobs;
pub mod error;
pub mod frame;
pub mod message;
pub mod pose;

pub use error::{FrameError, ProtocolError};
pub use frame::{
    encode_frame, encode_frame_guarded, to_frame, Decoded, DecoderStats, FrameDecoder, RawDecoded,
    MAX_FRAME_LEN, MAX_PAYLOAD_LEN,
};
pub use message::*;
pub use pose::Pose;

/// Version of this wire protocol; both `Hello`s carry it and peers must match exactly.
pub const PROTOCOL_VERSION: u16 = 2;

/// Checks a peer's `Hello` against ours.
pub fn check_version(peer: u16) -> Result<(), ProtocolError> {
    if peer == PROTOCOL_VERSION {
        Ok(())
    } else {
        Err(ProtocolError::VersionMismatch {
            ours: PROTOCOL_VERSION,
            theirs: peer,
        })
    }
}
