//! Wire-format tests: golden bytes, size budgets, round trips, garbage resilience, versions.

use figurine_protocol::pose::Pose;
use figurine_protocol::*;
use proptest::prelude::*;

/// One instance of every message, with fixed field values, for the golden file.
fn samples() -> Vec<(&'static str, Vec<u8>)> {
    let pose = Pose::quantize(513, 12.345678, [0.5, 1.25, -0.75], [0.9, 0.1, -0.3, 0.2]).unwrap();
    let caps = Capacities {
        max_actions: 32,
        max_pattern_len: 32,
        max_edits: 3,
        effort_features: 50,
        max_library_bytes: 4096,
        max_effort_bytes: 2048,
        pose_queue: 64,
    };
    let h = |m: HostToDevice| to_frame(&m).unwrap().to_vec();
    let d = |m: DeviceToHost| to_frame(&m).unwrap().to_vec();
    let chunk = UploadChunk {
        kind: BlobKind::Library,
        offset: 128,
        data: heapless::Vec::from_slice(&[0, 1, 2, 3, 0, 255]).unwrap(),
    };
    vec![
        (
            "host_hello",
            h(HostToDevice::Hello(HostHello {
                protocol_version: PROTOCOL_VERSION,
                host_build: 7,
            })),
        ),
        ("pose", h(HostToDevice::Pose(pose))),
        (
            "upload_begin",
            h(HostToDevice::UploadBegin(UploadBegin {
                kind: BlobKind::Effort,
                len: 700,
                crc32: 0xCAFE_F00D,
            })),
        ),
        ("upload_chunk", h(HostToDevice::UploadChunk(chunk))),
        (
            "upload_commit",
            h(HostToDevice::UploadCommit(BlobKind::Library)),
        ),
        ("reset", h(HostToDevice::Reset)),
        ("get_stats", h(HostToDevice::GetStats)),
        ("ping", h(HostToDevice::Ping(0x0102_0304))),
        (
            "device_hello",
            d(DeviceToHost::Hello(DeviceHello {
                protocol_version: PROTOCOL_VERSION,
                build_id: 0xB01D,
                capacities: caps,
                library_crc: 0x1234_5678,
                effort_crc: 0,
            })),
        ),
        (
            "event",
            d(DeviceToHost::Event(ActionEvent {
                seq: 9,
                action: 3,
                end_seq: 40_000,
                len: 75,
                time: 79,
                weight: -39,
                distance: 1,
            })),
        ),
        (
            "revised",
            d(DeviceToHost::Revised(ActionEvent {
                seq: 9,
                action: 3,
                end_seq: 40_100,
                len: 175,
                time: 75,
                weight: -41,
                distance: 2,
            })),
        ),
        (
            "upload_ack",
            d(DeviceToHost::UploadAck {
                kind: BlobKind::Library,
                next_offset: 192,
            }),
        ),
        (
            "upload_done",
            d(DeviceToHost::UploadDone {
                kind: BlobKind::Effort,
                crc32: 0xCAFE_F00D,
            }),
        ),
        (
            "stats",
            d(DeviceToHost::Stats(Stats {
                samples: 100_000,
                invalid_samples: 3,
                samples_dropped: 0,
                seq_gaps: 2,
                events: 17,
                frames_ok: 100_020,
                crc_errors: 5,
                cobs_errors: 1,
                decode_errors: 2,
                oversize: 1,
                pose_queue_high_water: 6,
                tx_queue_high_water: 2,
                worst_sample_cycles: 4321,
            })),
        ),
        (
            "error",
            d(DeviceToHost::Error(DeviceError {
                code: ErrorCode::UploadOutOfOrder,
                detail: 64,
            })),
        ),
        ("pong", d(DeviceToHost::Pong(0x0102_0304))),
    ]
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

const GOLDEN: &str = include_str!("golden_frames.txt");

/// Golden bytes: any change is a wire-format change and needs a PROTOCOL_VERSION bump.
/// Regenerate with `FIGURINE_BLESS=1 cargo test -p figurine-protocol --test wire golden`.
#[test]
fn golden_bytes_of_every_message() {
    let actual: String = samples()
        .iter()
        .map(|(n, b)| format!("{n} {}\n", hex(b)))
        .collect();
    if std::env::var_os("FIGURINE_BLESS").is_some() {
        let text = format!("# protocol version {PROTOCOL_VERSION}\n{actual}");
        std::fs::write(
            concat!(env!("CARGO_MANIFEST_DIR"), "/tests/golden_frames.txt"),
            text,
        )
        .unwrap();
        return;
    }
    let want = format!("# protocol version {PROTOCOL_VERSION}\n");
    assert!(
        GOLDEN.starts_with(&want),
        "golden file is for another protocol version"
    );
    let golden: String = GOLDEN
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(
        golden, actual,
        "wire bytes changed: bump PROTOCOL_VERSION and re-bless"
    );
    // Every golden frame decodes back to its message (the other direction of the golden test).
    for (name, bytes) in samples() {
        let mut dec = FrameDecoder::<MAX_FRAME_LEN>::new();
        let (raw, rest) = dec.feed_raw(&bytes);
        assert!(matches!(raw, RawDecoded::Payload(_)), "{name}");
        assert!(rest.is_empty(), "{name}");
    }
}

fn worst_pose() -> HostToDevice {
    HostToDevice::Pose(Pose {
        seq: u16::MAX,
        t_us: u32::MAX,
        pos: [-1_000_000, -1_000_000, -1_000_000],
        rot: [0xFF; 6],
    })
}

fn worst_event() -> DeviceToHost {
    DeviceToHost::Event(ActionEvent {
        seq: u8::MAX,
        action: u8::MAX,
        end_seq: u16::MAX,
        len: u16::MAX,
        time: i8::MIN,
        weight: i8::MIN,
        distance: u8::MAX,
    })
}

#[test]
fn wire_budgets_pose_32_event_16() {
    let mut buf = [0u8; MAX_FRAME_LEN + 1];
    let pose = encode_frame_guarded(&worst_pose(), &mut buf).unwrap();
    let pose_plain = encode_frame(&worst_pose(), &mut buf).unwrap();
    let event = encode_frame(&worst_event(), &mut buf).unwrap();
    println!("worst-case Pose frame: {pose} bytes guarded ({pose_plain} unguarded); worst-case ActionEvent frame: {event} bytes");
    assert!(pose <= 32, "pose frame {pose} bytes");
    assert!(event <= 16, "event frame {event} bytes");
    // Typical values are smaller still.
    let typical = HostToDevice::Pose(
        Pose::quantize(1000, 16.667, [0.3, 1.1, -0.4], [0.7, 0.1, 0.7, 0.1]).unwrap(),
    );
    let n = encode_frame_guarded(&typical, &mut buf).unwrap();
    println!("typical Pose frame: {n} bytes guarded");
    assert!(n <= pose);
}

#[test]
fn largest_message_of_each_kind_fits_the_buffers() {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let chunk = HostToDevice::UploadChunk(UploadChunk {
        kind: BlobKind::Effort,
        offset: u32::MAX,
        data: heapless::Vec::from_slice(&[0xFF; MAX_CHUNK_LEN]).unwrap(),
    });
    let stats = DeviceToHost::Stats(Stats {
        samples: u32::MAX,
        invalid_samples: u32::MAX,
        samples_dropped: u32::MAX,
        seq_gaps: u32::MAX,
        events: u32::MAX,
        frames_ok: u32::MAX,
        crc_errors: u32::MAX,
        cobs_errors: u32::MAX,
        decode_errors: u32::MAX,
        oversize: u32::MAX,
        pose_queue_high_water: u16::MAX,
        tx_queue_high_water: u16::MAX,
        worst_sample_cycles: u32::MAX,
    });
    let caps = Capacities {
        max_actions: 255,
        max_pattern_len: 255,
        max_edits: 255,
        effort_features: 255,
        max_library_bytes: u32::MAX,
        max_effort_bytes: u32::MAX,
        pose_queue: u16::MAX,
    };
    let hello = DeviceToHost::Hello(DeviceHello {
        protocol_version: u16::MAX,
        build_id: u32::MAX,
        capacities: caps,
        library_crc: u32::MAX,
        effort_crc: u32::MAX,
    });
    let err = DeviceToHost::Error(DeviceError {
        code: ErrorCode::NoLibrary,
        detail: u32::MAX,
    });
    for (name, len) in [
        ("chunk", encode_frame(&chunk, &mut buf)),
        ("stats", encode_frame(&stats, &mut buf)),
        ("hello", encode_frame(&hello, &mut buf)),
        ("error", encode_frame(&err, &mut buf)),
        (
            "host hello",
            encode_frame(
                &HostToDevice::Hello(HostHello {
                    protocol_version: u16::MAX,
                    host_build: u32::MAX,
                }),
                &mut buf,
            ),
        ),
        (
            "ping",
            encode_frame(&HostToDevice::Ping(u32::MAX), &mut buf),
        ),
    ] {
        let len = len.unwrap_or_else(|e| panic!("{name}: {e}"));
        println!("largest {name} frame: {len} bytes (MAX_FRAME_LEN {MAX_FRAME_LEN})");
        assert!(len <= MAX_FRAME_LEN, "{name}");
    }
    // A guarded frame of the largest message also fits MAX_FRAME_LEN + 1.
    let mut guarded = [0u8; MAX_FRAME_LEN + 1];
    assert!(encode_frame_guarded(&chunk, &mut guarded).is_ok());
    // And a too-small output buffer is an error, not a panic.
    assert_eq!(
        encode_frame(&chunk, &mut [0u8; 10]),
        Err(ProtocolError::BufferTooSmall)
    );
}

#[test]
fn version_mismatch_is_detected_and_named() {
    assert!(check_version(PROTOCOL_VERSION).is_ok());
    let err = check_version(PROTOCOL_VERSION + 1).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains(&format!("version {PROTOCOL_VERSION}"))
            && text.contains(&format!("version {}", PROTOCOL_VERSION + 1)),
        "{text}"
    );
    // A Hello from a future version with extra fields still reveals its version.
    #[derive(serde::Serialize)]
    enum FutureMsg {
        Hello { v: u16, extra: [u8; 5], more: u64 },
    }
    let frame = to_frame(&FutureMsg::Hello {
        v: 9,
        extra: [1; 5],
        more: 77,
    })
    .unwrap();
    let mut dec = FrameDecoder::<MAX_FRAME_LEN>::new();
    match dec.feed_raw(&frame).0 {
        RawDecoded::Payload(p) => assert_eq!(peek_hello_version(p), Some(9)),
        other => panic!("{other:?}"),
    }
}

