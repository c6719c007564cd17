//! Host tests of the two-slot store, including 1000 random power cuts.

use std::vec;
use std::vec::Vec;

use embedded_storage::nor_flash::{ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash};

use super::*;

/// Deterministic xorshift64* generator, so every failure reproduces.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }
    fn bytes(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.next() as u8).collect()
    }
}

const PAGE: usize = 1024;
const WORD: usize = 4;

/// Simulated NOR flash: writes only clear bits, erases set whole pages to 0xFF. With a
/// budget of operations (one per word written, one per page erased) it loses power when the
/// budget runs out: the operation in progress is torn (a word half-programmed, a page
/// half-erased, with random bits) and every later operation fails until `revive`.
struct SimFlash {
    mem: Vec<u8>,
    budget: Option<u64>,
    dead: bool,
    rng: Rng,
}

impl SimFlash {
    fn new(size: usize, seed: u64) -> Self {
        let mut rng = Rng(seed | 1);
        let mem = rng.bytes(size);
        SimFlash {
            mem,
            budget: None,
            dead: false,
            rng,
        }
    }
    /// Returns true if the power fails on this operation.
    fn spend(&mut self) -> bool {
        match &mut self.budget {
            Some(0) => true,
            Some(n) => {
                *n -= 1;
                false
            }
            None => false,
        }
    }
    fn revive(&mut self) {
        self.dead = false;
        self.budget = None;
    }
}

impl ErrorType for SimFlash {
    type Error = NorFlashErrorKind;
}

impl ReadNorFlash for SimFlash {
    const READ_SIZE: usize = 1;
    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        if self.dead {
            return Err(NorFlashErrorKind::Other);
        }
        let o = offset as usize;
        let src = self
            .mem
            .get(o..o + bytes.len())
            .ok_or(NorFlashErrorKind::OutOfBounds)?;
        bytes.copy_from_slice(src);
        Ok(())
    }
    fn capacity(&self) -> usize {
        self.mem.len()
    }
}

impl NorFlash for SimFlash {
    const WRITE_SIZE: usize = WORD;
    const ERASE_SIZE: usize = PAGE;
    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        embedded_storage::nor_flash::check_erase(self, from, to)?;
        if self.dead {
            return Err(NorFlashErrorKind::Other);
        }
        for page in (from as usize..to as usize).step_by(PAGE) {
            if self.spend() {
                for i in page..page + PAGE {
                    self.mem[i] |= self.rng.next() as u8;
                }
                self.dead = true;
                return Err(NorFlashErrorKind::Other);
            }
            self.mem[page..page + PAGE].fill(0xFF);
        }
        Ok(())
    }
    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        embedded_storage::nor_flash::check_write(self, offset, bytes.len())?;
        if self.dead {
            return Err(NorFlashErrorKind::Other);
        }
        for (k, word) in bytes.chunks(WORD).enumerate() {
            let at = offset as usize + k * WORD;
            let torn = self.spend();
            for (i, &b) in word.iter().enumerate() {
                let noise = if torn { self.rng.next() as u8 } else { 0 };
                self.mem[at + i] &= b | noise;
            }
            if torn {
                self.dead = true;
                return Err(NorFlashErrorKind::Other);
            }
        }
        Ok(())
    }
}

const SLOT: u32 = 4 * PAGE as u32;
const STORE: TwoSlotStore = TwoSlotStore::new(PAGE as u32, SLOT);

/// Uploads `blob` in chunks of random sizes (1..=64 bytes).
fn upload(flash: &mut SimFlash, blob: &[u8], rng: &mut Rng) -> Result<ActiveBlob, StoreError> {
    let mut up = STORE.begin(flash, blob.len() as u32, CRC32.checksum(blob))?;
    let mut off = 0usize;
    while off < blob.len() {
        let n = (1 + rng.below(64) as usize).min(blob.len() - off);
        STORE.write(flash, &mut up, off as u32, &blob[off..off + n])?;
        off += n;
    }
    STORE.finish(flash, &mut up)?;
    STORE.commit(flash, &up)
}

fn active_bytes(flash: &mut SimFlash) -> Option<Vec<u8>> {
    let blob = STORE.active(flash)?;
    let mut buf = vec![0u8; blob.header.len as usize];
    STORE.read(flash, &blob, 0, &mut buf).ok()?;
    Some(buf)
}

fn random_blob(rng: &mut Rng) -> Vec<u8> {
    let len = rng.below(u64::from(STORE.capacity()) + 1) as usize;
    rng.bytes(len)
}

#[test]
fn fresh_flash_has_no_blob_and_uploads_alternate_slots() {
    let mut flash = SimFlash::new(16 * PAGE, 1);
    let mut rng = Rng(2);
    STORE.check(&flash).unwrap();
    assert_eq!(STORE.active(&mut flash), None);
    let mut slots = Vec::new();
    for round in 0..5 {
        let blob = random_blob(&mut rng);
        let got = upload(&mut flash, &blob, &mut rng).unwrap();
        assert_eq!(got.header.generation, round + 1);
        slots.push(got.slot);
        assert_eq!(active_bytes(&mut flash), Some(blob));
    }
    assert_eq!(slots, [0, 1, 0, 1, 0]);
}

