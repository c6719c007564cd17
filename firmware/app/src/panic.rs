//! The panic handler (both boards): logs the location and any static message through defmt
//! without pulling in `core::fmt` (≈ 3 KiB of flash), then stops the board: QEMU exits with
//! status 101, the nRF52840 halts on `UDF` for the debugger. The firmware is written not to
//! panic; this is the last line of defence.

#[panic_handler]
fn panic(info: &core::panic::PanicInfo<'_>) -> ! {
    let msg = info.message().as_str().unwrap_or("(formatted message)");
    match info.location() {
        Some(l) => defmt::error!("panic at {=str}:{=u32}: {=str}", l.file(), l.line(), msg),
        None => defmt::error!("panic: {=str}", msg),
    }
    crate::board::halt(101)
}
