//! Flash and static RAM of a firmware ELF, read from its section headers (what
//! `llvm-size -A` shows, summed the way a linker map would).

use std::path::{Path, PathBuf};
use std::time::SystemTime;

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

/// The firmware's source folders, relative to the workspace root: what an image is built from.
pub const FIRMWARE_SOURCES: [&str; 5] = [
    "firmware/recognizer/src",
    "firmware/app/src",
    "firmware/fpu/src",
    "firmware/store/src",
    "protocol/src",
];

/// A firmware source file (under [`FIRMWARE_SOURCES`] of workspace `root`) changed after the
/// image `elf` was built, if any: the image's figures are then not the sources' (the benches
/// read whatever image the last `cargo xtask firmware` left). None when the image or every
/// source is older, or a time cannot be read.
pub fn newer_source(root: &Path, elf: &Path) -> Option<PathBuf> {
    let built = modified(elf)?;
    let mut stack: Vec<PathBuf> = FIRMWARE_SOURCES.iter().map(|d| root.join(d)).collect();
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else if modified(&path).is_some_and(|t| t > built) {
                return Some(path);
            }
        }
    }
    None
}

fn modified(path: &Path) -> Option<SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
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

    #[test]
    fn a_source_changed_after_the_image_is_named() {
        use std::time::Duration;
        let root = std::env::temp_dir().join(format!("fig-stale-{}", std::process::id()));
        let src = root.join("firmware/recognizer/src/deep");
        std::fs::create_dir_all(&src).unwrap();
        let (elf, rs) = (root.join("image.elf"), src.join("follow.rs"));
        let at = |path: &Path, secs: u64| {
            let f = std::fs::File::create(path).unwrap();
            f.set_modified(SystemTime::UNIX_EPOCH + Duration::from_secs(secs))
                .unwrap();
        };
        at(&rs, 1_000);
        at(&elf, 2_000);
        assert_eq!(newer_source(&root, &elf), None);
        at(&rs, 3_000);
        assert_eq!(newer_source(&root, &elf), Some(rs));
        // No image: nothing to call stale.
        assert_eq!(newer_source(&root, &root.join("missing.elf")), None);
        std::fs::remove_dir_all(&root).unwrap();
    }
}
