//! The messages of the figurine link, both directions, with their units.
//!
//! Encoding is postcard: unsigned integers are LEB128 varints, signed ones zigzag varints,
//! `u8`/`i8` single bytes, enums a varint variant index. Variant order is part of the wire
//! format: append new variants, never reorder (and bump [`crate::PROTOCOL_VERSION`]).

use heapless::Vec;
use serde::{Deserialize, Serialize};

use crate::pose::Pose;

/// Largest data chunk of one library/effort-model upload frame, bytes.
pub const MAX_CHUNK_LEN: usize = 64;

/// What the device can hold; sent in its [`DeviceHello`] so the host can check a library
/// fits before uploading it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Capacities {
    /// Most actions in a library.
    pub max_actions: u8,
    /// Most tokens in one compiled action pattern.
    pub max_pattern_len: u8,
    /// Most edits the approximate matcher allows per action.
    pub max_edits: u8,
    /// Laban features the effort model may use.
    pub effort_features: u8,
    /// Largest compiled library blob, bytes.
    pub max_library_bytes: u32,
    /// Largest effort-model blob, bytes.
    pub max_effort_bytes: u32,
    /// Capacity of the pose queue between link and recognizer, samples.
    pub pose_queue: u16,
}

/// The host's half of the version handshake. Its first field never moves, in any version.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HostHello {
    /// The host's [`crate::PROTOCOL_VERSION`].
    pub protocol_version: u16,
    /// Host software build identifier (free-form, for logs).
    pub host_build: u32,
}

/// The device's half of the version handshake. Its first field never moves, in any version.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DeviceHello {
    /// The firmware's [`crate::PROTOCOL_VERSION`].
    pub protocol_version: u16,
    /// Firmware build identifier (e.g. a hash of the firmware version string).
    pub build_id: u32,
    /// What the firmware can hold.
    pub capacities: Capacities,
    /// CRC-32 of the action library in use, 0 if none is loaded.
    pub library_crc: u32,
    /// CRC-32 of the effort model in use, 0 if the built-in default is used.
    pub effort_crc: u32,
}

/// A recognised action, as the device reports it. Fits 16 bytes on the wire.
///
/// The segment is named by the sequence numbers of its first and last pose samples, so the
/// host maps it back to the exact timestamps of the samples it sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ActionEvent {
    /// Event counter, +1 per event, wrapping; a gap means an event was lost. A
    /// [`DeviceToHost::Revised`] repeats the counter of the event it replaces.
    pub seq: u8,
    /// Index of the action in the uploaded library.
    pub action: u8,
    /// [`Pose::seq`] of the segment's last sample.
    pub end_seq: u16,
    /// Segment length in samples: start seq = `end_seq - len` (wrapping); saturates at 65 535.
    pub len: u16,
    /// Laban Time effort Lt × 127 (> 0 sudden, < 0 sustained).
    pub time: i8,
    /// Laban Weight effort Lw × 127 (> 0 strong, < 0 light).
    pub weight: i8,
    /// Edit distance of the approximate match, whole edits (near substitutions count half;
    /// rounded up).
    pub distance: u8,
}

/// Which blob an upload carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BlobKind {
    /// The compiled action library (the patterns; action names stay on the host, which maps
    /// action indices back to names).
    Library,
    /// The effort model (selected features and Gaussian parameters).
    Effort,
}

/// Starts an upload: the device erases its spare slot and expects `len` bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UploadBegin {
    /// What is uploaded.
    pub kind: BlobKind,
    /// Total blob length, bytes.
    pub len: u32,
    /// CRC-32 (ISO-HDLC) of the whole blob, checked at commit.
    pub crc32: u32,
}

/// One piece of an upload; chunks must arrive in order (`offset` = bytes sent before).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UploadChunk {
    /// What is uploaded.
    pub kind: BlobKind,
    /// Byte offset of `data` in the blob.
    pub offset: u32,
    /// Up to [`MAX_CHUNK_LEN`] bytes of the blob.
    pub data: Vec<u8, MAX_CHUNK_LEN>,
}

