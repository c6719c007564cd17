//! RAM-backed NOR flash for the emulated board, with power-cut injection.
//!
//! The STORE region of `hw/mps2-an386/memory.x` (1 MiB at 0x0030_0000) is SSRAM that is not
//! part of the ELF image, so QEMU's warm reset (SYSRESETREQ) keeps its contents like flash
//! across a power cut. The emulation is faithful to NOR: erase sets 4 KiB pages to 0xFF, a
//! write can only clear bits (a word written twice without erase ANDs), writes are whole
//! 32-bit words.
//!
//! **Fault injection** (`cut=U:K` on the semihosting command line): during the U-th upload
//! since power-on (counted by erase operations), once K bytes have been written the word in
//! progress is torn (only its low half-word programmed) and the core is reset at once, as a
//! power cut would. A marker in `.uninit` RAM (kept by the warm reset) makes it fire once.

use core::mem::MaybeUninit;
use core::ptr::{addr_of_mut, read_volatile, write_volatile};

use embedded_storage::nor_flash::{
    check_erase, check_read, check_write, ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash,
};

/// Start of the STORE region.
const BASE: usize = 0x0030_0000;
/// Size of the STORE region, bytes.
pub const STORE_SIZE: usize = 1024 * 1024;
const SIZE: usize = STORE_SIZE;
/// Erase page, bytes.
const PAGE: usize = 4096;
/// Marker value meaning "the injected power cut already happened".
const CUT_DONE: u32 = 0xC07D_0E11;

#[link_section = ".uninit.figurine_cut"]
static mut CUT_MARK: MaybeUninit<u32> = MaybeUninit::uninit();

fn cut_done() -> bool {
    // SAFETY: a plain word in .uninit RAM, only touched here and in `mark_cut_done`,
    // single core; any bit pattern is a valid u32.
    unsafe { read_volatile(addr_of_mut!(CUT_MARK).cast::<u32>()) == CUT_DONE }
}

fn mark_cut_done() {
    // SAFETY: as in `cut_done`.
    unsafe { write_volatile(addr_of_mut!(CUT_MARK).cast::<u32>(), CUT_DONE) }
}

/// Where to cut the power (see the module docs).
#[derive(Debug, Clone, Copy, defmt::Format)]
pub struct Cut {
    /// Which upload since power-on, 1-based.
    pub upload: u32,
    /// Bytes written in that upload before the cut.
    pub after_bytes: u32,
}

/// The emulated flash.
pub struct Flash {
    cut: Option<Cut>,
    erases: u32,
    written: u32,
}

impl Flash {
    /// The flash, with an optional power cut to inject (ignored if it already fired).
    pub fn new(cut: Option<Cut>) -> Self {
        Flash {
            cut: cut.filter(|_| !cut_done()),
            erases: 0,
            written: 0,
        }
    }

    /// The power cut still to come, if any.
    pub fn armed(&self) -> Option<Cut> {
        self.cut
    }

    fn word_ptr(offset: usize) -> *mut u32 {
        (BASE + offset) as *mut u32
    }

    fn program(offset: usize, value: u32) {
        let p = Self::word_ptr(offset);
        // SAFETY: `offset` was bounds- and alignment-checked against the STORE region, which
        // no Rust object occupies (it is outside the image and the RAM region).
        unsafe { write_volatile(p, read_volatile(p) & value) }
    }
}

/// The bytes `offset..offset + len` of the STORE region, in place (empty if out of bounds).
///
/// Callers pass only the active blob of a two-slot store, which is never erased or written
/// while active (uploads go to the other slot), so the shared slice never changes under them.
pub fn mapped_flash(offset: u32, len: u32) -> &'static [u8] {
    let (offset, len) = (offset as usize, len as usize);
    if offset > SIZE || len > SIZE - offset {
        return &[];
    }
    // SAFETY: in bounds of the STORE region (always mapped RAM on this board), and see above
    // for why the bytes stay unchanged while the slice is used.
    unsafe { core::slice::from_raw_parts((BASE + offset) as *const u8, len) }
}

impl ErrorType for Flash {
    type Error = NorFlashErrorKind;
}

impl ReadNorFlash for Flash {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        check_read(self, offset, bytes.len())?;
        for (i, b) in bytes.iter_mut().enumerate() {
            // SAFETY: bounds checked above; byte reads have no alignment requirement.
            *b = unsafe { read_volatile((BASE + offset as usize + i) as *const u8) };
        }
        Ok(())
    }

    fn capacity(&self) -> usize {
        SIZE
    }
}

impl NorFlash for Flash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = PAGE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        check_erase(self, from, to)?;
        self.erases = self.erases.wrapping_add(1);
        self.written = 0;
        for offset in (from as usize..to as usize).step_by(4) {
            // SAFETY: bounds and alignment checked above.
            unsafe { write_volatile(Self::word_ptr(offset), u32::MAX) }
        }
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        check_write(self, offset, bytes.len())?;
        for (k, word) in bytes.chunks_exact(4).enumerate() {
            let value = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
            let at = offset as usize + 4 * k;
            if let Some(cut) = self
                .cut
                .filter(|c| c.upload == self.erases && self.written >= c.after_bytes)
            {
                Self::program(at, value | 0xFFFF_0000);
                mark_cut_done();
                defmt::warn!(
                    "power cut injected in upload {} after {} bytes",
                    cut.upload,
                    self.written
                );
                cortex_m::peripheral::SCB::sys_reset();
            }
            Self::program(at, value);
            self.written = self.written.wrapping_add(4);
        }
        Ok(())
    }
}
