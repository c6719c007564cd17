//! The real firmware in QEMU over its emulated UART: handshake, ping, statistics, uploads
//! and their refusals, and a link full of garbage.

use figurine_e2e::{Qemu, QemuOptions};
use figurine_host::link::device::Device;
use figurine_host::link::LinkError;
use figurine_protocol::{
    cobs, encode_frame, frame::CRC16, BlobKind, ErrorCode, HostToDevice, Pose, UploadBegin,
    UploadChunk, MAX_FRAME_LEN, PROTOCOL_VERSION,
};

/// The smallest valid library: no actions.
const EMPTY_LIBRARY: [u8; 8] = *b"FGL\x01\0\0\0\0";

fn start() -> (Qemu, Device) {
    let mut q = Qemu::start(&QemuOptions::default()).expect("start QEMU");
    let d = q.connect().expect("connect");
    (q, d)
}

fn pose(i: u16) -> HostToDevice {
    let t = f64::from(i) * 0.01;
    HostToDevice::Pose(Pose::quantize(i, t, [0.1 * t, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0]).unwrap())
}

#[test]
fn handshake_ping_and_stats() {
    let (_q, mut dev) = start();
    let h = *dev.hello();
    assert_eq!(h.protocol_version, PROTOCOL_VERSION);
    assert_eq!(h.capacities.max_actions, 32);
    assert!(h.capacities.pose_queue >= 8);
    dev.reset().unwrap();
    for _ in 0..5 {
        dev.ping().unwrap();
    }
    for i in 0..20 {
        dev.send(&pose(i)).unwrap();
    }
    dev.ping().unwrap();
    let s = dev.stats().unwrap();
    assert_eq!(s.samples, 20);
    assert_eq!(s.samples_dropped, 0);
    // Counted since the reset: 5 pings, 20 poses, a ping, GetStats — plus the ping that
    // followed the reset if the receiver counted it after the engine cleared the counters.
    assert!((27..=28).contains(&s.frames_ok), "{s:?}");
    assert_eq!(
        s.crc_errors + s.cobs_errors + s.decode_errors + s.oversize,
        0
    );
}

#[test]
fn uploads_are_acknowledged_checked_and_refused_with_reasons() {
    let (mut q, mut dev) = start();
    // Garbage content with a correct CRC: the recognizer refuses it, nothing changes.
    let err = dev.upload(BlobKind::Library, b"not a library at all", |_, _| {});
    match err {
        Err(LinkError::Device(e)) => assert_eq!(e.code, ErrorCode::BlobInvalid),
        other => panic!("{other:?}"),
    }
    assert_eq!(dev.hello().library_crc, 0);
    // A chunk without a begin, then out of order.
    let chunk = |offset: u32| {
        HostToDevice::UploadChunk(UploadChunk {
            kind: BlobKind::Library,
            offset,
            data: heapless_vec(&EMPTY_LIBRARY),
        })
    };
    dev.send(&chunk(0)).unwrap();
    dev.send(&HostToDevice::UploadBegin(UploadBegin {
        kind: BlobKind::Library,
        len: 8,
        crc32: 0,
    }))
    .unwrap();
    dev.send(&chunk(4)).unwrap();
    dev.send(&chunk(0)).unwrap();
    dev.send(&HostToDevice::UploadCommit(BlobKind::Library))
        .unwrap();
    dev.ping().unwrap();
    let mut codes = Vec::new();
    while let Some(m) = dev.poll(std::time::Duration::ZERO).unwrap() {
        if let figurine_protocol::DeviceToHost::Error(e) = m {
            codes.push(e.code);
        }
    }
    assert_eq!(
        codes,
        [
            ErrorCode::UploadNotStarted,
            ErrorCode::UploadOutOfOrder,
            ErrorCode::UploadCrc
        ]
    );
    // A valid one is stored and survives a reconnect.
    let crc = dev
        .upload(BlobKind::Library, &EMPTY_LIBRARY, |_, _| {})
        .unwrap();
    drop(dev);
    let dev = q.connect().unwrap();
    assert_eq!(dev.hello().library_crc, crc);
}

fn heapless_vec(b: &[u8]) -> heapless::Vec<u8, { figurine_protocol::MAX_CHUNK_LEN }> {
    heapless::Vec::from_slice(b).unwrap()
}

/// A frame whose CRC is wrong but whose COBS stuffing is valid.
fn bad_crc_frame(msg: &HostToDevice) -> Vec<u8> {
    let body = postcard::to_allocvec(msg).unwrap();
    let mut raw = body.clone();
    raw.extend((CRC16.checksum(&body) ^ 0x0100).to_le_bytes());
    let mut out = vec![0u8; MAX_FRAME_LEN];
    let n = cobs::encode(&raw, &mut out).unwrap();
    out.truncate(n);
    out.insert(0, 0);
    out.push(0);
    out
}

/// A frame with a good CRC whose payload is no message (variant 200).
fn undecodable_frame() -> Vec<u8> {
    let body = [200u8, 1, 2, 3];
    let mut raw = body.to_vec();
    raw.extend(CRC16.checksum(&body).to_le_bytes());
    let mut out = vec![0u8; MAX_FRAME_LEN];
    let n = cobs::encode(&raw, &mut out).unwrap();
    out.truncate(n);
    out.insert(0, 0);
    out.push(0);
    out
}

#[test]
fn garbage_and_truncated_frames_are_counted_and_every_valid_frame_after_them_is_processed() {
    let (mut q, mut dev) = start();
    dev.reset().unwrap();
    let mut rng = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    let (mut crc_bad, mut undecodable, mut oversize, mut truncated) = (0, 0, 0, 0);
    let mut poses = 0u32;
    let mut pings = 0u32;
    for round in 0..40u16 {
        match round % 5 {
            0 => {
                dev.send_raw(&bad_crc_frame(&pose(round))).unwrap();
                crc_bad += 1;
            }
            1 => {
                dev.send_raw(&undecodable_frame()).unwrap();
                undecodable += 1;
            }
            2 => {
                // More non-zero bytes than any frame: one oversize report.
                let junk: Vec<u8> = (0..MAX_FRAME_LEN + 50)
                    .map(|_| (next() as u8) | 1)
                    .collect();
                dev.send_raw(&junk).unwrap();
                oversize += 1;
            }
            3 => {
                // The first half of a frame; the next guarded frame's 0x00 closes it.
                let mut f = [0u8; MAX_FRAME_LEN];
                let n = encode_frame(&pose(round), &mut f).unwrap();
                dev.send_raw(&f[..n / 2]).unwrap();
                truncated += 1;
            }
            _ => {
                // Random bytes, zeros included: counted as some kind of rejection.
                let junk: Vec<u8> = (0..1 + next() % 40).map(|_| next() as u8).collect();
                dev.send_raw(&junk).unwrap();
            }
        }
        dev.send(&pose(round)).unwrap();
        poses += 1;
        dev.ping().unwrap();
        pings += 1;
    }
    let s = dev.stats().unwrap();
    assert_eq!(s.samples, poses, "{s:?}");
    assert_eq!(s.samples_dropped, 0);
    assert!(s.decode_errors >= undecodable, "{s:?}");
    assert!(s.oversize >= oversize, "{s:?}");
    assert!(s.crc_errors + s.cobs_errors >= crc_bad + truncated, "{s:?}");
    assert!(s.frames_ok >= poses + pings, "{s:?}");
    assert!(q.exited().unwrap().is_none(), "the firmware died");
    // The link is still fully usable.
    dev.handshake().unwrap();
}
