//! Reading only an Arrow IPC file's last column, a `fixed_size_list<float32>`, and of it only
//! the values of its valid rows, straight into one `Vec<f32>`.
//!
//! The merge of a graph job needs the feature store's `lma` column (the raw LMA measurements of
//! every window: 456 of the 664 bytes per frame) and nothing else. arrow-ipc's `FileReader`
//! reads a record batch's whole body before it decodes a projected column, and the caller then
//! copies the values out while that body is still held: at 54k frames (one batch) the merge
//! read 36 MB and held it beside the 25 MB it kept. A batch body holds its buffers in
//! depth-first field order, so the last column's three buffers (list validity, item validity,
//! item values) come last; [`TrailingFloatRows`] reads a batch's message, the list's validity
//! bitmap, then, run by run of valid rows, only their value bytes, into the caller's vector.
//! Null rows (where no window fits) are neither read nor stored, and no second copy of the
//! column exists at any time.
//!
//! It relies on what the IPC format fixes for an uncompressed batch (buffer order, validity
//! bitmaps least significant bit first, values in the endianness the schema states) and checks
//! each thing it relies on: a compressed batch, another node or buffer count, a nullable item,
//! a row count or a buffer that does not fit is an error naming the file, never a wrong value.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use arrow_ipc::Block;
use arrow_schema::DataType;

use super::ipc_prefix::{err, read_at, read_footer, read_message, record_batch};
use super::GraphError;

/// Bytes of one f32 value.
const F32_BYTES: usize = 4;

/// An open IPC file read for the valid rows of its last column.
pub struct TrailingFloatRows {
    path: PathBuf,
    file: File,
    blocks: Vec<Block>,
    /// Floats per row of the column.
    width: usize,
    /// Field nodes and IPC buffers of a whole record batch (every column).
    all_nodes: usize,
    all_buffers: usize,
    /// Bytes read so far from record batches (messages, bitmaps, values).
    read: u64,
}

impl TrailingFloatRows {
    /// Opens `path`, whose last column must be a non-null-item `fixed_size_list<float32>` of
    /// `width` floats, in record batches of `all_nodes` field nodes and `all_buffers` buffers
    /// (the caller knows the whole schema).
    pub fn open(
        path: &Path,
        width: usize,
        all_nodes: usize,
        all_buffers: usize,
    ) -> Result<TrailingFloatRows, GraphError> {
        let f = read_footer(path)?;
        if !f.little_endian {
            return Err(err(path, "big-endian buffers"));
        }
        let fits = match f.schema.fields().last().map(|c| c.data_type()) {
            Some(DataType::FixedSizeList(item, n)) => {
                usize::try_from(*n).ok() == Some(width)
                    && *item.data_type() == DataType::Float32
                    && !item.is_nullable()
            }
            _ => false,
        };
        if !fits || all_nodes < 2 || all_buffers < 3 {
            return Err(err(
                path,
                format!("the last column is no fixed_size_list<float32>[{width}]"),
            ));
        }
        Ok(TrailingFloatRows {
            path: path.to_path_buf(),
            file: f.file,
            blocks: f.blocks,
            width,
            all_nodes,
            all_buffers,
            read: 0,
        })
    }

    /// Record batches in the file.
    pub fn batches(&self) -> usize {
        self.blocks.len()
    }

    /// Bytes read so far from record batches: messages, validity bitmaps and values.
    pub fn bytes_read(&self) -> u64 {
        self.read
    }

