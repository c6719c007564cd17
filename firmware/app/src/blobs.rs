//! The uploaded blobs (action library, effort model): persisted in the board's flash through
//! the power-fail-safe [`TwoSlotStore`], validated by the recognizer before they become
//! active, loaded at boot.
//!
//! The library is read in place from memory-mapped flash (its patterns never take RAM); the
//! effort model is parsed into RAM.

use figurine_protocol::{BlobKind, DeviceError, ErrorCode, UploadBegin, UploadChunk};
use figurine_recognizer::pattern::MAX_LIBRARY_BYTES;
use figurine_recognizer::{bayes::MAX_EFFORT_BYTES, EffortModel, Library};
use figurine_store::{ActiveBlob, StoreError, TwoSlotStore, Upload};

use crate::board::{self, Flash};

fn err(code: ErrorCode, detail: u32) -> DeviceError {
    DeviceError { code, detail }
}

fn store_of(kind: BlobKind) -> &'static TwoSlotStore {
    match kind {
        BlobKind::Library => &board::LIBRARY_STORE,
        BlobKind::Effort => &board::EFFORT_STORE,
    }
}

/// Largest blob of `kind` the device takes, bytes: the smaller of the recognizer's format
/// limit and the flash slot.
pub fn capacity(kind: BlobKind) -> u32 {
    let format = match kind {
        BlobKind::Library => MAX_LIBRARY_BYTES,
        BlobKind::Effort => MAX_EFFORT_BYTES,
    } as u32;
    format.min(store_of(kind).capacity())
}

/// A numeric reason for `ErrorCode::BlobInvalid`, from the recognizer's error.
fn reason(e: figurine_recognizer::Error) -> u32 {
    use figurine_recognizer::Error as E;
    match e {
        E::Truncated => 1,
        E::TooLarge => 2,
        E::BadMagic => 3,
        E::Version(v) => 0x100 | u32::from(v),
        E::Capacity => 5,
        E::Invalid(_) => 6,
    }
}

/// Persisted blobs and the upload in progress.
pub struct Blobs {
    flash: Flash,
    upload: Option<(BlobKind, Upload)>,
    library: Option<ActiveBlob>,
    effort: Option<ActiveBlob>,
}

impl Blobs {
    /// Finds the active blobs in flash (each must pass its CRCs and the recognizer's checks).
    pub fn boot(mut flash: Flash) -> Self {
        let mut active = |kind: BlobKind| {
            let store = store_of(kind);
            if let Err(e) = store.check(&flash) {
                defmt::error!("{} store geometry: {}", kind, e);
                return None;
            }
            let blob = store.active(&mut flash)?;
            match validate(kind, &mut flash, &blob) {
                Ok(()) => {
                    defmt::info!(
                        "{} loaded: {} bytes, crc {=u32:08x}, generation {}",
                        kind,
                        blob.header.len,
                        blob.header.crc32,
                        blob.header.generation
                    );
                    Some(blob)
                }
                Err(e) => {
                    defmt::warn!("{} in flash refused: {}", kind, e);
                    None
                }
            }
        };
        let library = active(BlobKind::Library);
        let effort = active(BlobKind::Effort);
        Blobs {
            flash,
            upload: None,
            library,
            effort,
        }
    }

