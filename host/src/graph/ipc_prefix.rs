//! Reading only the leading columns of an Arrow IPC file's record batches.
//!
//! arrow-ipc's `FileReader` reads a record batch's whole body from the file and then decodes
//! the projected columns, so a tile of a graph job read all 664 bytes per frame of the feature
//! store to use the 208 bytes of its first five columns (the LMA column, last, is the rest).
//! An IPC body holds its buffers in column order (a depth-first walk of the fields), so the
//! leading columns are a prefix of it: [`LeadingColumns`] reads a batch's message, finds where
//! the buffers of the leading columns end, and reads the body only up to there, then decodes
//! through arrow-ipc's own `FileDecoder`.
//!
//! Where a batch does not look as expected (compressed, another buffer count), the batch is
//! read whole, so this never reads less than the columns need.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use arrow_array::RecordBatch;
use arrow_buffer::Buffer;
use arrow_ipc::reader::{read_footer_length, FileDecoder};
use arrow_ipc::Block;

use super::GraphError;

/// Bytes of the footer's length and the closing magic at the end of an IPC file.
const TRAILER: u64 = 10;
/// Bytes before a message's flatbuffer: continuation marker and length.
const MESSAGE_PREFIX: usize = 8;

/// An open IPC file read for its first `columns` columns.
pub struct LeadingColumns {
    path: PathBuf,
    file: File,
    decoder: FileDecoder,
    blocks: Vec<Block>,
    /// IPC buffers of the leading columns, and of all columns, per record batch.
    leading_buffers: usize,
    all_buffers: usize,
    /// Bytes of record batches read so far (messages and body prefixes).
    read: u64,
}

/// An error about feature store `path`.
pub(super) fn err(path: &Path, what: impl std::fmt::Display) -> GraphError {
    GraphError::format(path, format!("feature store: {what}"))
}

/// `len` bytes of `file` (at `path`) from byte `at`.
pub(super) fn read_at(
    file: &mut File,
    path: &Path,
    at: u64,
    len: usize,
) -> Result<Vec<u8>, GraphError> {
    // Lengths come from the file itself: a damaged one must not make us allocate gigabytes.
    let size = file.metadata().map_err(|e| err(path, e))?.len();
    if at.checked_add(len as u64).is_none_or(|end| end > size) {
        return Err(err(
            path,
            format!("{len} bytes at {at} lie past the end of the file ({size} bytes): cut short?"),
        ));
    }
    let mut buf = vec![0u8; len];
    file.seek(SeekFrom::Start(at))
        .and_then(|_| file.read_exact(&mut buf))
        .map_err(|e| err(path, format!("reading {len} bytes at {at}: {e}")))?;
    Ok(buf)
}

/// What an IPC file's footer holds: its schema, format version and record batch blocks.
pub(super) struct Footer {
    /// The file, open for reading.
    pub file: File,
    pub schema: arrow_schema::Schema,
    pub version: arrow_ipc::MetadataVersion,
    /// Where each record batch lies: message offset, message length, body length (bytes).
    pub blocks: Vec<Block>,
    /// Whether the file says its buffers are little-endian.
    pub little_endian: bool,
}

