//! Framing: `COBS(postcard ‖ CRC-16) ‖ 0x00`, and the streaming receiver.
//!
//! **Why CRC-16 (CRC-16/IBM-3740, poly 0x1021):** every frame is at most
//! [`MAX_FRAME_LEN`] bytes, far inside the length up to which this polynomial detects all 1-, 2-
//! and 3-bit errors and every burst of up to 16 bits; a CRC-32 would cost two more bytes, which
//! the 32-byte pose and 16-byte event budgets cannot spare. Residual risk of an undetected
//! random corruption: 2⁻¹⁶ per corrupted frame, and such a frame must also decode as a valid
//! message. Uploaded blobs carry their own CRC-32 on top.

use serde::{de::DeserializeOwned, Serialize};

use crate::cobs;
use crate::error::{FrameError, ProtocolError};

/// Largest postcard encoding of any message, bytes (the upload chunk is the largest: 72).
pub const MAX_PAYLOAD_LEN: usize = 96;
/// Bytes of CRC after the payload.
pub const CRC_LEN: usize = 2;
/// Largest frame on the wire, bytes, delimiter included: payload + CRC, COBS overhead, `0x00`.
pub const MAX_FRAME_LEN: usize = cobs::max_encoded_len(MAX_PAYLOAD_LEN + CRC_LEN) + 1;

/// The frame checksum (CRC-16/IBM-3740, also known as CCITT-FALSE).
pub const CRC16: crc::Crc<u16> = crc::Crc::<u16>::new(&crc::CRC_16_IBM_3740);
/// The checksum of uploaded blobs and of flash slots (CRC-32/ISO-HDLC, as zlib's).
pub const CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// Encodes `msg` as one complete frame (delimiter included) into `out`; returns its length.
pub fn encode_frame<T: Serialize>(msg: &T, out: &mut [u8]) -> Result<usize, ProtocolError> {
    let mut raw = [0u8; MAX_PAYLOAD_LEN + CRC_LEN];
    let (body, _) = raw.split_at_mut(MAX_PAYLOAD_LEN);
    let used = postcard::to_slice(msg, body)
        .map_err(|_| ProtocolError::MessageTooLarge)?
        .len();
    let crc = CRC16.checksum(raw.get(..used).ok_or(ProtocolError::MessageTooLarge)?);
    raw.get_mut(used..used + CRC_LEN)
        .ok_or(ProtocolError::MessageTooLarge)?
        .copy_from_slice(&crc.to_le_bytes());
    let framed = raw
        .get(..used + CRC_LEN)
        .ok_or(ProtocolError::MessageTooLarge)?;
    let n = cobs::encode(framed, out).ok_or(ProtocolError::BufferTooSmall)?;
    *out.get_mut(n).ok_or(ProtocolError::BufferTooSmall)? = 0;
    Ok(n + 1)
}

/// Like [`encode_frame`] but with a leading `0x00` as well, so a truncated or garbled frame
/// before it on the line is closed off and cannot swallow this one. The host uses this for
/// everything it sends (a pose frame stays within its 32-byte budget); the device's frames
/// omit it to keep events within 16 bytes. Returns the length written.
pub fn encode_frame_guarded<T: Serialize>(msg: &T, out: &mut [u8]) -> Result<usize, ProtocolError> {
    let (first, rest) = out.split_first_mut().ok_or(ProtocolError::BufferTooSmall)?;
    *first = 0;
    Ok(1 + encode_frame(msg, rest)?)
}

/// Encodes `msg` as one frame into a fixed-capacity vector.
pub fn to_frame<T: Serialize>(msg: &T) -> Result<heapless::Vec<u8, MAX_FRAME_LEN>, ProtocolError> {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let n = encode_frame(msg, &mut buf)?;
    heapless::Vec::from_slice(buf.get(..n).ok_or(ProtocolError::BufferTooSmall)?)
        .map_err(|_| ProtocolError::BufferTooSmall)
}

/// Counts of what a [`FrameDecoder`] received, since creation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecoderStats {
    /// Frames whose CRC matched (including any that then failed to decode as a message).
    pub frames: u32,
    /// Frames rejected by the CRC (or too short to hold one).
    pub crc_errors: u32,
    /// Frames rejected for invalid COBS stuffing.
    pub cobs_errors: u32,
    /// Frames that overflowed the receive buffer.
    pub oversize: u32,
    /// Frames with a good CRC that did not decode as a message (counted by [`FrameDecoder::feed`]).
    pub decode_errors: u32,
}