    /// Appends the values of record batch `k`'s valid rows to `out` (`width` floats a row, in
    /// row order) after checking that the batch holds `rows` rows; returns the rows appended.
    pub fn append_batch(
        &mut self,
        k: usize,
        rows: usize,
        out: &mut Vec<f32>,
    ) -> Result<usize, GraphError> {
        let path = self.path.clone();
        let bad = |what: String| err(&path, format!("record batch {k}: {what}"));
        let block = *self.blocks.get(k).ok_or_else(|| bad("missing".into()))?;
        let (meta, body_at, body_len) = read_message(&mut self.file, &path, &block, k)?;
        self.read += meta.len() as u64;
        let batch = record_batch(&meta, &path)?;
        if batch.compression().is_some() {
            return Err(bad(
                "compressed (figurine writes and reads uncompressed stores)".into(),
            ));
        }
        if usize::try_from(batch.length()).ok() != Some(rows) {
            return Err(bad(format!("{} rows, expected {rows}", batch.length())));
        }
        let (nodes, buffers) = match (batch.nodes(), batch.buffers()) {
            (Some(n), Some(b)) if n.len() == self.all_nodes && b.len() == self.all_buffers => {
                (n, b)
            }
            _ => return Err(bad("not laid out as a feature store batch".into())),
        };
        let (list, item) = (nodes.get(self.all_nodes - 2), nodes.get(self.all_nodes - 1));
        let list_nulls = usize::try_from(list.null_count())
            .ok()
            .filter(|&n| n <= rows);
        let (Some(list_nulls), true, true, true) = (
            list_nulls,
            usize::try_from(list.length()).ok() == Some(rows),
            usize::try_from(item.length()).ok() == rows.checked_mul(self.width),
            item.null_count() == 0,
        ) else {
            return Err(bad("its last column does not match its row count".into()));
        };
        // A buffer's place in the body, checked to lie inside it.
        let span = |b: &arrow_ipc::Buffer| -> Option<(u64, u64)> {
            let (at, len) = (
                u64::try_from(b.offset()).ok()?,
                u64::try_from(b.length()).ok()?,
            );
            (at.checked_add(len)? <= body_len).then_some((at, len))
        };
        let (Some((mask_at, mask_len)), Some((values_at, values_len))) = (
            span(buffers.get(self.all_buffers - 3)),
            span(buffers.get(self.all_buffers - 1)),
        ) else {
            return Err(bad(
                "a buffer of its last column lies outside the batch".into()
            ));
        };
        let row_bytes = self.width * F32_BYTES;
        if (values_len as u128) < rows as u128 * row_bytes as u128 {
            return Err(bad("its values are cut short".into()));
        }
        // Without nulls a writer may leave the bitmap out: every row is then valid.
        let mask = if list_nulls == 0 {
            None
        } else {
            let need = rows.div_ceil(8);
            if mask_len < need as u64 {
                return Err(bad("its validity bitmap is cut short".into()));
            }
            self.read += need as u64;
            Some(read_at(&mut self.file, &path, body_at + mask_at, need)?)
        };
        let valid = |i: usize| {
            mask.as_ref()
                .is_none_or(|m| m.get(i / 8).is_some_and(|b| (b >> (i % 8)) & 1 == 1))
        };
        let mut appended = 0;
        let mut i = 0;
        while i < rows {
            if !valid(i) {
                i += 1;
                continue;
            }
            let j = (i + 1..rows).find(|&r| !valid(r)).unwrap_or(rows);
            let start = out.len();
            out.resize(start + (j - i) * self.width, 0.0);
            let dst: &mut [u8] = bytemuck::cast_slice_mut(&mut out[start..]);
            let at = body_at + values_at + (i * row_bytes) as u64;
            self.file
                .seek(SeekFrom::Start(at))
                .and_then(|_| self.file.read_exact(dst))
                .map_err(|e| bad(format!("reading rows {i}..{j}: {e}")))?;
            self.read += dst.len() as u64;
            // The file's values are little-endian (checked at open): a no-op on such hosts.
            for v in &mut out[start..] {
                *v = f32::from_bits(u32::from_le(v.to_bits()));
            }
            appended += j - i;
            i = j;
        }
        if appended != rows - list_nulls {
            return Err(bad(format!(
                "{appended} valid rows, its null count says {}",
                rows - list_nulls
            )));
        }
        Ok(appended)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    use arrow_array::{Array, FixedSizeListArray, Float32Array, RecordBatch, UInt32Array};
    use arrow_buffer::NullBuffer;
    use arrow_ipc::reader::FileReader;
    use arrow_ipc::writer::FileWriter;
    use arrow_schema::{Field, Schema};

    const WIDTH: usize = 3;

    /// A file of a u32 column `a` (2 buffers) and a nullable list `b` of 3 floats (3
    /// buffers), in batches of 50, 50 and 20 rows; row r of `b` is null where r % 7 < 2 (and
    /// everywhere in the last batch when `all_null_last`), else holds r + 0.25, −r, r / 3.
    fn file(name: &str, all_null_last: bool) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("figurine-ipcf-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("f.arrow");
        let item = Arc::new(Field::new("item", DataType::Float32, false));
        let schema = Arc::new(Schema::new(vec![
            Field::new("a", DataType::UInt32, false),
            Field::new(
                "b",
                DataType::FixedSizeList(item.clone(), WIDTH as i32),
                true,
            ),
        ]));
        let mut w = FileWriter::try_new(File::create(&path).unwrap(), &schema).unwrap();
        for (start, len) in [(0u32, 50u32), (50, 50), (100, 20)] {
            let rows = start..start + len;
            let valid: Vec<bool> = rows
                .clone()
                .map(|r| r % 7 >= 2 && !(all_null_last && start == 100))
                .collect();
            let values: Vec<f32> = rows
                .clone()
                .flat_map(|r| [r as f32 + 0.25, -(r as f32), r as f32 / 3.0])
                .collect();
            let b = FixedSizeListArray::try_new(
                item.clone(),
                WIDTH as i32,
                Arc::new(Float32Array::from(values)),
                Some(NullBuffer::from(valid)),
            )
            .unwrap();
            let a = UInt32Array::from_iter_values(rows);
            w.write(&RecordBatch::try_new(schema.clone(), vec![Arc::new(a), Arc::new(b)]).unwrap())
                .unwrap();
        }
        w.finish().unwrap();
        path
    }

    /// The valid rows of column `b` through arrow-ipc's own reader.
    fn through_arrow(path: &Path) -> Vec<u32> {
        let r = FileReader::try_new(File::open(path).unwrap(), Some(vec![1])).unwrap();
        let mut out = Vec::new();
        for b in r {
            let b = b.unwrap();
            let list = b
                .column(0)
                .as_any()
                .downcast_ref::<FixedSizeListArray>()
                .unwrap();
            let v = list
                .values()
                .as_any()
                .downcast_ref::<Float32Array>()
                .unwrap();
            for i in (0..list.len()).filter(|&i| list.is_valid(i)) {
                out.extend((0..WIDTH).map(|c| v.value(i * WIDTH + c).to_bits()));
            }
        }
        out
    }

    #[test]
    fn valid_rows_equal_arrows_own_reading_and_skip_the_rest() {
        for all_null_last in [false, true] {
            let path = file(&format!("eq{all_null_last}"), all_null_last);
            let mut r = TrailingFloatRows::open(&path, WIDTH, 3, 5).unwrap();
            assert_eq!(r.batches(), 3);
            let mut out = Vec::new();
            let got: Vec<usize> = [50, 50, 20]
                .iter()
                .enumerate()
                .map(|(k, &rows)| r.append_batch(k, rows, &mut out).unwrap())
                .collect();
            let want_last = if all_null_last { 0 } else { 15 };
            assert_eq!(got, vec![35, 35, want_last]);
            let bits: Vec<u32> = out.iter().map(|v| v.to_bits()).collect();
            assert_eq!(bits, through_arrow(&path));
            // Values of valid rows, messages and bitmaps only: less than the file's bodies.
            let values = out.len() as u64 * 4;
            let file_len = std::fs::metadata(&path).unwrap().len();
            assert!(r.bytes_read() >= values && r.bytes_read() < values + 2000);
            assert!(
                r.bytes_read() + 400 < file_len,
                "{} of {file_len}",
                r.bytes_read()
            );
            std::fs::remove_dir_all(path.parent().unwrap()).ok();
        }
    }

    #[test]
    fn wrong_shapes_truncation_and_row_counts_are_errors_naming_the_file() {
        let path = file("bad", false);
        // Another width, another layout, another row count.
        assert!(TrailingFloatRows::open(&path, 4, 3, 5).is_err());
        let e = TrailingFloatRows::open(&path, WIDTH, 3, 6)
            .unwrap()
            .append_batch(0, 50, &mut Vec::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("f.arrow") && e.contains("record batch 0"), "{e}");
        let e = TrailingFloatRows::open(&path, WIDTH, 3, 5)
            .unwrap()
            .append_batch(1, 49, &mut Vec::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("f.arrow") && e.contains("49"), "{e}");
        assert!(TrailingFloatRows::open(&path, WIDTH, 3, 5)
            .unwrap()
            .append_batch(3, 20, &mut Vec::new())
            .is_err());
        // Cut anywhere: refused at open (the footer) or at the batch, naming the file.
        let bytes = std::fs::read(&path).unwrap();
        for cut in [0, 9, 300, bytes.len() / 2, bytes.len() - 1] {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            let e = TrailingFloatRows::open(&path, WIDTH, 3, 5)
                .and_then(|mut r| {
                    let mut out = Vec::new();
                    (0..3)
                        .try_for_each(|k| r.append_batch(k, [50, 50, 20][k], &mut out).map(|_| ()))
                })
                .err()
                .unwrap_or_else(|| panic!("cut {cut} accepted"))
                .to_string();
            assert!(e.contains("f.arrow"), "cut {cut}: {e}");
        }
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }
}
