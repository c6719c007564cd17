//! Flash and static RAM of a firmware ELF, read from its section headers (what
//! `llvm-size -A` shows, summed the way a linker map would).

use std::path::Path;

use anyhow::{bail, Context, Result};

/// Memory a firmware image takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageSize {
    /// Bytes stored in flash: code, read-only data, vector table, `.data` initialisers.
    pub flash: u64,
    /// Bytes of RAM reserved statically: `.data`, `.bss`, `.uninit` (the stack comes on top).
    pub static_ram: u64,
}

const SHF_WRITE: u32 = 0x1;
const SHF_ALLOC: u32 = 0x2;
const SHT_NOBITS: u32 = 8;

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(at..at + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

/// Sizes of a 32-bit little-endian ELF (all Cortex-M images are).
pub fn image_size(path: &Path) -> Result<ImageSize> {
    let b = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    if b.get(..6) != Some(&[0x7F, b'E', b'L', b'F', 1, 1][..]) {
        bail!("{} is not a 32-bit little-endian ELF", path.display());
    }
    let parse = || -> Option<ImageSize> {
        let shoff = u32_at(&b, 0x20)? as usize;
        let shentsize = usize::from(u16_at(&b, 0x2E)?);
        let shnum = usize::from(u16_at(&b, 0x30)?);
        let mut size = ImageSize {
            flash: 0,
            static_ram: 0,
        };
        for i in 0..shnum {
            let h = shoff + i * shentsize;
            let (kind, flags, bytes) =
                (u32_at(&b, h + 4)?, u32_at(&b, h + 8)?, u32_at(&b, h + 20)?);
            if flags & SHF_ALLOC == 0 {
                continue;
            }
            if kind != SHT_NOBITS {
                size.flash += u64::from(bytes);
            }
            if flags & SHF_WRITE != 0 {
                size.static_ram += u64::from(bytes);
            }
        }
        Some(size)
    };
    parse().with_context(|| format!("{}: truncated section headers", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_what_is_not_an_elf() {
        let dir = std::env::temp_dir().join(format!("fig-elf-{}", std::process::id()));
        std::fs::write(&dir, b"hello").unwrap();
        assert!(image_size(&dir).is_err());
        std::fs::remove_file(&dir).unwrap();
    }
}