/// Opens `path` and reads its footer (the last bytes of the file only).
pub(super) fn read_footer(path: &Path) -> Result<Footer, GraphError> {
    let mut file = File::open(path).map_err(|source| GraphError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let len = file.metadata().map_err(|e| err(path, e))?.len();
    if len < TRAILER {
        return Err(err(path, "shorter than an Arrow IPC trailer"));
    }
    let mut trailer = [0u8; TRAILER as usize];
    trailer.copy_from_slice(&read_at(&mut file, path, len - TRAILER, TRAILER as usize)?);
    let footer_len = read_footer_length(trailer).map_err(|e| err(path, e))? as u64;
    let start = len
        .checked_sub(TRAILER + footer_len)
        .ok_or_else(|| err(path, "footer longer than the file"))?;
    let bytes = read_at(&mut file, path, start, footer_len as usize)?;
    let footer = arrow_ipc::root_as_footer(&bytes).map_err(|e| err(path, e))?;
    let fb_schema = footer
        .schema()
        .ok_or_else(|| err(path, "no schema in the footer"))?;
    let little_endian = fb_schema.endianness() == arrow_ipc::Endianness::Little;
    let schema = arrow_ipc::convert::try_fb_to_schema(fb_schema).map_err(|e| err(path, e))?;
    let blocks = footer
        .recordBatches()
        .map(|b| b.iter().copied().collect())
        .unwrap_or_default();
    Ok(Footer {
        file,
        schema,
        version: footer.version(),
        blocks,
        little_endian,
    })
}

/// The message of record batch `k` at `block` (read from `file`, at `path`) as raw bytes with
/// its 8-byte prefix, where its body starts and the body's length, bytes.
pub(super) fn read_message(
    file: &mut File,
    path: &Path,
    block: &Block,
    k: usize,
) -> Result<(Vec<u8>, u64, u64), GraphError> {
    let (offset, meta_len, body_len) = match (
        u64::try_from(block.offset()),
        usize::try_from(block.metaDataLength()),
        u64::try_from(block.bodyLength()),
    ) {
        (Ok(o), Ok(m), Ok(b)) => (o, m, b),
        _ => return Err(err(path, format!("record batch {k}: bad block"))),
    };
    let bytes = read_at(file, path, offset, meta_len)?;
    let size = file.metadata().map_err(|e| err(path, e))?.len();
    let body_at = offset
        .checked_add(meta_len as u64)
        .filter(|at| at.checked_add(body_len).is_some_and(|end| end <= size))
        .ok_or_else(|| {
            err(
                path,
                format!(
                    "record batch {k} lies past the end of the file ({size} bytes): cut short?"
                ),
            )
        })?;
    Ok((bytes, body_at, body_len))
}

/// The record batch header inside message bytes `meta` (with their 8-byte prefix).
pub(super) fn record_batch<'a>(
    meta: &'a [u8],
    path: &Path,
) -> Result<arrow_ipc::RecordBatch<'a>, GraphError> {
    let flat = meta
        .get(MESSAGE_PREFIX..)
        .ok_or_else(|| err(path, "record batch message cut short"))?;
    let message = arrow_ipc::root_as_message(flat).map_err(|e| err(path, e))?;
    message
        .header_as_record_batch()
        .ok_or_else(|| err(path, "a record batch block holds another message"))
}

impl LeadingColumns {
    /// Opens `path` to read columns `0..columns`, whose fields take `leading_buffers` of the
    /// `all_buffers` IPC buffers of a record batch (the caller has checked the schema).
    pub fn open(
        path: &Path,
        columns: usize,
        leading_buffers: usize,
        all_buffers: usize,
    ) -> Result<LeadingColumns, GraphError> {
        let f = read_footer(path)?;
        let decoder =
            FileDecoder::new(Arc::new(f.schema), f.version).with_projection((0..columns).collect());
        Ok(LeadingColumns {
            path: path.to_path_buf(),
            file: f.file,
            decoder,
            blocks: f.blocks,
            leading_buffers,
            all_buffers,
            read: 0,
        })
    }

    /// Record batches in the file.
    pub fn batches(&self) -> usize {
        self.blocks.len()
    }

    /// Bytes of record batches read so far, messages and body prefixes.
    pub fn bytes_read(&self) -> u64 {
        self.read
    }

    /// Bytes of record batch `k`'s body that hold the leading columns, or the whole body when
    /// the message is not laid out as expected.
    fn body_prefix(&self, meta: &[u8], body_len: u64) -> Result<u64, GraphError> {
        let batch = record_batch(meta, &self.path)?;
        let buffers = batch.buffers().map(|b| b.iter().collect::<Vec<_>>());
        // Every buffer the message names must lie inside its body: the IPC decoder slices
        // them unchecked, and a corrupt offset would panic there.
        let stop = |buf: &arrow_ipc::Buffer| {
            u64::try_from(buf.offset())
                .ok()
                .zip(u64::try_from(buf.length()).ok())
                .and_then(|(o, l)| o.checked_add(l))
                .filter(|&s| s <= body_len)
                .ok_or_else(|| err(&self.path, "a column buffer lies outside its batch"))
        };
        for buf in buffers.iter().flatten() {
            stop(buf)?;
        }
        // Nor may a column be longer than its body could hold, a bit a value at the least
        // (a validity bitmap): arrow-data multiplies a fixed-size list's length by its width
        // unchecked against overflow and panics (arrow-data 60.1, `validate_child_data`).
        let most = body_len.saturating_mul(8);
        let fits = |n: i64| u64::try_from(n).is_ok_and(|n| n <= most);
        let mut nodes = batch.nodes().into_iter().flat_map(|n| n.iter());
        if !fits(batch.length()) || !nodes.all(|n| fits(n.length())) {
            return Err(err(
                &self.path,
                "a column is longer than its batch's body could hold",
            ));
        }
        match buffers {
            Some(b) if batch.compression().is_none() && b.len() == self.all_buffers => {
                let mut end = 0u64;
                for buf in &b[..self.leading_buffers] {
                    end = end.max(stop(buf)?);
                }
                Ok(end)
            }
            _ => Ok(body_len),
        }
    }

