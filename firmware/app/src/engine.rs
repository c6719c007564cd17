//! The recognizer task: takes the inbox in order — poses into the recognizer, commands
//! (handshake, uploads, reset, statistics, ping) answered — and queues what goes back.
//!
//! Samples are fed exactly as host simulation feeds them: sequence numbers and timestamps
//! unwrapped with the protocol's `SeqUnwrapper`/`TimeUnwrapper`, position and orientation
//! dequantised with `Pose::position_m`/`Pose::orientation`, so both compute the same bits.

use figurine_protocol::pose::{SeqUnwrapper, TimeUnwrapper};
use figurine_protocol::{
    ActionEvent, BlobKind, Capacities, DeviceError, DeviceHello, DeviceToHost, ErrorCode,
    HostHello, HostToDevice, Pose, PROTOCOL_VERSION,
};
use figurine_recognizer::bayes::MAX_EFFORT_FEATURES;
use figurine_recognizer::pattern::{MAX_ACTIONS, MAX_EDITS, MAX_POSITIONS};
use figurine_recognizer::{Recognizer, Sample};

use crate::blobs::{self, Blobs};
use crate::board::{self, Flash, Stopwatch};
use crate::channels::{send_to_host, INBOX, INBOX_CAPACITY};
use crate::stats;

/// Room for the events one `push` or `flush` of the recognizer hands back before they are
/// queued for the host (48 B each). The most measured is 2 from one sample and 3 from one
/// flush (`host/tests/events_per_call.rs` asserts at most half this room over generated
/// sequences, repetitions and a hand that talks). An event past the room is dropped, since
/// the recognizer's callback cannot wait for the queue: not counted (`Stats` has no field for
/// it, and one changes the wire format) nor logged (a `defmt` warning at either call costs
/// 640 B of flash, past the 64 KiB budget).
pub const EVENTS_PER_CALL: usize = 6;

/// Identifies this firmware build in `Hello` (FNV-1a of crate version and board name).
pub const BUILD_ID: u32 = fnv1a(concat!(
    env!("CARGO_PKG_NAME"),
    " ",
    env!("CARGO_PKG_VERSION"),
    " "
))
.wrapping_add(fnv1a(board::NAME));

const fn fnv1a(s: &str) -> u32 {
    let b = s.as_bytes();
    let mut h: u32 = 0x811C_9DC5;
    let mut i = 0;
    while i < b.len() {
        h ^= b[i] as u32;
        h = h.wrapping_mul(0x0100_0193);
        i += 1;
    }
    h
}

/// Recognition state and the persisted blobs.
pub struct Engine {
    blobs: Blobs,
    recognizer: Recognizer<'static>,
    seq: SeqUnwrapper,
    time: TimeUnwrapper,
    last_seq: Option<u32>,
    event_seq: u8,
    /// Sum of per-sample cycles since the last reset (for the mean logged with `GetStats`).
    total_cycles: u64,
}

impl Engine {
    /// Loads the blobs from flash and starts a recognizer on them.
    pub fn boot(flash: Flash) -> Self {
        let blobs = Blobs::boot(flash);
        let recognizer = Recognizer::new(blobs.library(), blobs.effort());
        Engine {
            blobs,
            recognizer,
            seq: SeqUnwrapper::default(),
            time: TimeUnwrapper::default(),
            last_seq: None,
            event_seq: 0,
            total_cycles: 0,
        }
    }

    /// Our half of the handshake.
    pub fn hello(&self) -> DeviceHello {
        DeviceHello {
            protocol_version: PROTOCOL_VERSION,
            build_id: BUILD_ID,
            capacities: Capacities {
                max_actions: MAX_ACTIONS as u8,
                max_pattern_len: MAX_POSITIONS as u8,
                max_edits: MAX_EDITS as u8,
                effort_features: MAX_EFFORT_FEATURES as u8,
                max_library_bytes: blobs::capacity(BlobKind::Library),
                max_effort_bytes: blobs::capacity(BlobKind::Effort),
                pose_queue: INBOX_CAPACITY as u16,
            },
            library_crc: self.blobs.crc(BlobKind::Library),
            effort_crc: self.blobs.crc(BlobKind::Effort),
        }
    }

    async fn pose(&mut self, p: &Pose) {
        let seq = self.seq.unwrap(p.seq);
        let t_us = self.time.unwrap(p.t_us);
        let gap = self
            .last_seq
            .is_some_and(|last| seq != last.wrapping_add(1));
        self.last_seq = Some(seq);
        let sample = Sample {
            seq,
            t_us,
            pos: p.position_m(),
            quat: p.orientation(),
        };
        let mut events: heapless::Vec<figurine_recognizer::ActionEvent, EVENTS_PER_CALL> =
            heapless::Vec::new();
        let watch = Stopwatch::start();
        self.recognizer.push(&sample, |e| {
            // Past the room, dropped (`EVENTS_PER_CALL`).
            let _ = events.push(e);
        });
        let cycles = watch.cycles();
        self.total_cycles = self.total_cycles.wrapping_add(u64::from(cycles));
        let invalid = self.recognizer.stats().intake.skipped();
        stats::update(|s| {
            s.samples = s.samples.wrapping_add(1);
            s.seq_gaps = s.seq_gaps.wrapping_add(u32::from(gap));
            s.worst_sample_cycles = s.worst_sample_cycles.max(cycles);
            s.invalid_samples = invalid;
        });
        for e in events {
            self.emit(e).await;
        }
    }

