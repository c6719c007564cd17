//! The slot header: the commit record of one stored blob.

use crate::CRC32;

/// Bytes reserved for the header at the start of each slot (a multiple of every supported
/// write granule; the blob starts right after it).
pub const HEADER_LEN: usize = 32;
/// Bytes of the header covered by its own CRC.
const BODY_LEN: usize = 16;
/// `"FGB1"`: figurine blob, header layout 1.
const MAGIC: u32 = u32::from_le_bytes(*b"FGB1");

/// What a slot's header says about the blob after it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SlotHeader {
    /// Upload counter: the valid slot with the newest generation is the active one.
    pub generation: u32,
    /// Blob length, bytes.
    pub len: u32,
    /// CRC-32 of the blob bytes.
    pub crc32: u32,
}

impl SlotHeader {
    /// The header as written to flash (unused tail bytes left erased, 0xFF).
    pub fn to_bytes(&self) -> [u8; HEADER_LEN] {
        let mut out = [0xFF; HEADER_LEN];
        let words = [MAGIC, self.generation, self.len, self.crc32];
        for (dst, w) in out.chunks_exact_mut(4).zip(words) {
            dst.copy_from_slice(&w.to_le_bytes());
        }
        let crc = CRC32.checksum(out.get(..BODY_LEN).unwrap_or(&[]));
        if let Some(dst) = out.get_mut(BODY_LEN..BODY_LEN + 4) {
            dst.copy_from_slice(&crc.to_le_bytes());
        }
        out
    }

    /// Parses a header read from flash; `None` for an erased, torn or foreign header.
    pub fn from_bytes(bytes: &[u8; HEADER_LEN]) -> Option<SlotHeader> {
        let word = |i: usize| -> u32 {
            let mut w = [0u8; 4];
            if let Some(src) = bytes.get(4 * i..4 * i + 4) {
                w.copy_from_slice(src);
            }
            u32::from_le_bytes(w)
        };
        if word(0) != MAGIC || CRC32.checksum(bytes.get(..BODY_LEN)?) != word(4) {
            return None;
        }
        Some(SlotHeader {
            generation: word(1),
            len: word(2),
            crc32: word(3),
        })
    }

    /// True if `self` was written after `other` (generations compared modulo 2³²).
    pub fn newer_than(&self, other: &SlotHeader) -> bool {
        (self.generation.wrapping_sub(other.generation) as i32) > 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_every_single_bit_flip_is_rejected() {
        let h = SlotHeader {
            generation: 7,
            len: 1234,
            crc32: 0xDEAD_BEEF,
        };
        let bytes = h.to_bytes();
        assert_eq!(SlotHeader::from_bytes(&bytes), Some(h));
        for bit in 0..(BODY_LEN + 4) * 8 {
            let mut b = bytes;
            b[bit / 8] ^= 1 << (bit % 8);
            assert_eq!(SlotHeader::from_bytes(&b), None, "bit {bit}");
        }
        assert_eq!(SlotHeader::from_bytes(&[0xFF; HEADER_LEN]), None);
        assert_eq!(SlotHeader::from_bytes(&[0; HEADER_LEN]), None);
    }

    #[test]
    fn generations_compare_across_wrap() {
        let h = |generation| SlotHeader {
            generation,
            len: 0,
            crc32: 0,
        };
        assert!(h(1).newer_than(&h(0)));
        assert!(h(0).newer_than(&h(u32::MAX)));
        assert!(!h(5).newer_than(&h(5)));
    }
}
