//! The thread-mode executor: polls the embassy tasks, then sleeps with `WFI` until an
//! interrupt wakes one.
//!
//! embassy's stock Cortex-M thread executor sleeps with `WFE`, which QEMU implements as a
//! mere yield: the emulated core then spins, holding QEMU's global lock, and every byte of
//! the emulated UART waits milliseconds for it. `WFI` really halts the core in QEMU (and on
//! the nRF52840 saves the same power), so the link runs at full speed.

use core::sync::atomic::{AtomicBool, Ordering};

use embassy_executor::{raw, Spawner};
use static_cell::StaticCell;

/// Set when a task was woken since the last poll.
static WOKEN: AtomicBool = AtomicBool::new(false);

/// Called by embassy (from tasks or interrupts) when a task became ready.
#[export_name = "__pender"]
fn pender(_context: *mut ()) {
    WOKEN.store(true, Ordering::Release);
}

/// Starts the executor: `init` spawns the tasks, then tasks run forever.
pub fn run(init: impl FnOnce(Spawner)) -> ! {
    static EXECUTOR: StaticCell<raw::Executor> = StaticCell::new();
    let executor: &'static raw::Executor = EXECUTOR.init(raw::Executor::new(core::ptr::null_mut()));
    init(executor.spawner());
    loop {
        // SAFETY: `poll` is only called from this loop, in thread mode, never re-entrantly.
        unsafe { executor.poll() };
        // With interrupts masked, a wake-up that lands between the check and `WFI` still
        // ends the sleep (WFI wakes on any pending interrupt, masked or not).
        cortex_m::interrupt::free(|_| {
            if !WOKEN.swap(false, Ordering::AcqRel) {
                cortex_m::asm::wfi();
            }
        });
    }
}