    async fn emit(&mut self, e: figurine_recognizer::ActionEvent) {
        let len = e.end_seq.wrapping_sub(e.start_seq).min(u32::from(u16::MAX)) as u16;
        // A revision repeats the counter of the event it replaces.
        let seq = if e.revises {
            self.event_seq.wrapping_sub(1)
        } else {
            self.event_seq
        };
        let msg = ActionEvent {
            seq,
            action: e.action,
            end_seq: e.end_seq as u16,
            len,
            time: e.time_q,
            weight: e.weight_q,
            distance: e.distance,
        };
        defmt::info!("event {} (revises: {})", msg, e.revises);
        stats::update(|s| s.events = s.events.wrapping_add(1));
        if e.revises {
            send_to_host(DeviceToHost::Revised(msg)).await;
        } else {
            self.event_seq = self.event_seq.wrapping_add(1);
            send_to_host(DeviceToHost::Event(msg)).await;
        }
    }

    /// Ends the current session: emits any action still waiting for its look-ahead, then
    /// restarts recognition, sequence tracking and statistics (the blobs stay).
    async fn reset(&mut self) {
        let mut events: heapless::Vec<figurine_recognizer::ActionEvent, EVENTS_PER_CALL> =
            heapless::Vec::new();
        self.recognizer.flush(|e| {
            // Past the room, dropped (`EVENTS_PER_CALL`).
            let _ = events.push(e);
        });
        for e in events {
            self.emit(e).await;
        }
        self.restart();
        stats::clear();
    }

    fn restart(&mut self) {
        self.recognizer = Recognizer::new(self.blobs.library(), self.blobs.effort());
        self.seq = SeqUnwrapper::default();
        self.time = TimeUnwrapper::default();
        self.last_seq = None;
        self.total_cycles = 0;
    }

    async fn hello_from_host(&mut self, h: HostHello) {
        if h.protocol_version != PROTOCOL_VERSION {
            defmt::warn!(
                "host speaks protocol {}, we speak {}",
                h.protocol_version,
                PROTOCOL_VERSION
            );
            send_to_host(DeviceToHost::Error(DeviceError {
                code: ErrorCode::VersionMismatch,
                detail: u32::from(PROTOCOL_VERSION),
            }))
            .await;
        }
        send_to_host(DeviceToHost::Hello(self.hello())).await;
    }

    /// Handles one inbox message.
    pub async fn handle(&mut self, msg: HostToDevice) {
        let reply = match msg {
            HostToDevice::Pose(p) => {
                self.pose(&p).await;
                return;
            }
            HostToDevice::Hello(h) => {
                self.hello_from_host(h).await;
                return;
            }
            HostToDevice::Reset => {
                self.reset().await;
                return;
            }
            HostToDevice::Ping(v) => DeviceToHost::Pong(v),
            HostToDevice::GetStats => {
                let s = stats::snapshot();
                // The mean is left to the reader: a 64-bit division would pull in 0.8 KiB of
                // software division for this one log line.
                defmt::info!(
                    "stats: {} samples, {} cycles total, {} worst",
                    s.samples,
                    self.total_cycles,
                    s.worst_sample_cycles
                );
                DeviceToHost::Stats(s)
            }
            HostToDevice::UploadBegin(b) => match self.blobs.begin(&b) {
                Ok(()) => DeviceToHost::UploadAck {
                    kind: b.kind,
                    next_offset: 0,
                },
                Err(e) => DeviceToHost::Error(e),
            },
            HostToDevice::UploadChunk(c) => match self.blobs.chunk(&c) {
                Ok(next_offset) => DeviceToHost::UploadAck {
                    kind: c.kind,
                    next_offset,
                },
                Err(e) => DeviceToHost::Error(e),
            },
            HostToDevice::UploadCommit(kind) => match self.blobs.commit(kind) {
                Ok(crc32) => {
                    match kind {
                        BlobKind::Library => self.recognizer.set_library(self.blobs.library()),
                        BlobKind::Effort => self.recognizer.set_effort(self.blobs.effort()),
                    }
                    defmt::info!("{} committed, crc {=u32:08x}", kind, crc32);
                    DeviceToHost::UploadDone { kind, crc32 }
                }
                Err(e) => DeviceToHost::Error(e),
            },
        };
        if let DeviceToHost::Error(e) = &reply {
            defmt::warn!("refused: {}", e);
        }
        send_to_host(reply).await;
    }
}

/// Boots the engine, announces the device, then serves the inbox forever.
#[embassy_executor::task]
pub async fn task(flash: Flash) {
    let mut engine = Engine::boot(flash);
    if !engine.blobs.has_library() {
        defmt::info!("no action library yet: upload one with `figurine upload`");
    }
    send_to_host(DeviceToHost::Hello(engine.hello())).await;
    loop {
        let msg = INBOX.receive().await;
        engine.handle(msg).await;
    }
}