fn arb_pose() -> impl Strategy<Value = Pose> {
    (
        any::<u16>(),
        any::<u32>(),
        prop::array::uniform3(-1_000_000i32..=1_000_000),
        prop::array::uniform6(any::<u8>()),
    )
        .prop_map(|(seq, t_us, pos, rot)| Pose {
            seq,
            t_us,
            pos,
            rot,
        })
}

fn arb_kind() -> impl Strategy<Value = BlobKind> {
    prop_oneof![Just(BlobKind::Library), Just(BlobKind::Effort)]
}

fn arb_host() -> impl Strategy<Value = HostToDevice> {
    prop_oneof![
        (any::<u16>(), any::<u32>()).prop_map(|(v, b)| HostToDevice::Hello(HostHello {
            protocol_version: v,
            host_build: b
        })),
        arb_pose().prop_map(HostToDevice::Pose),
        (arb_kind(), any::<u32>(), any::<u32>()).prop_map(|(kind, len, crc32)| {
            HostToDevice::UploadBegin(UploadBegin { kind, len, crc32 })
        }),
        (
            arb_kind(),
            any::<u32>(),
            prop::collection::vec(any::<u8>(), 0..=MAX_CHUNK_LEN)
        )
            .prop_map(|(kind, offset, d)| HostToDevice::UploadChunk(UploadChunk {
                kind,
                offset,
                data: heapless::Vec::from_slice(&d).unwrap()
            })),
        arb_kind().prop_map(HostToDevice::UploadCommit),
        Just(HostToDevice::Reset),
        Just(HostToDevice::GetStats),
        any::<u32>().prop_map(HostToDevice::Ping),
    ]
}

