//! The protocol crate's errors (hand-written `Display`: this crate is `no_std`).

use core::fmt;

/// Why one received frame was rejected by the [`crate::FrameDecoder`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// The frame did not fit the decoder's buffer; bytes were discarded up to the next delimiter.
    Oversize,
    /// The COBS stuffing was invalid (a code byte pointed past the end of the frame).
    Cobs,
    /// The frame was too short to hold a CRC, or its CRC did not match: corrupted on the wire.
    Crc,
    /// The CRC matched but the payload is not a valid message of this protocol version.
    Decode,
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FrameError::Oversize => "frame longer than the receive buffer",
            FrameError::Cobs => "invalid COBS stuffing",
            FrameError::Crc => "CRC mismatch or frame shorter than its CRC",
            FrameError::Decode => "payload is not a valid message",
        })
    }
}

/// Errors of encoding and of the version handshake.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ProtocolError {
    /// The output buffer is too small for the encoded frame.
    BufferTooSmall,
    /// The message's postcard encoding exceeds [`crate::MAX_PAYLOAD_LEN`].
    MessageTooLarge,
    /// The peer speaks another protocol version.
    VersionMismatch {
        /// Our [`crate::PROTOCOL_VERSION`].
        ours: u16,
        /// The version the peer announced.
        theirs: u16,
    },
}

impl fmt::Display for ProtocolError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProtocolError::BufferTooSmall => f.write_str("output buffer too small for the frame"),
            ProtocolError::MessageTooLarge => f.write_str("message larger than MAX_PAYLOAD_LEN"),
            ProtocolError::VersionMismatch { ours, theirs } => write!(
                f,
                "protocol version mismatch: this side speaks version {ours}, the peer speaks \
                 version {theirs}"
            ),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for FrameError {}
#[cfg(feature = "std")]
impl std::error::Error for ProtocolError {}