    /// Record batch `k`, leading columns only.
    pub fn batch(&mut self, k: usize) -> Result<RecordBatch, GraphError> {
        let block = *self
            .blocks
            .get(k)
            .ok_or_else(|| err(&self.path, format!("record batch {k} missing")))?;
        let (mut bytes, body_at, body_len) = read_message(&mut self.file, &self.path, &block, k)?;
        let prefix = self.body_prefix(&bytes, body_len)?;
        // Read into the message's own vector: one allocation for the batch, no copy.
        let at = bytes.len();
        bytes.resize(at + prefix as usize, 0);
        self.file
            .seek(SeekFrom::Start(body_at))
            .and_then(|_| self.file.read_exact(&mut bytes[at..]))
            .map_err(|e| {
                err(
                    &self.path,
                    format!("record batch {k}: reading its body: {e}"),
                )
            })?;
        self.read += bytes.len() as u64;
        self.decoder
            .read_record_batch(&block, &Buffer::from(bytes))
            .map_err(|e| err(&self.path, format!("record batch {k}: {e}")))?
            .ok_or_else(|| err(&self.path, format!("record batch {k} missing")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use arrow_array::{Array, Float32Array, UInt32Array};
    use arrow_ipc::writer::FileWriter;
    use arrow_schema::{DataType, Field, Schema};

    /// A two-column file (u32 `a`, f32 `b`, 2 buffers each) in 3 batches of 100 rows.
    fn file(name: &str) -> (PathBuf, Vec<RecordBatch>) {
        let dir = std::env::temp_dir().join(format!("figurine-ipc-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.arrow");
        let schema = Arc::new(Schema::new(vec![
            Field::new("a", DataType::UInt32, false),
            Field::new("b", DataType::Float32, false),
        ]));
        let mut w = FileWriter::try_new(File::create(&path).unwrap(), &schema).unwrap();
        let mut batches = Vec::new();
        for k in 0..3u32 {
            let a = UInt32Array::from_iter_values((0..100).map(|i| k * 100 + i));
            let b = Float32Array::from_iter_values((0..100).map(|i| (k * 100 + i) as f32 * 0.5));
            let batch =
                RecordBatch::try_new(schema.clone(), vec![Arc::new(a), Arc::new(b)]).unwrap();
            w.write(&batch).unwrap();
            batches.push(batch);
        }
        w.finish().unwrap();
        (path, batches)
    }

    #[test]
    fn leading_columns_equal_the_full_read_and_skip_the_rest() {
        let (path, batches) = file("lead");
        let mut r = LeadingColumns::open(&path, 1, 2, 4).unwrap();
        assert_eq!(r.batches(), 3);
        for (k, full) in batches.iter().enumerate() {
            let b = r.batch(k).unwrap();
            assert_eq!(b.num_columns(), 1);
            assert_eq!(b.column(0).to_data(), full.column(0).to_data());
        }
        // Told that all four buffers lead, it reads whole bodies: the `b` column's 3 × 400
        // bytes of values more.
        let mut whole = LeadingColumns::open(&path, 1, 4, 4).unwrap();
        for k in 0..3 {
            assert_eq!(whole.batch(k).unwrap().column(0).len(), 100);
        }
        assert!(
            whole.bytes_read() >= r.bytes_read() + 1200,
            "{} against {}",
            whole.bytes_read(),
            r.bytes_read()
        );
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }

    #[test]
    fn truncated_files_and_missing_batches_are_errors_naming_the_file() {
        let (path, _) = file("cut");
        let bytes = std::fs::read(&path).unwrap();
        let e = LeadingColumns::open(&path, 1, 2, 4)
            .unwrap()
            .batch(3)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("t.arrow"), "{e}");
        for cut in [0, 5, 9, bytes.len() / 2, bytes.len() - 1] {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            let e = LeadingColumns::open(&path, 1, 2, 4)
                .and_then(|mut r| r.batch(0).map(|_| ()))
                .err()
                .unwrap_or_else(|| panic!("cut {cut} accepted"))
                .to_string();
            assert!(e.contains("t.arrow"), "cut {cut}: {e}");
        }
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }
}
