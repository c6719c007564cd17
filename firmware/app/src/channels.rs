//! The bounded queues between the tasks, with their capacities.
//!
//! ```text
//! link_rx ──INBOX──▶ engine (recognizer, uploads, stats) ──OUTBOX──▶ link_tx
//! ```
//!
//! One inbox keeps poses and commands in arrival order, so `Reset` and `Ping` act as barriers
//! (a `Pong` leaves only after every earlier pose was processed and its events queued).

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use figurine_protocol::{DeviceToHost, HostToDevice};

/// Messages waiting for the engine. When full, a pose is dropped and counted in
/// `Stats::samples_dropped`; a command waits for room (the link then back-pressures).
/// 32 × 84 B ≈ 2.7 KiB; at 1 kHz this absorbs 32 ms of engine stall.
pub const INBOX_CAPACITY: usize = 32;
/// Messages waiting for the transmitter. When full, the engine waits: no event is dropped here
/// (what one recognizer call hands back waits in the engine's `EVENTS_PER_CALL` before it).
pub const OUTBOX_CAPACITY: usize = 16;

/// Link receiver → engine.
pub static INBOX: Channel<CriticalSectionRawMutex, HostToDevice, INBOX_CAPACITY> = Channel::new();
/// Engine → link transmitter.
pub static OUTBOX: Channel<CriticalSectionRawMutex, DeviceToHost, OUTBOX_CAPACITY> = Channel::new();

/// Queues `msg` for the transmitter (waiting for room) and records the queue's high-water mark.
pub async fn send_to_host(msg: DeviceToHost) {
    OUTBOX.send(msg).await;
    let len = OUTBOX.len() as u16;
    crate::stats::update(|s| {
        s.tx_queue_high_water = s.tx_queue_high_water.max(len);
    });
}