/// Result of offering bytes to [`FrameDecoder::feed`].
#[derive(Debug, PartialEq)]
pub enum Decoded<'a, T> {
    /// All input was absorbed; no frame is complete yet.
    NeedMore,
    /// A frame completed with a valid message; `remaining` is the input after its delimiter.
    Message {
        /// The decoded message.
        msg: T,
        /// Unconsumed input: feed it again.
        remaining: &'a [u8],
    },
    /// A frame completed but was rejected; the decoder is already resynchronised.
    Rejected {
        /// Why the frame was rejected.
        error: FrameError,
        /// Unconsumed input: feed it again.
        remaining: &'a [u8],
    },
}

/// Result of offering bytes to [`FrameDecoder::feed_raw`]: the CRC-checked payload, undecoded.
#[derive(Debug, PartialEq)]
pub enum RawDecoded<'b> {
    /// All input was absorbed; no frame is complete yet.
    NeedMore,
    /// A frame completed and its CRC matched: the postcard payload (CRC stripped).
    Payload(&'b [u8]),
    /// A frame completed but was rejected.
    Rejected(FrameError),
}

/// Streaming frame receiver with a fixed `N`-byte buffer (default [`MAX_FRAME_LEN`]).
///
/// Takes byte chunks of any size and split, yields one result per frame and hands back the
/// bytes after that frame. Never panics and never allocates. A frame longer than `N` is
/// discarded up to the next delimiter and reported once as [`FrameError::Oversize`]; empty
/// frames (consecutive delimiters, useful to flush a line) are skipped silently.
#[derive(Debug, Clone)]
pub struct FrameDecoder<const N: usize = MAX_FRAME_LEN> {
    buf: [u8; N],
    len: usize,
    overflow: bool,
    stats: DecoderStats,
}

impl<const N: usize> Default for FrameDecoder<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> FrameDecoder<N> {
    /// An empty decoder.
    pub const fn new() -> Self {
        FrameDecoder {
            buf: [0; N],
            len: 0,
            overflow: false,
            stats: DecoderStats {
                frames: 0,
                crc_errors: 0,
                cobs_errors: 0,
                oversize: 0,
                decode_errors: 0,
            },
        }
    }

    /// What was received so far.
    pub fn stats(&self) -> DecoderStats {
        self.stats
    }

    /// Bytes of an incomplete frame currently buffered.
    pub fn pending(&self) -> usize {
        self.len
    }

    /// Forgets any partial frame (e.g. after a reconnect); statistics are kept.
    pub fn clear(&mut self) {
        self.len = 0;
        self.overflow = false;
    }