    /// The active action library, read in place from flash (empty if none is loaded).
    pub fn library(&self) -> Library<'static> {
        self.library
            .and_then(|b| Library::from_bytes(mapped(BlobKind::Library, &b)).ok())
            .unwrap_or(Library::empty())
    }

    /// True if an action library is loaded.
    pub fn has_library(&self) -> bool {
        self.library.is_some()
    }

    /// The active effort model, or `None` for the recognizer's built-in default.
    pub fn effort(&self) -> Option<EffortModel> {
        self.effort
            .and_then(|b| EffortModel::from_bytes(mapped(BlobKind::Effort, &b)).ok())
    }

    /// CRC-32 of the active blob of `kind`, 0 if none.
    pub fn crc(&self, kind: BlobKind) -> u32 {
        match kind {
            BlobKind::Library => self.library,
            BlobKind::Effort => self.effort,
        }
        .map_or(0, |b| b.header.crc32)
    }

    /// `UploadBegin`: erases the spare slot. Any earlier unfinished upload is abandoned.
    pub fn begin(&mut self, b: &UploadBegin) -> Result<(), DeviceError> {
        self.upload = None;
        let cap = capacity(b.kind);
        if b.len > cap {
            return Err(err(ErrorCode::UploadTooLarge, cap));
        }
        let up = store_of(b.kind)
            .begin(&mut self.flash, b.len, b.crc32)
            .map_err(store_err)?;
        self.upload = Some((b.kind, up));
        Ok(())
    }

    /// `UploadChunk`: writes the chunk; returns the bytes received so far.
    pub fn chunk(&mut self, c: &UploadChunk) -> Result<u32, DeviceError> {
        let Some((kind, up)) = self.upload.as_mut().filter(|(k, _)| *k == c.kind) else {
            return Err(err(ErrorCode::UploadNotStarted, 0));
        };
        let store = store_of(*kind);
        match store.write(&mut self.flash, up, c.offset, &c.data) {
            Ok(()) => Ok(up.received()),
            Err(StoreError::OutOfOrder(next)) => Err(err(ErrorCode::UploadOutOfOrder, next)),
            Err(StoreError::Overrun) => Err(err(ErrorCode::UploadTooLarge, up.header().len)),
            Err(e) => {
                self.upload = None;
                Err(store_err(e))
            }
        }
    }

    /// `UploadCommit`: checks CRC and content, then writes the slot header (the commit
    /// record). On any failure the previous blob stays active. Returns the new blob's CRC-32.
    pub fn commit(&mut self, kind: BlobKind) -> Result<u32, DeviceError> {
        let Some((k, mut up)) = self.upload.take().filter(|(k, _)| *k == kind) else {
            return Err(err(ErrorCode::UploadNotStarted, 0));
        };
        let store = store_of(k);
        let staged = match store.finish(&mut self.flash, &mut up) {
            Ok(b) => b,
            Err(StoreError::Crc) => return Err(err(ErrorCode::UploadCrc, 0)),
            Err(StoreError::Incomplete(got)) => return Err(err(ErrorCode::UploadOutOfOrder, got)),
            Err(e) => return Err(store_err(e)),
        };
        validate(k, &mut self.flash, &staged)
            .map_err(|e| err(ErrorCode::BlobInvalid, reason(e)))?;
        let blob = store.commit(&mut self.flash, &up).map_err(store_err)?;
        match k {
            BlobKind::Library => self.library = Some(blob),
            BlobKind::Effort => self.effort = Some(blob),
        }
        Ok(blob.header.crc32)
    }
}

fn store_err(e: StoreError) -> DeviceError {
    defmt::warn!("store: {}", e);
    match e {
        StoreError::TooLarge(cap) => err(ErrorCode::UploadTooLarge, cap),
        StoreError::OutOfOrder(next) => err(ErrorCode::UploadOutOfOrder, next),
        StoreError::Crc => err(ErrorCode::UploadCrc, 0),
        _ => err(ErrorCode::FlashWrite, 0),
    }
}

/// The bytes of `blob`, in place in memory-mapped flash.
fn mapped(kind: BlobKind, blob: &ActiveBlob) -> &'static [u8] {
    board::mapped_flash(store_of(kind).blob_offset(blob), blob.header.len)
}

fn validate(
    kind: BlobKind,
    _flash: &mut Flash,
    blob: &ActiveBlob,
) -> Result<(), figurine_recognizer::Error> {
    let bytes = mapped(kind, blob);
    match kind {
        BlobKind::Library => Library::from_bytes(bytes).map(|_| ()),
        BlobKind::Effort => EffortModel::from_bytes(bytes).map(|_| ()),
    }
}
