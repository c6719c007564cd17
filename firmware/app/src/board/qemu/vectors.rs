//! The device part of the vector table (cortex-m-rt's `device` feature): the mps2-an386 has
//! 32 external interrupts; UART0 RX and TX are wired, the rest go to the default handler.

use super::uart;

/// One vector-table entry.
#[derive(Clone, Copy)]
pub union Vector {
    #[allow(dead_code)] // read by the core, not by Rust code
    handler: unsafe extern "C" fn(),
}

extern "C" {
    fn DefaultHandler();
}

unsafe extern "C" fn uart0_rx() {
    uart::on_rx();
}

unsafe extern "C" fn uart0_tx() {
    uart::on_tx();
}

const DEFAULT: Vector = Vector {
    handler: DefaultHandler,
};

/// Interrupts 0..32 of the mps2-an386 (placed after the core exceptions by cortex-m-rt).
#[link_section = ".vector_table.interrupts"]
#[no_mangle]
pub static __INTERRUPTS: [Vector; 32] = {
    let mut v = [DEFAULT; 32];
    v[uart::Irq::Uart0Rx as usize] = Vector { handler: uart0_rx };
    v[uart::Irq::Uart0Tx as usize] = Vector { handler: uart0_tx };
    v
};
