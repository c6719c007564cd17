//! nRF52840 board (e.g. Seeed XIAO nRF52840, small enough to sit inside a figurine).
//!
//! * link: UARTE0 at 1 Mbaud, RX P1.12 / TX P1.11 (XIAO pins D7 / D6), DMA-buffered
//!   (`BufferedUarte`, [`RX_BUFFER`]/[`TX_BUFFER`] bytes); see `hw/README.md` for wiring;
//! * clock: the DWT cycle counter as the stopwatch (64 MHz); no time driver (nothing waits on
//!   a clock: samples carry their own time);
//! * flash: the NVMC over the STORE region of the root `memory.x` (64 KiB at 0xF_0000);
//! * logs: defmt over RTT (probe-rs); a panic logs its location and halts on `UDF`.

use cortex_m::peripheral::DWT;
use defmt_rtt as _;
use embassy_nrf::buffered_uarte::{self, BufferedUarte, BufferedUarteRx, BufferedUarteTx};
use embassy_nrf::nvmc::Nvmc;
use embassy_nrf::{bind_interrupts, peripherals, uarte};
use embedded_storage::nor_flash::{ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash};
use static_cell::StaticCell;

use super::Board;

/// Board name (part of the build id).
pub const NAME: &str = "nrf52840";
/// Core clock, Hz.
pub const CORE_HZ: u32 = 64_000_000;
/// UARTE receive ring buffer, bytes (≈ 50 pose frames).
pub const RX_BUFFER: usize = 1024;
/// UARTE transmit ring buffer, bytes.
pub const TX_BUFFER: usize = 256;
/// First byte of the STORE region (root `memory.x`).
const STORE_BASE: u32 = 0x000F_0000;
/// Size of the STORE region, bytes.
pub const STORE_SIZE: usize = 64 * 1024;

bind_interrupts!(struct Irqs {
    UARTE0 => buffered_uarte::InterruptHandler<peripherals::UARTE0>;
});

/// Counts core clock cycles (DWT CYCCNT, wraps every 67 s).
pub struct Stopwatch(u32);

impl Stopwatch {
    /// Starts counting.
    pub fn start() -> Self {
        Stopwatch(DWT::cycle_count())
    }

    /// Cycles since `start`.
    pub fn cycles(&self) -> u32 {
        DWT::cycle_count().wrapping_sub(self.0)
    }
}

/// Receive half of the link.
pub struct SerialRx(BufferedUarteRx<'static>);

impl SerialRx {
    /// Waits for at least one received byte; returns how many were copied into `buf`.
    /// A UART error (overrun, framing) is logged and reads on; the frame decoder then
    /// rejects the damaged frame and counts it.
    pub async fn read(&mut self, buf: &mut [u8]) -> usize {
        loop {
            match self.0.read(buf).await {
                Ok(n) if n > 0 => return n,
                Ok(_) => {}
                Err(e) => defmt::warn!("UARTE receive error: {}", e),
            }
        }
    }
}

/// Transmit half of the link.
pub struct SerialTx(BufferedUarteTx<'static>);

impl SerialTx {
    /// Writes every byte of `bytes`.
    pub async fn write_all(&mut self, bytes: &[u8]) {
        if let Err(e) = embedded_io_async::Write::write_all(&mut self.0, bytes).await {
            defmt::warn!("UARTE transmit error: {}", e);
        }
    }
}

/// The NVMC, seen through the STORE region only (offsets relative to its start).
pub struct Flash(Nvmc<'static>);

impl ErrorType for Flash {
    type Error = NorFlashErrorKind;
}

fn kind<E: embedded_storage::nor_flash::NorFlashError>(e: E) -> NorFlashErrorKind {
    e.kind()
}

impl ReadNorFlash for Flash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        embedded_storage::nor_flash::check_read(self, offset, bytes.len())?;
        self.0.read(STORE_BASE + offset, bytes).map_err(kind)
    }

    fn capacity(&self) -> usize {
        STORE_SIZE
    }
}

impl NorFlash for Flash {
    const WRITE_SIZE: usize = <Nvmc<'static> as NorFlash>::WRITE_SIZE;
    const ERASE_SIZE: usize = <Nvmc<'static> as NorFlash>::ERASE_SIZE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        embedded_storage::nor_flash::check_erase(self, from, to)?;
        self.0
            .erase(STORE_BASE + from, STORE_BASE + to)
            .map_err(kind)
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        embedded_storage::nor_flash::check_write(self, offset, bytes.len())?;
        self.0.write(STORE_BASE + offset, bytes).map_err(kind)
    }
}

/// The bytes `offset..offset + len` of the STORE region, in place (empty if out of bounds).
///
/// Callers pass only the active blob of a two-slot store, which is never erased or written
/// while active (uploads go to the other slot), so the shared slice never changes under them.
pub fn mapped_flash(offset: u32, len: u32) -> &'static [u8] {
    let (offset, len) = (offset as usize, len as usize);
    if offset > STORE_SIZE || len > STORE_SIZE - offset {
        return &[];
    }
    // SAFETY: in bounds of the STORE region of the memory-mapped internal flash, which is
    // always readable; see above for why the bytes stay unchanged while the slice is used.
    unsafe { core::slice::from_raw_parts((STORE_BASE as usize + offset) as *const u8, len) }
}

/// Brings up the board: clocks, the cycle counter, UARTE0, the NVMC.
pub fn init() -> Board {
    let p = embassy_nrf::init(Default::default());
    if let Some(mut core) = cortex_m::Peripherals::take() {
        core.DCB.enable_trace();
        core.DWT.enable_cycle_counter();
    }
    static RX_BUF: StaticCell<[u8; RX_BUFFER]> = StaticCell::new();
    static TX_BUF: StaticCell<[u8; TX_BUFFER]> = StaticCell::new();
    let mut config = uarte::Config::default();
    config.baudrate = uarte::Baudrate::Baud1m;
    let uart = BufferedUarte::new(
        p.UARTE0,
        p.TIMER0,
        p.PPI_CH0,
        p.PPI_CH1,
        p.PPI_GROUP0,
        p.P1_12,
        p.P1_11,
        Irqs,
        config,
        RX_BUF.init([0; RX_BUFFER]),
        TX_BUF.init([0; TX_BUFFER]),
    );
    let (rx, tx) = uart.split();
    Board {
        rx: SerialRx(rx),
        tx: SerialTx(tx),
        flash: Flash(Nvmc::new(p.NVMC)),
    }
}

/// Stops the board for good (a debugger shows the `UDF`); `code` is for the log only.
pub fn halt(code: i32) -> ! {
    defmt::error!("halted ({})", code);
    cortex_m::asm::udf()
}
