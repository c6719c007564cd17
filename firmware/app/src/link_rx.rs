//! Link receive task: serial bytes → frames → messages → the engine's inbox.
//!
//! Any byte stream is survivable: the decoder resynchronises at the next `0x00` after a bad
//! frame, and every rejected frame is counted by kind in `Stats`.

use figurine_protocol::{
    peek_hello_version, FrameDecoder, FrameError, HostHello, HostToDevice, RawDecoded,
    MAX_FRAME_LEN,
};

use crate::board::SerialRx;
use crate::channels::INBOX;
use crate::stats;

/// Bytes taken from the serial driver per read.
const READ_CHUNK: usize = 64;

/// Decodes one CRC-checked payload; a `Hello` of another protocol version still comes out
/// as a `Hello` (carrying that version) so the engine can answer with the reason.
fn decode(payload: &[u8]) -> Option<HostToDevice> {
    match postcard_decode(payload) {
        Some(msg) => Some(msg),
        None => peek_hello_version(payload).map(|v| {
            HostToDevice::Hello(HostHello {
                protocol_version: v,
                host_build: 0,
            })
        }),
    }
}

fn postcard_decode(payload: &[u8]) -> Option<HostToDevice> {
    postcard::from_bytes::<HostToDevice>(payload).ok()
}

fn count_rejected(error: FrameError) {
    stats::update(|s| match error {
        FrameError::Oversize => s.oversize = s.oversize.wrapping_add(1),
        FrameError::Cobs => s.cobs_errors = s.cobs_errors.wrapping_add(1),
        FrameError::Crc => s.crc_errors = s.crc_errors.wrapping_add(1),
        FrameError::Decode => s.decode_errors = s.decode_errors.wrapping_add(1),
    });
}

/// Hands one message to the engine: a pose is dropped (and counted) if the inbox is full,
/// anything else waits for room.
async fn deliver(msg: HostToDevice) {
    if matches!(msg, HostToDevice::Pose(_)) {
        if INBOX.try_send(msg).is_err() {
            stats::update(|s| s.samples_dropped = s.samples_dropped.wrapping_add(1));
            return;
        }
    } else {
        INBOX.send(msg).await;
    }
    let len = INBOX.len() as u16;
    stats::update(|s| s.pose_queue_high_water = s.pose_queue_high_water.max(len));
}

/// Receives forever.
#[embassy_executor::task]
pub async fn task(mut rx: SerialRx) {
    let mut decoder = FrameDecoder::<MAX_FRAME_LEN>::new();
    let mut buf = [0u8; READ_CHUNK];
    loop {
        let n = rx.read(&mut buf).await;
        let mut input = buf.get(..n).unwrap_or(&[]);
        while !input.is_empty() {
            let (raw, rest) = decoder.feed_raw(input);
            input = rest;
            let msg = match raw {
                RawDecoded::NeedMore => None,
                RawDecoded::Rejected(e) => {
                    count_rejected(e);
                    None
                }
                RawDecoded::Payload(p) => match decode(p) {
                    Some(m) => {
                        stats::update(|s| s.frames_ok = s.frames_ok.wrapping_add(1));
                        Some(m)
                    }
                    None => {
                        count_rejected(FrameError::Decode);
                        None
                    }
                },
            };
            if let Some(msg) = msg {
                deliver(msg).await;
            }
        }
    }
}
