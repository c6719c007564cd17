//! figurine firmware: the online action/effort recognizer on a Cortex-M4F.
//!
//! ```text
//! serial RX ─▶ link_rx ──INBOX──▶ engine (recognizer, uploads, stats) ──OUTBOX──▶ link_tx ─▶ serial TX
//! ```
//!
//! `main` only wires the board (`board`, chosen by cargo feature) and spawns the three tasks;
//! the queues and their capacities are in `channels`.
#![no_std]
#![no_main]

mod blobs;
mod board;
mod channels;
mod engine;
mod executor;
mod link_rx;
mod link_tx;
mod panic;
mod stats;

#[cfg(feature = "qemu")]
use defmt_semihosting as _;

#[cortex_m_rt::entry]
fn main() -> ! {
    let board = board::init();
    defmt::info!(
        "figurine firmware {} on {} ({} Hz), build {=u32:08x}",
        env!("CARGO_PKG_VERSION"),
        board::NAME,
        board::CORE_HZ,
        engine::BUILD_ID
    );
    executor::run(|spawner| {
        spawner.spawn(link_rx::task(board.rx).expect("link_rx spawned once"));
        spawner.spawn(engine::task(board.flash).expect("engine spawned once"));
        spawner.spawn(link_tx::task(board.tx).expect("link_tx spawned once"));
    })
}