fn arb_device() -> impl Strategy<Value = DeviceToHost> {
    prop_oneof![
        (
            any::<u8>(),
            any::<u8>(),
            any::<u16>(),
            any::<u16>(),
            any::<i8>(),
            any::<i8>(),
            any::<u8>()
        )
            .prop_map(|(seq, action, end_seq, len, time, weight, distance)| {
                DeviceToHost::Event(ActionEvent {
                    seq,
                    action,
                    end_seq,
                    len,
                    time,
                    weight,
                    distance,
                })
            }),
        (arb_kind(), any::<u32>())
            .prop_map(|(kind, next_offset)| DeviceToHost::UploadAck { kind, next_offset }),
        (arb_kind(), any::<u32>())
            .prop_map(|(kind, crc32)| DeviceToHost::UploadDone { kind, crc32 }),
        (any::<u32>(), any::<u32>(), any::<u16>()).prop_map(|(a, b, c)| DeviceToHost::Stats(
            Stats {
                samples: a,
                crc_errors: b,
                pose_queue_high_water: c,
                ..Stats::default()
            }
        )),
        any::<u32>().prop_map(DeviceToHost::Pong),
    ]
}

/// Garbage between frames: random bytes closed by a delimiter, or a valid frame cut short.
#[derive(Debug, Clone)]
enum Junk {
    Bytes(Vec<u8>),
    Truncated(usize),
}

