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
        spawner.spawn(once(link_rx::task(board.rx), "link_rx"));
        spawner.spawn(once(engine::task(board.flash), "engine"));
        spawner.spawn(once(link_tx::task(board.tx), "link_tx"));
    })
}

/// The spawn token of a task `main` spawns once, so its pool of one is never busy. Not
/// `expect`: the error's `Debug` text would link `core::fmt`'s padding code (≈ 0.6 KiB of
/// flash) for a panic that cannot happen.
fn once<T>(token: Result<T, embassy_executor::SpawnError>, task: &str) -> T {
    match token {
        Ok(t) => t,
        Err(_) => defmt::panic!("task {=str} spawned twice", task),
    }
}
