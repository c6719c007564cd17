//! The two-slot store: where a blob's bytes live and how an upload replaces them safely.

use embedded_storage::nor_flash::NorFlash;

use crate::error::StoreError;
use crate::header::{SlotHeader, HEADER_LEN};
use crate::CRC32;

/// Largest flash write granule supported, bytes (nRF52840 NVMC: 4).
const MAX_WRITE_SIZE: usize = 16;
/// Bytes read per flash access while checking a CRC.
const READ_CHUNK: usize = 64;

/// One kind of blob kept in two slots of `slot_size` bytes each, starting at flash offset
/// `base`. The store holds no flash handle: the caller passes it in, so several stores can
/// share one flash.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TwoSlotStore {
    base: u32,
    slot_size: u32,
}

/// A blob whose header and bytes passed their CRCs (or an upload verified but not yet
/// committed, see [`TwoSlotStore::finish`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ActiveBlob {
    /// Which slot (0 or 1) holds it.
    pub slot: u8,
    /// Its header (length, CRC-32, generation).
    pub header: SlotHeader,
}

/// An upload in progress into the spare slot: created by [`TwoSlotStore::begin`].
#[derive(Debug, Clone)]
pub struct Upload {
    slot: u8,
    header: SlotHeader,
    /// Blob bytes received so far (staged or written).
    received: u32,
    /// Bytes waiting for a whole write granule.
    stage: [u8; MAX_WRITE_SIZE],
    staged: usize,
    finished: bool,
}

impl Upload {
    /// Bytes received so far; the next chunk must start here.
    pub fn received(&self) -> u32 {
        self.received
    }

    /// The header the upload will commit.
    pub fn header(&self) -> SlotHeader {
        self.header
    }
}

fn flash_err<E>(_: E) -> StoreError {
    StoreError::Flash
}

impl TwoSlotStore {
    /// A store whose two slots of `slot_size` bytes start at flash offset `base`. Both must
    /// be multiples of the flash's erase page; [`TwoSlotStore::check`] verifies that.
    pub const fn new(base: u32, slot_size: u32) -> Self {
        TwoSlotStore { base, slot_size }
    }

    /// Checks the geometry against a flash: pages, capacity, write and read granules.
    pub fn check<F: NorFlash>(&self, flash: &F) -> Result<(), StoreError> {
        let page = F::ERASE_SIZE as u64;
        let end = u64::from(self.base) + 2 * u64::from(self.slot_size);
        let ok = page > 0
            && u64::from(self.base).is_multiple_of(page)
            && u64::from(self.slot_size).is_multiple_of(page)
            && self.slot_size as usize > HEADER_LEN
            && end <= flash.capacity() as u64
            && F::WRITE_SIZE <= MAX_WRITE_SIZE
            && HEADER_LEN.is_multiple_of(F::WRITE_SIZE)
            && F::READ_SIZE == 1;
        if ok {
            Ok(())
        } else {
            Err(StoreError::Geometry)
        }
    }

    /// Largest blob a slot holds, bytes.
    pub const fn capacity(&self) -> u32 {
        self.slot_size - HEADER_LEN as u32
    }

    /// Flash offset of `blob`'s first byte, for boards whose flash is memory-mapped and read
    /// in place. Those bytes never change while `blob` is the active one: uploads erase and
    /// write only the other slot.
    pub fn blob_offset(&self, blob: &ActiveBlob) -> u32 {
        self.slot_addr(blob.slot) + HEADER_LEN as u32
    }

    fn slot_addr(&self, slot: u8) -> u32 {
        self.base + u32::from(slot) * self.slot_size
    }

    fn read_header<F: NorFlash>(&self, flash: &mut F, slot: u8) -> Option<SlotHeader> {
        let mut bytes = [0u8; HEADER_LEN];
        flash.read(self.slot_addr(slot), &mut bytes).ok()?;
        SlotHeader::from_bytes(&bytes)
    }

    /// CRC-32 of `len` bytes of `slot`'s blob area, read back from flash.
    fn crc_of<F: NorFlash>(&self, flash: &mut F, slot: u8, len: u32) -> Result<u32, StoreError> {
        let mut digest = CRC32.digest();
        let mut buf = [0u8; READ_CHUNK];
        let start = self.slot_addr(slot) + HEADER_LEN as u32;
        let mut done = 0u32;
        while done < len {
            let n = (len - done).min(READ_CHUNK as u32) as usize;
            let part = buf.get_mut(..n).ok_or(StoreError::Flash)?;
            flash.read(start + done, part).map_err(flash_err)?;
            digest.update(part);
            done += n as u32;
        }
        Ok(digest.finalize())
    }

    fn valid<F: NorFlash>(&self, flash: &mut F, slot: u8) -> Option<ActiveBlob> {
        let header = self.read_header(flash, slot)?;
        if header.len > self.capacity()
            || self.crc_of(flash, slot, header.len).ok()? != header.crc32
        {
            return None;
        }
        Some(ActiveBlob { slot, header })
    }

