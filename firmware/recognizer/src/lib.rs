//! figurine's online recognizer: which actions a toy figurine was made to do, and how.
//!
//! `no_std`, no allocator, no panics on any input, no clock: samples come in with their
//! sequence numbers and timestamps ([`Sample`]), recognised actions go out as
//! [`ActionEvent`]s with Laban Time and Weight efforts. The same code runs on the MCU and in
//! host simulation, and all float math goes through [`fmath`] (libm, and the FPU's correctly
//! rounded square root on the MCU), so both compute the same bits.
//!
//! Stages, one module each, in data-flow order:
//! [`intake`] (validate, resample to 100 Hz) → [`filter`] (Savitzky–Golay) → [`frame`]
//! (object-frame velocities) → [`token`] (27×27 + STILL) → [`pattern`] (compiled regexes) →
//! [`automaton`] (bit-parallel Levenshtein automata, edits weighted by [`alignment`]: near
//! tokens cost half; a match's motion against its action's: [`shape`]) → [`segment`] (online
//! decision; stand-alone gestures no action matched given to their [`nearest`] action; a
//! match right after an event may be its next piece, its rest or its settling: [`follow`]; a
//! new event only when it went as far as its action's examples, not a fidget: [`extent`], and
//! was not one sweep of a hand carrying the toy where the examples made several pushes:
//! [`sweep`]) →
//! [`features`] (58 Laban features: the seed's 50, redefined, plus 8) → [`bayes`] (Time and
//! Weight: naive Bayes or a linear discriminant per axis). [`frontend`] and
//! [`history`] join the first stages; [`recognizer`] is the whole pipeline, and tells a
//! reader who asks why a match was dropped or read as another action ([`note`]).
//!
//! # Capacities and RAM (with 32 actions loaded)
//! | constant | value | RAM |
//! |---|---|---|
//! | [`pattern::MAX_ACTIONS`] | 32 actions | 64 B of record offsets (patterns stay in flash) |
//! | [`pattern::MAX_POSITIONS`] | 32 tokens per pattern | blob ≤ [`pattern::MAX_LIBRARY_BYTES`] (flash) |
//! | [`pattern::MAX_EDITS`] | 3 edits per action | 32 × 7 × 8 B = 1.75 KiB of automaton state (half-edit levels) |
//! | [`history::HISTORY_RUNS`] | 40 token runs | ≈ 11.6 KiB (features per run) |
//! | [`filter::SG_WINDOW`] | 11 ticks (110 ms) | ≈ 0.6 KiB |
//! | [`token::SWEEP_TICKS`] | 8 ticks of a quick stroke after stillness | 16 B |
//! | [`bayes::MAX_EFFORT_FEATURES`] | 16 per axis | ≈ 0.6 KiB; blob ≤ [`bayes::MAX_EFFORT_BYTES`] |
//! | [`alignment::MAX_COST`] | 23 half-edits | 192 B of stack while a candidate is weighed |
//! | [`nearest::NEAREST_MAX_TOKENS`] | 24 tokens per stand-alone phrase | 96 B of stack |
//! | [`history::HISTORY_RUNS`] tokens after an event | its next piece or rest, weighed whole ([`follow`]) | 80 B of stack at a commit |
//!
//! Latency: the filter adds 50 ms; an action is reported [`segment::PAUSE_US`] after the
//! figurine stops, or [`segment::LOOKAHEAD_TOKENS`] tokens after it ends when actions follow
//! each other without a pause. When it may still change — the next cycle of a cyclic action,
//! the rest of a one-shot one, or a longer action it is part of, may follow — it is reported
//! then all the same, and revised if it does change ([`ActionEvent::revises`]).
#![no_std]
#![forbid(unsafe_code)]

#[cfg(feature = "std")]
extern crate std;

pub mod alignment;
pub mod automaton;
pub mod bayes;
pub mod extent;
pub mod features;
pub mod filter;
pub mod fmath;
pub mod follow;
pub mod frame;
pub mod frontend;
pub mod history;
pub mod intake;
pub mod nearest;
pub mod noise;
pub mod note;
pub mod pattern;
pub mod recognizer;
pub mod segment;
pub mod shape;
pub mod sweep;
pub mod token;

pub use bayes::EffortModel;
pub use intake::Sample;
pub use note::{Note, Why};
pub use pattern::Library;
pub use recognizer::{ActionEvent, Recognizer, Stats};

/// Why a library or effort blob was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// The blob ends early.
    Truncated,
    /// The blob is larger than the format allows.
    TooLarge,
    /// Wrong magic bytes.
    BadMagic,
    /// Unsupported format version (the byte found).
    Version(u8),
    /// A count exceeds a compile-time capacity.
    Capacity,
    /// A field is inconsistent (what).
    Invalid(&'static str),
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Error::Truncated => f.write_str("blob truncated"),
            Error::TooLarge => f.write_str("blob too large"),
            Error::BadMagic => f.write_str("bad magic bytes"),
            Error::Version(v) => write!(f, "unsupported format version {v}"),
            Error::Capacity => f.write_str("capacity exceeded"),
            Error::Invalid(what) => write!(f, "invalid {what}"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for Error {}