fn arb_junk() -> impl Strategy<Value = Junk> {
    prop_oneof![
        prop::collection::vec(any::<u8>(), 0..300).prop_map(Junk::Bytes),
        (1usize..40).prop_map(Junk::Truncated),
    ]
}

fn drain<T: serde::de::DeserializeOwned>(
    dec: &mut FrameDecoder,
    mut input: &[u8],
    out: &mut Vec<T>,
    rejected: &mut usize,
) {
    loop {
        match dec.feed::<T>(input) {
            Decoded::NeedMore => return,
            Decoded::Message { msg, remaining } => {
                out.push(msg);
                input = remaining;
            }
            Decoded::Rejected { remaining, .. } => {
                *rejected += 1;
                input = remaining;
            }
        }
    }
}

proptest! {
    #[test]
    fn host_messages_round_trip(msg in arb_host()) {
        let frame = to_frame(&msg).unwrap();
        let mut dec = FrameDecoder::<MAX_FRAME_LEN>::new();
        let mut got: Vec<HostToDevice> = Vec::new();
        let mut rej = 0;
        drain(&mut dec, &frame, &mut got, &mut rej);
        prop_assert_eq!(got, vec![msg]);
        prop_assert_eq!(rej, 0);
    }

    #[test]
    fn device_messages_round_trip(msg in arb_device()) {
        let frame = to_frame(&msg).unwrap();
        let mut dec = FrameDecoder::<MAX_FRAME_LEN>::new();
        let mut got: Vec<DeviceToHost> = Vec::new();
        let mut rej = 0;
        drain(&mut dec, &frame, &mut got, &mut rej);
        prop_assert_eq!(got, vec![msg]);
    }

    /// Garbage and truncated frames between guarded frames, the stream cut into random chunks:
    /// every valid frame is still decoded, in order, and nothing panics.
    #[test]
    fn every_valid_frame_survives_garbage_between_frames(
        items in prop::collection::vec((arb_host(), prop::option::of(arb_junk())), 1..20),
        chunk in 1usize..64,
    ) {
        let mut stream = Vec::new();
        let mut sent = Vec::new();
        let mut buf = [0u8; MAX_FRAME_LEN + 1];
        for (msg, junk) in &items {
            match junk {
                Some(Junk::Bytes(b)) => stream.extend_from_slice(b),
                Some(Junk::Truncated(n)) => {
                    let f = to_frame(&HostToDevice::Ping(0xAAAA_AAAA)).unwrap();
                    stream.extend_from_slice(&f[..(*n).min(f.len() - 1)]);
                }
                None => {}
            }
            let n = encode_frame_guarded(msg, &mut buf).unwrap();
            stream.extend_from_slice(&buf[..n]);
            sent.push(msg.clone());
        }
        let mut dec = FrameDecoder::<MAX_FRAME_LEN>::new();
        let mut got: Vec<HostToDevice> = Vec::new();
        let mut rej = 0;
        for part in stream.chunks(chunk) {
            drain(&mut dec, part, &mut got, &mut rej);
        }
        // Garbage may by chance contain a valid frame (2^-16 per frame, and it must then parse),
        // so check that `sent` is a subsequence of what was received.
        let mut it = got.iter();
        for s in &sent {
            prop_assert!(it.any(|g| g == s), "lost {:?}", s);
        }
        let st = dec.stats();
        prop_assert_eq!(st.frames as usize, got.len() + st.decode_errors as usize);
        prop_assert_eq!(rej as u32, st.crc_errors + st.cobs_errors + st.oversize + st.decode_errors);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..2000)) {
        let mut dec = FrameDecoder::<MAX_FRAME_LEN>::new();
        let mut got: Vec<DeviceToHost> = Vec::new();
        let mut rej = 0;
        drain(&mut dec, &bytes, &mut got, &mut rej);
        prop_assert!(dec.pending() <= MAX_FRAME_LEN);
    }
}