#[test]
fn power_cut_at_1000_random_points_leaves_old_or_new_blob() {
    let mut rng = Rng(0x5EED_F16D);
    let (mut saw_old, mut saw_new) = (0, 0);
    for case in 0..1000 {
        let mut flash = SimFlash::new(16 * PAGE, rng.next());
        let mut previous = None;
        for _ in 0..rng.below(3) {
            let blob = random_blob(&mut rng);
            upload(&mut flash, &blob, &mut rng).unwrap();
            previous = Some(blob);
        }
        let new = random_blob(&mut rng);
        let erase_ops = u64::from(SLOT) / PAGE as u64;
        let data_ops = (new.len() as u64).div_ceil(WORD as u64);
        let header_ops = (HEADER_LEN / WORD) as u64;
        let total = erase_ops + data_ops + header_ops;
        let budget = rng.below(total + 2);
        flash.budget = Some(budget);
        let result = upload(&mut flash, &new, &mut rng);
        flash.revive();
        let after = active_bytes(&mut flash);
        if budget >= total {
            assert!(result.is_ok(), "case {case}: no cut, but {result:?}");
        }
        if budget < erase_ops + data_ops {
            assert!(result.is_err(), "case {case}");
            assert_eq!(after, previous, "case {case}: cut before the header");
        } else {
            assert!(
                after == previous || after.as_ref() == Some(&new),
                "case {case}: budget {budget} of {total} left a mixture"
            );
        }
        if after.as_ref() == Some(&new) && previous.as_ref() != Some(&new) {
            saw_new += 1;
        } else {
            saw_old += 1;
        }
        // The store keeps working after the cut.
        let next = random_blob(&mut rng);
        upload(&mut flash, &next, &mut rng).unwrap();
        assert_eq!(active_bytes(&mut flash), Some(next), "case {case}");
    }
    assert!(
        saw_old > 100 && saw_new > 10,
        "old {saw_old}, new {saw_new}"
    );
}

#[test]
fn wrong_crc_or_bad_chunks_never_touch_the_active_blob() {
    let mut flash = SimFlash::new(16 * PAGE, 3);
    let mut rng = Rng(4);
    let old = rng.bytes(300);
    upload(&mut flash, &old, &mut rng).unwrap();

    let new = rng.bytes(200);
    let mut up = STORE
        .begin(&mut flash, 200, CRC32.checksum(&new) ^ 1)
        .unwrap();
    assert_eq!(
        STORE.write(&mut flash, &mut up, 10, &new[..10]),
        Err(StoreError::OutOfOrder(0))
    );
    STORE.write(&mut flash, &mut up, 0, &new[..150]).unwrap();
    assert_eq!(
        STORE.finish(&mut flash, &mut up),
        Err(StoreError::Incomplete(150))
    );
    assert_eq!(
        STORE.commit(&mut flash, &up),
        Err(StoreError::Incomplete(150))
    );
    assert_eq!(
        STORE.write(&mut flash, &mut up, 150, &rng.bytes(51)),
        Err(StoreError::Overrun)
    );
    STORE.write(&mut flash, &mut up, 150, &new[150..]).unwrap();
    assert_eq!(STORE.finish(&mut flash, &mut up), Err(StoreError::Crc));
    assert_eq!(active_bytes(&mut flash), Some(old.clone()));

    assert_eq!(
        STORE.begin(&mut flash, STORE.capacity() + 1, 0).err(),
        Some(StoreError::TooLarge(STORE.capacity()))
    );
    assert_eq!(active_bytes(&mut flash), Some(old));
}

#[test]
fn geometry_is_checked() {
    let flash = SimFlash::new(8 * PAGE, 5);
    assert_eq!(TwoSlotStore::new(0, 4 * PAGE as u32).check(&flash), Ok(()));
    assert_eq!(
        TwoSlotStore::new(0, 5 * PAGE as u32).check(&flash),
        Err(StoreError::Geometry)
    );
    assert_eq!(
        TwoSlotStore::new(100, 2 * PAGE as u32).check(&flash),
        Err(StoreError::Geometry)
    );
}

#[test]
fn reads_past_the_blob_are_refused() {
    let mut flash = SimFlash::new(16 * PAGE, 6);
    let mut rng = Rng(7);
    let blob = upload(&mut flash, &[1, 2, 3], &mut rng).unwrap();
    let mut buf = [0u8; 4];
    assert_eq!(
        STORE.read(&mut flash, &blob, 0, &mut buf),
        Err(StoreError::Overrun)
    );
    assert_eq!(STORE.read(&mut flash, &blob, 1, &mut buf[..2]), Ok(()));
    assert_eq!(&buf[..2], &[2, 3]);
}