/// Statistics of the device since boot or the last `Reset`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stats {
    /// Pose samples received and queued for the recognizer.
    pub samples: u32,
    /// Samples the recognizer skipped as invalid (time backwards, jumps, bad values).
    pub invalid_samples: u32,
    /// Samples dropped because the pose queue was full.
    pub samples_dropped: u32,
    /// Gaps in pose sequence numbers (frames lost before reaching the device).
    pub seq_gaps: u32,
    /// Action events sent.
    pub events: u32,
    /// Frames received intact.
    pub frames_ok: u32,
    /// Frames rejected for a CRC mismatch.
    pub crc_errors: u32,
    /// Frames rejected for invalid COBS stuffing.
    pub cobs_errors: u32,
    /// Frames with a good CRC that were not valid messages.
    pub decode_errors: u32,
    /// Frames longer than the receive buffer.
    pub oversize: u32,
    /// Most samples ever waiting in the pose queue.
    pub pose_queue_high_water: u16,
    /// Most messages ever waiting in the transmit queue.
    pub tx_queue_high_water: u16,
    /// Worst time the recognizer spent on one sample, CPU cycles.
    pub worst_sample_cycles: u32,
}

/// Why the device refused or failed something.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ErrorCode {
    /// The host's `Hello` named another protocol version (`detail` = the device's version).
    VersionMismatch,
    /// A message the device does not accept in its current state.
    Unexpected,
    /// An upload chunk or commit arrived without `UploadBegin`.
    UploadNotStarted,
    /// A chunk's offset is not the next expected one (`detail` = expected offset).
    UploadOutOfOrder,
    /// The announced blob is larger than the device holds (`detail` = capacity, bytes).
    UploadTooLarge,
    /// The uploaded bytes do not match the announced CRC-32.
    UploadCrc,
    /// The blob's content is invalid for the recognizer (`detail` = reason code).
    BlobInvalid,
    /// Writing flash failed; the previous blob stays active.
    FlashWrite,
    /// No action library is loaded, so nothing can be recognised.
    NoLibrary,
}

/// An error report from the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DeviceError {
    /// What went wrong.
    pub code: ErrorCode,
    /// Extra information; meaning given per [`ErrorCode`] variant.
    pub detail: u32,
}

/// Messages from the host to the device.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HostToDevice {
    /// Version handshake; the device answers with its `Hello`.
    Hello(HostHello),
    /// One tracker pose sample.
    Pose(Pose),
    /// Begin uploading a blob.
    UploadBegin(UploadBegin),
    /// Next piece of the blob; answered by `UploadAck`.
    UploadChunk(UploadChunk),
    /// Verify and persist the uploaded blob; answered by `UploadDone` or `Error`.
    UploadCommit(BlobKind),
    /// End of a session: the device first emits any action still waiting for its
    /// look-ahead (as host simulation does at the end of a log), then restarts recognition
    /// and statistics. The library and effort model stay.
    Reset,
    /// Ask for `Stats`.
    GetStats,
    /// Liveness check; the device echoes the value in `Pong`.
    Ping(u32),
}

/// Messages from the device to the host.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DeviceToHost {
    /// Version handshake, sent at boot and in answer to the host's `Hello`.
    Hello(DeviceHello),
    /// A recognised action.
    Event(ActionEvent),
    /// An upload chunk was stored; `next_offset` = bytes received so far.
    UploadAck {
        /// What is being uploaded.
        kind: BlobKind,
        /// Bytes of the blob received so far.
        next_offset: u32,
    },
    /// The blob was verified, persisted and is now active; `crc32` identifies it.
    UploadDone {
        /// What was uploaded.
        kind: BlobKind,
        /// CRC-32 of the active blob.
        crc32: u32,
    },
    /// Statistics, in answer to `GetStats`.
    Stats(Stats),
    /// Something was refused or failed.
    Error(DeviceError),
    /// Answer to `Ping`, echoing its value.
    Pong(u32),
    /// The previous `Event` (same `seq`) revised, to be replaced by this one: the next cycles
    /// of a cyclic action (a walk's next hops after a short pause) extended it — this carries
    /// the whole segment, effort and distance over all of it — or a longer action took over
    /// an event reported while the figurine paused inside it (a punch held at full reach
    /// after strides that alone read as a run). Sent only right after the event it revises
    /// (or after another revision of it).
    Revised(ActionEvent),
}

/// Reads the protocol version from a `Hello` payload of *any* version (variant 0 with the
/// version as first field), or `None` if the payload is not a `Hello`.
pub fn peek_hello_version(payload: &[u8]) -> Option<u16> {
    let (tag, rest) = payload.split_first()?;
    if *tag != 0 {
        return None;
    }
    postcard::take_from_bytes::<u16>(rest).ok().map(|(v, _)| v)
}
