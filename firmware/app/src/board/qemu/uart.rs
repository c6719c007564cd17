//! Interrupt-driven driver for the CMSDK APB UART0 of the mps2-an386 (0x4000_4000, RX IRQ 0,
//! TX IRQ 1, one-byte buffers, no FIFO).
//!
//! Receive: the RX interrupt moves bytes into [`RX_BUFFER`]-byte pipe. When the pipe is full the
//! interrupt masks itself and leaves the byte in the UART, so QEMU holds further input back
//! (flow control) instead of losing it; `SerialRx::read` unmasks it once there is room.
//! The RX interrupt is cleared *before* DATA is drained, otherwise a byte arriving in between
//! leaves the interrupt deasserted forever and reception stalls.
//!
//! Transmit: a byte is written whenever the TX buffer is free; otherwise the task sleeps
//! until the TX interrupt.

use core::future::poll_fn;
use core::ptr::{read_volatile, write_volatile};
use core::task::Poll;

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::pipe::Pipe;
use embassy_sync::waitqueue::AtomicWaker;

/// Receive buffer between the RX interrupt and the link task, bytes (≈ 25 pose frames).
pub const RX_BUFFER: usize = 512;

const UART0: usize = 0x4000_4000;
const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const INTCLEAR: usize = 0x0C;
const BAUDDIV: usize = 0x10;

const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const CTRL_TX_EN: u32 = 1 << 0;
const CTRL_RX_EN: u32 = 1 << 1;
const CTRL_TX_IE: u32 = 1 << 2;
const CTRL_RX_IE: u32 = 1 << 3;
const INT_TX: u32 = 1 << 0;
const INT_RX: u32 = 1 << 1;
/// Smallest divider the CMSDK UART accepts (QEMU does not throttle to the baud rate).
const MIN_BAUDDIV: u32 = 16;

static RX_PIPE: Pipe<CriticalSectionRawMutex, RX_BUFFER> = Pipe::new();
static TX_WAKER: AtomicWaker = AtomicWaker::new();

/// The UART's interrupt lines on the mps2-an386.
#[derive(Clone, Copy)]
pub(super) enum Irq {
    /// UART0 receive.
    Uart0Rx = 0,
    /// UART0 transmit.
    Uart0Tx = 1,
}

// SAFETY: the numbers are the mps2-an386's interrupt lines for UART0 RX and TX.
unsafe impl InterruptNumber for Irq {
    fn number(self) -> u16 {
        self as u16
    }
}

fn read(reg: usize) -> u32 {
    // SAFETY: an aligned register of the UART0 block, always mapped on this board.
    unsafe { read_volatile((UART0 + reg) as *const u32) }
}

fn write(reg: usize, value: u32) {
    // SAFETY: as in `read`; writes to these registers have no memory-safety effects.
    unsafe { write_volatile((UART0 + reg) as *mut u32, value) }
}

fn modify_ctrl(set: u32, clear: u32) {
    critical_section::with(|_| write(CTRL, (read(CTRL) | set) & !clear));
}

/// Configures UART0 and unmasks its interrupts.
pub(super) fn init(nvic: &mut NVIC) -> (SerialRx, SerialTx) {
    write(BAUDDIV, MIN_BAUDDIV);
    write(INTCLEAR, INT_TX | INT_RX);
    write(CTRL, CTRL_TX_EN | CTRL_RX_EN | CTRL_RX_IE);
    // SAFETY: the handlers below are ready; no critical section depends on these masks.
    unsafe {
        nvic.set_priority(Irq::Uart0Rx, 0x40);
        nvic.set_priority(Irq::Uart0Tx, 0x40);
        NVIC::unmask(Irq::Uart0Rx);
        NVIC::unmask(Irq::Uart0Tx);
    }
    (SerialRx(()), SerialTx(()))
}

/// UART0 RX interrupt handler.
pub(super) extern "C" fn on_rx() {
    super::in_handler(|| {
        write(INTCLEAR, INT_RX);
        while read(STATE) & STATE_RX_FULL != 0 {
            if RX_PIPE.free_capacity() == 0 {
                modify_ctrl(0, CTRL_RX_IE);
                return;
            }
            let byte = read(DATA) as u8;
            let _ = RX_PIPE.try_write(&[byte]);
        }
    });
}

/// UART0 TX interrupt handler.
pub(super) extern "C" fn on_tx() {
    super::in_handler(|| {
        write(INTCLEAR, INT_TX);
        modify_ctrl(0, CTRL_TX_IE);
        TX_WAKER.wake();
    });
}

/// Receive half of UART0.
pub struct SerialRx(());

impl SerialRx {
    /// Waits for at least one received byte; returns how many were copied into `buf`.
    pub async fn read(&mut self, buf: &mut [u8]) -> usize {
        let n = RX_PIPE.read(buf).await;
        if read(CTRL) & CTRL_RX_IE == 0 {
            // The interrupt masked itself on a full pipe, leaving a byte in the UART: drain it.
            modify_ctrl(CTRL_RX_IE, 0);
            NVIC::pend(Irq::Uart0Rx);
        }
        n
    }
}

/// Transmit half of UART0.
pub struct SerialTx(());

impl SerialTx {
    /// Writes every byte of `bytes`.
    pub async fn write_all(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            poll_fn(|cx| {
                if read(STATE) & STATE_TX_FULL == 0 {
                    write(DATA, u32::from(byte));
                    return Poll::Ready(());
                }
                TX_WAKER.register(cx.waker());
                modify_ctrl(CTRL_TX_IE, 0);
                if read(STATE) & STATE_TX_FULL == 0 {
                    TX_WAKER.wake();
                }
                Poll::Pending
            })
            .await;
        }
    }
}