    /// The blob in use: the newest slot whose header and bytes pass their CRCs, if any.
    pub fn active<F: NorFlash>(&self, flash: &mut F) -> Option<ActiveBlob> {
        match (self.valid(flash, 0), self.valid(flash, 1)) {
            (Some(a), Some(b)) => Some(if b.header.newer_than(&a.header) { b } else { a }),
            (a, b) => a.or(b),
        }
    }

    /// Reads `buf.len()` bytes of `blob` starting at byte `offset` of the blob.
    pub fn read<F: NorFlash>(
        &self,
        flash: &mut F,
        blob: &ActiveBlob,
        offset: u32,
        buf: &mut [u8],
    ) -> Result<(), StoreError> {
        let end = u64::from(offset) + buf.len() as u64;
        if end > u64::from(blob.header.len) {
            return Err(StoreError::Overrun);
        }
        let addr = self.slot_addr(blob.slot) + HEADER_LEN as u32 + offset;
        flash.read(addr, buf).map_err(flash_err)
    }

    /// Starts replacing the blob: erases the spare slot (never the active one) for a blob of
    /// `len` bytes whose CRC-32 is `crc32`.
    pub fn begin<F: NorFlash>(
        &self,
        flash: &mut F,
        len: u32,
        crc32: u32,
    ) -> Result<Upload, StoreError> {
        if len > self.capacity() {
            return Err(StoreError::TooLarge(self.capacity()));
        }
        let active = self.active(flash);
        let (slot, generation) = match active {
            Some(a) => (1 - a.slot.min(1), a.header.generation.wrapping_add(1)),
            None => (0, 1),
        };
        let addr = self.slot_addr(slot);
        flash
            .erase(addr, addr + self.slot_size)
            .map_err(flash_err)?;
        Ok(Upload {
            slot,
            header: SlotHeader {
                generation,
                len,
                crc32,
            },
            received: 0,
            stage: [0xFF; MAX_WRITE_SIZE],
            staged: 0,
            finished: false,
        })
    }

    /// Appends `data`, which must start at blob byte `offset` = [`Upload::received`].
    pub fn write<F: NorFlash>(
        &self,
        flash: &mut F,
        up: &mut Upload,
        offset: u32,
        data: &[u8],
    ) -> Result<(), StoreError> {
        if offset != up.received || up.finished {
            return Err(StoreError::OutOfOrder(up.received));
        }
        if u64::from(up.received) + data.len() as u64 > u64::from(up.header.len) {
            return Err(StoreError::Overrun);
        }
        let blob_start = self.slot_addr(up.slot) + HEADER_LEN as u32;
        for &byte in data {
            let slot = up.stage.get_mut(up.staged).ok_or(StoreError::Geometry)?;
            *slot = byte;
            up.staged += 1;
            up.received += 1;
            if up.staged == F::WRITE_SIZE {
                self.flush_stage(flash, up, blob_start)?;
            }
        }
        Ok(())
    }

    fn flush_stage<F: NorFlash>(
        &self,
        flash: &mut F,
        up: &mut Upload,
        blob_start: u32,
    ) -> Result<(), StoreError> {
        if up.staged == 0 {
            return Ok(());
        }
        // The staged bytes end at `received`; the granule starts `staged` bytes before.
        let at = blob_start + up.received - up.staged as u32;
        let granule = up.stage.get(..F::WRITE_SIZE).ok_or(StoreError::Geometry)?;
        let result = flash.write(at, granule).map_err(flash_err);
        up.stage = [0xFF; MAX_WRITE_SIZE];
        up.staged = 0;
        result
    }

    /// Writes any partial granule and checks the flash contents against the announced
    /// length and CRC-32. The blob is readable through the returned [`ActiveBlob`] (to
    /// validate it) but not yet active: [`TwoSlotStore::commit`] makes it so.
    pub fn finish<F: NorFlash>(
        &self,
        flash: &mut F,
        up: &mut Upload,
    ) -> Result<ActiveBlob, StoreError> {
        if up.received != up.header.len {
            return Err(StoreError::Incomplete(up.received));
        }
        let blob_start = self.slot_addr(up.slot) + HEADER_LEN as u32;
        self.flush_stage(flash, up, blob_start)?;
        if self.crc_of(flash, up.slot, up.header.len)? != up.header.crc32 {
            return Err(StoreError::Crc);
        }
        up.finished = true;
        Ok(ActiveBlob {
            slot: up.slot,
            header: up.header,
        })
    }

    /// Writes the header, the commit record: from here on the new blob is the active one.
    pub fn commit<F: NorFlash>(
        &self,
        flash: &mut F,
        up: &Upload,
    ) -> Result<ActiveBlob, StoreError> {
        if !up.finished {
            return Err(StoreError::Incomplete(up.received));
        }
        flash
            .write(self.slot_addr(up.slot), &up.header.to_bytes())
            .map_err(flash_err)?;
        match self.valid(flash, up.slot) {
            Some(blob) if blob.header == up.header => Ok(blob),
            _ => Err(StoreError::Crc),
        }
    }
}

#[cfg(test)]
mod tests;
