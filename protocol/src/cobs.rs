//! Consistent Overhead Byte Stuffing: removes every `0x00` from a frame so `0x00` can delimit
//! frames. Overhead: one byte per started 254 bytes of input.

/// Largest encoded length of `n` input bytes (without the trailing delimiter).
pub const fn max_encoded_len(n: usize) -> usize {
    n + n / 254 + 1
}

/// COBS-encodes `input` into `out`; returns the encoded length, or `None` if `out` is too
/// small. The output contains no zero byte and no delimiter.
pub fn encode(input: &[u8], out: &mut [u8]) -> Option<usize> {
    let mut code_idx = 0usize;
    let mut write = 1usize;
    let mut code: u8 = 1;
    *out.get_mut(code_idx)? = 0;
    for &b in input {
        if b == 0 {
            *out.get_mut(code_idx)? = code;
            code_idx = write;
            *out.get_mut(code_idx)? = 0;
            write += 1;
            code = 1;
        } else {
            *out.get_mut(write)? = b;
            write += 1;
            code += 1;
            if code == 0xFF {
                *out.get_mut(code_idx)? = code;
                code_idx = write;
                *out.get_mut(code_idx)? = 0;
                write += 1;
                code = 1;
            }
        }
    }
    *out.get_mut(code_idx)? = code;
    Some(write)
}

/// Decodes a COBS frame (without its delimiter) in place; returns the decoded length, or
/// `None` if the stuffing is invalid (a zero byte inside, or a code running past the end).
pub fn decode_in_place(buf: &mut [u8]) -> Option<usize> {
    let len = buf.len();
    let mut read = 0usize;
    let mut write = 0usize;
    while read < len {
        let code = *buf.get(read)?;
        if code == 0 {
            return None;
        }
        read += 1;
        let run = usize::from(code) - 1;
        let end = read.checked_add(run)?;
        if end > len {
            return None;
        }
        for i in 0..run {
            let b = *buf.get(read + i)?;
            if b == 0 {
                return None;
            }
            *buf.get_mut(write)? = b;
            write += 1;
        }
        read = end;
        if code != 0xFF && read < len {
            *buf.get_mut(write)? = 0;
            write += 1;
        }
    }
    Some(write)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip(data: &[u8]) {
        let mut enc = [0u8; 1200];
        let n = encode(data, &mut enc).unwrap();
        assert!(n <= max_encoded_len(data.len()));
        assert!(!enc[..n].contains(&0));
        let mut dec = enc;
        let m = decode_in_place(&mut dec[..n]).unwrap();
        assert_eq!(&dec[..m], data);
    }

    #[test]
    fn known_vectors() {
        let mut out = [0u8; 16];
        let n = encode(&[0x11, 0x22, 0x00, 0x33], &mut out).unwrap();
        assert_eq!(&out[..n], &[0x03, 0x11, 0x22, 0x02, 0x33]);
        let n = encode(&[0x00], &mut out).unwrap();
        assert_eq!(&out[..n], &[0x01, 0x01]);
        let n = encode(&[], &mut out).unwrap();
        assert_eq!(&out[..n], &[0x01]);
    }

    #[test]
    fn round_trips_edge_lengths() {
        for len in [0usize, 1, 253, 254, 255, 508, 509, 1000] {
            let data: alloc_free::Buf = alloc_free::ramp(len);
            round_trip(&data.0[..len]);
            let zeros = [0u8; 1000];
            round_trip(&zeros[..len]);
        }
    }

    #[test]
    fn invalid_stuffing_is_rejected_not_panicking() {
        assert_eq!(decode_in_place(&mut [0x05, 0x01]), None);
        assert_eq!(decode_in_place(&mut [0x02, 0x00]), None);
        assert_eq!(decode_in_place(&mut [0x00]), None);
        assert_eq!(decode_in_place(&mut []), Some(0));
    }

    #[test]
    fn small_output_buffer_is_reported() {
        let mut out = [0u8; 3];
        assert_eq!(encode(&[1, 2, 3, 4], &mut out), None);
    }

    mod alloc_free {
        pub struct Buf(pub [u8; 1000]);
        pub fn ramp(len: usize) -> Buf {
            let mut b = [0u8; 1000];
            for (i, x) in b.iter_mut().enumerate().take(len) {
                *x = (i % 251) as u8 + 1;
            }
            Buf(b)
        }
    }
}