    /// Absorbs bytes up to and including the next frame's delimiter; returns the frame's
    /// CRC-checked payload (borrowed from the decoder) and the unconsumed rest of `input`.
    pub fn feed_raw<'a>(&mut self, input: &'a [u8]) -> (RawDecoded<'_>, &'a [u8]) {
        for (i, &byte) in input.iter().enumerate() {
            if byte != 0 {
                if self.overflow {
                    continue;
                }
                match self.buf.get_mut(self.len) {
                    Some(slot) => {
                        *slot = byte;
                        self.len += 1;
                    }
                    None => self.overflow = true,
                }
                continue;
            }
            let rest = input.get(i + 1..).unwrap_or(&[]);
            if self.overflow {
                self.clear();
                self.stats.oversize = self.stats.oversize.wrapping_add(1);
                return (RawDecoded::Rejected(FrameError::Oversize), rest);
            }
            if self.len == 0 {
                continue;
            }
            let n = self.len;
            self.len = 0;
            return (self.check(n), rest);
        }
        (RawDecoded::NeedMore, &[])
    }

    fn check(&mut self, n: usize) -> RawDecoded<'_> {
        let Some(frame) = self.buf.get_mut(..n) else {
            return RawDecoded::Rejected(FrameError::Oversize);
        };
        let Some(m) = cobs::decode_in_place(frame) else {
            self.stats.cobs_errors = self.stats.cobs_errors.wrapping_add(1);
            return RawDecoded::Rejected(FrameError::Cobs);
        };
        let crc_ok = m >= CRC_LEN
            && match (frame.get(..m - CRC_LEN), frame.get(m - CRC_LEN..m)) {
                (Some(body), Some(&[lo, hi])) => {
                    CRC16.checksum(body) == u16::from_le_bytes([lo, hi])
                }
                _ => false,
            };
        if !crc_ok {
            self.stats.crc_errors = self.stats.crc_errors.wrapping_add(1);
            return RawDecoded::Rejected(FrameError::Crc);
        }
        self.stats.frames = self.stats.frames.wrapping_add(1);
        match self.buf.get(..m - CRC_LEN) {
            Some(body) => RawDecoded::Payload(body),
            None => RawDecoded::Rejected(FrameError::Crc),
        }
    }

    /// Absorbs bytes up to and including the next frame's delimiter and decodes the frame as
    /// a `T`; returns the message or why the frame was rejected, and the unconsumed input.
    pub fn feed<'a, T: DeserializeOwned>(&mut self, input: &'a [u8]) -> Decoded<'a, T> {
        let (raw, remaining) = self.feed_raw(input);
        let decoded = match raw {
            RawDecoded::NeedMore => return Decoded::NeedMore,
            RawDecoded::Rejected(error) => Err(error),
            RawDecoded::Payload(body) => match postcard::from_bytes::<T>(body) {
                Ok(msg) => Ok(msg),
                Err(_) => Err(FrameError::Decode),
            },
        };
        match decoded {
            Ok(msg) => Decoded::Message { msg, remaining },
            Err(error) => {
                if error == FrameError::Decode {
                    self.stats.decode_errors = self.stats.decode_errors.wrapping_add(1);
                }
                Decoded::Rejected { error, remaining }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::message::HostToDevice;

    #[test]
    fn one_frame_split_at_every_position_decodes_once() {
        let msg = HostToDevice::Ping(0xDEAD_BEEF);
        let frame = to_frame(&msg).unwrap();
        for cut in 0..=frame.len() {
            let mut dec = FrameDecoder::<MAX_FRAME_LEN>::new();
            let (a, b) = frame.split_at(cut);
            let mut got = None;
            for part in [a, b] {
                let mut input = part;
                loop {
                    match dec.feed::<HostToDevice>(input) {
                        Decoded::NeedMore => break,
                        Decoded::Message { msg, remaining } => {
                            assert!(got.is_none());
                            got = Some(msg);
                            input = remaining;
                        }
                        Decoded::Rejected { error, .. } => panic!("rejected: {error}"),
                    }
                }
            }
            assert_eq!(got, Some(msg.clone()), "cut at {cut}");
        }
    }

    #[test]
    fn oversize_frame_is_reported_once_and_next_frame_decodes() {
        let mut dec = FrameDecoder::<16>::new();
        let long = [7u8; 40];
        assert_eq!(dec.feed::<HostToDevice>(&long), Decoded::NeedMore);
        let good = to_frame(&HostToDevice::Reset).unwrap();
        let mut input = [0u8; 1 + MAX_FRAME_LEN];
        input[1..1 + good.len()].copy_from_slice(&good);
        let input = &input[..1 + good.len()];
        match dec.feed::<HostToDevice>(input) {
            Decoded::Rejected {
                error: FrameError::Oversize,
                remaining,
            } => {
                assert!(matches!(
                    dec.feed::<HostToDevice>(remaining),
                    Decoded::Message {
                        msg: HostToDevice::Reset,
                        ..
                    }
                ));
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(dec.stats().oversize, 1);
        assert_eq!(dec.stats().frames, 1);
    }

    #[test]
    fn corrupted_byte_is_a_crc_error() {
        let mut frame = to_frame(&HostToDevice::Ping(42)).unwrap();
        frame[2] ^= 0x10;
        if frame[2] == 0 {
            frame[2] = 0x55;
        }
        let mut dec = FrameDecoder::<MAX_FRAME_LEN>::new();
        let r = dec.feed::<HostToDevice>(&frame);
        assert!(matches!(
            r,
            Decoded::Rejected {
                error: FrameError::Crc | FrameError::Cobs,
                ..
            }
        ));
    }
}
