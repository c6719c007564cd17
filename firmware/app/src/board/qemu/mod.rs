//! QEMU `mps2-an386` (Cortex-M4F at 25 MHz), run by `qemu-system-arm -M mps2-an386`.
//!
//! * link: CMSDK APB UART0, interrupt-driven ([`uart`]);
//! * clock: SysTick, free-running, as the cycle stopwatch; no time driver (nothing waits on a
//!   clock: samples carry their own time);
//! * flash: RAM-backed NOR emulation with power-cut injection ([`flash`]);
//! * logs: defmt over semihosting; a panic exits QEMU with status 101 (semihosting `exit`).
//!
//! Memory map: `hw/mps2-an386/memory.x`; details in `hw/README.md`.

mod flash;
mod uart;
mod vectors;

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;

pub use flash::{mapped_flash, Flash, STORE_SIZE};
pub use uart::{SerialRx, SerialTx};

use super::Board;

/// Board name (part of the build id).
pub const NAME: &str = "qemu-mps2-an386";
/// Marks the ELF as built for this board, so the e2e tests refuse a binary for another one.
#[used]
static BOARD_TAG: [u8; 30] = *b"figurine-board:qemu-mps2-an386";

/// Core and SysTick clock, Hz.
pub const CORE_HZ: u32 = 25_000_000;
/// SysTick reload: the full 24 bits, so one wrap is 0.67 s (the stopwatch's range).
const SYSTICK_RELOAD: u32 = 0x00FF_FFFF;
/// Semihosting command-line buffer, bytes.
const ARGS_BUF: usize = 256;

/// Cycles spent in the UART's interrupt handlers since boot (wrapping): a stopwatch leaves
/// them out, so that a sample's processing time does not depend on when the host's bytes
/// happened to arrive.
static HANDLER_CYCLES: AtomicU32 = AtomicU32::new(0);

/// Counts core clock cycles over an interval shorter than one SysTick wrap (0.67 s), less
/// those the UART's interrupt handlers took meanwhile ([`in_handler`]). Under
/// `qemu-system-arm -icount shift=0` one instruction takes 1 ns of virtual time, so
/// instructions = cycles × 40 exactly (25 MHz), and counts repeat run to run (up to the
/// handlers' few instructions outside their own stopwatch).
pub struct Stopwatch {
    systick: u32,
    handlers: u32,
}

impl Stopwatch {
    /// Starts counting.
    pub fn start() -> Self {
        Stopwatch {
            systick: SYST::get_current(),
            handlers: HANDLER_CYCLES.load(Ordering::Relaxed),
        }
    }

    /// Cycles since `start`, less the interrupt handlers'.
    pub fn cycles(&self) -> u32 {
        let all = self.systick.wrapping_sub(SYST::get_current()) & SYSTICK_RELOAD;
        let handlers = HANDLER_CYCLES
            .load(Ordering::Relaxed)
            .wrapping_sub(self.handlers);
        all.saturating_sub(handlers)
    }
}

/// Runs interrupt handler body `f`, adding the cycles it takes to [`HANDLER_CYCLES`].
fn in_handler(f: impl FnOnce()) {
    let start = SYST::get_current();
    f();
    let took = start.wrapping_sub(SYST::get_current()) & SYSTICK_RELOAD;
    // A handler does not nest with itself; the two UART handlers share one priority.
    HANDLER_CYCLES.store(
        HANDLER_CYCLES.load(Ordering::Relaxed).wrapping_add(took),
        Ordering::Relaxed,
    );
}

/// Reads the power-cut fault injection from the semihosting command line
/// (`qemu-system-arm … -semihosting-config enable=on,target=native,arg=fw,arg=cut=U:K`).
fn fault_from_args() -> Option<flash::Cut> {
    let args = semihosting::experimental::env::args::<ARGS_BUF>().ok()?;
    let mut cut = None;
    for arg in (&args).flatten() {
        if let Some(spec) = arg.strip_prefix("cut=") {
            let (u, k) = spec.split_once(':')?;
            cut = Some(flash::Cut {
                upload: u.parse().ok()?,
                after_bytes: k.parse().ok()?,
            });
        }
    }
    cut
}

/// Brings up the board: the SysTick stopwatch, UART0 with its interrupts, the RAM-backed flash.
pub fn init() -> Board {
    let Some(mut core) = cortex_m::Peripherals::take() else {
        // Only reachable if init ran twice.
        semihosting::process::exit(102)
    };
    // Counting down from the full 24 bits at the core clock, without an interrupt.
    core.SYST.set_clock_source(SystClkSource::Core);
    core.SYST.set_reload(SYSTICK_RELOAD);
    core.SYST.clear_current();
    core.SYST.enable_counter();
    let (rx, tx) = uart::init(&mut core.NVIC);
    let flash = Flash::new(fault_from_args());
    if let Some(c) = flash.armed() {
        defmt::info!(
            "fault injection armed: power cut in upload {} after {} bytes",
            c.upload,
            c.after_bytes
        );
    }
    Board { rx, tx, flash }
}

#[cortex_m_rt::exception]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    defmt::error!("hard fault at pc {=u32:08x}", frame.pc());
    semihosting::process::exit(103)
}

#[cortex_m_rt::exception]
unsafe fn DefaultHandler(irq: i16) {
    defmt::error!("unexpected exception/interrupt {}", irq);
    semihosting::process::exit(104)
}

/// Stops the board for good: QEMU exits with `code` (semihosting), so a test sees it.
pub fn halt(code: i32) -> ! {
    semihosting::process::exit(code)
}
