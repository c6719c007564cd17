//! What the host uploads: the compiled library blob with its action names, and the effort
//! model blob — the same bytes `figurine simulate` runs in-process (default library and
//! default effort model when none is given), so the device and simulation agree.

use std::path::Path;

use anyhow::Result;

use crate::recognize::effort_model::EffortFile;
use crate::recognize::simulate::load_library;

/// A library and an effort model in their device form.
#[derive(Debug, Clone)]
pub struct Blobs {
    /// Action names, in device order (event `action` indexes this).
    pub names: Vec<String>,
    /// The compiled library blob.
    pub library: Vec<u8>,
    /// The effort model blob.
    pub effort: Vec<u8>,
}

/// Loads LIB.json and EFFORT.json (or the shipped defaults) and builds their blobs.
pub fn load(library: Option<&Path>, effort: Option<&Path>) -> Result<Blobs> {
    let (lib, library) = load_library(library)?;
    let effort = match effort {
        Some(p) => EffortFile::read(p)?,
        None => EffortFile::default_model()?,
    }
    .blob()?;
    Ok(Blobs {
        names: lib.names(),
        library,
        effort,
    })
}

/// CRC-32 of a blob as the device reports it in `Hello` and `UploadDone`.
pub fn crc32(blob: &[u8]) -> u32 {
    figurine_protocol::frame::CRC32.checksum(blob)
}
