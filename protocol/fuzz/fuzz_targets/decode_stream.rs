//! Fuzzes the streaming frame decoder: arbitrary bytes, cut into chunks whose sizes come from
//! the input, decoded in both directions. Checks: no panic, bounded buffering, statistics that
//! add up, and every decoded message re-encodes to a frame that decodes to itself.
#![no_main]

use figurine_protocol::*;
use libfuzzer_sys::fuzz_target;

fn check<T: serde::Serialize + serde::de::DeserializeOwned + PartialEq + core::fmt::Debug>(data: &[u8]) {
    let (sizes, bytes) = data.split_at(data.len().min(4));
    let mut dec = FrameDecoder::<MAX_FRAME_LEN>::new();
    let mut delivered = 0u32;
    let mut rejected = 0u32;
    let mut rest = bytes;
    let mut k = 0usize;
    while !rest.is_empty() {
        let step = 1 + usize::from(sizes.get(k % sizes.len().max(1)).copied().unwrap_or(255));
        k += 1;
        let (chunk, tail) = rest.split_at(step.min(rest.len()));
        rest = tail;
        let mut input = chunk;
        loop {
            match dec.feed::<T>(input) {
                Decoded::NeedMore => break,
                Decoded::Message { msg, remaining } => {
                    delivered += 1;
                    let frame = to_frame(&msg).expect("a decoded message re-encodes");
                    let mut again = FrameDecoder::<MAX_FRAME_LEN>::new();
                    match again.feed::<T>(&frame) {
                        Decoded::Message { msg: back, .. } => assert_eq!(back, msg),
                        other => panic!("re-encoded frame did not decode: {other:?}"),
                    }
                    input = remaining;
                }
                Decoded::Rejected { remaining, .. } => {
                    rejected += 1;
                    input = remaining;
                }
            }
        }
        assert!(dec.pending() <= MAX_FRAME_LEN);
    }
    let s = dec.stats();
    assert_eq!(s.frames, delivered + s.decode_errors);
    assert_eq!(rejected, s.crc_errors + s.cobs_errors + s.oversize + s.decode_errors);
}

fuzz_target!(|data: &[u8]| {
    check::<HostToDevice>(data);
    check::<DeviceToHost>(data);
});
