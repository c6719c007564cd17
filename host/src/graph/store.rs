//! The feature store of a distributed graph job: one Arrow IPC file every tile reads.
//!
//! `JOB/features.arrow` holds one row per frame of the concatenated library (global frame
//! order), so other tools (pyarrow, polars, DuckDB, arrow-rs …) can read the features too:
//!
//! | column | Arrow type | unit | what |
//! |---|---|---|---|
//! | `clip` | uint32 | — | index into the manifest's clip list |
//! | `points` | fixed_size_list<float32>[48] | m | the 16 role points, x y z each ([`Role`] order) |
//! | `window_mx`, `window_mz` | float32, null off-centre | m | mean x, z of the 35-frame window centred here |
//! | `window_sq` | float32, null off-centre | m² | Σ‖p‖² − W (x̄² + z̄²) of that window |
//! | `lma` | fixed_size_list<float32>[114], null off-centre | mixed (see [`super::lma`]) | raw LMA measurements of that window |
//!
//! The window columns are null on a clip's first and last [`super::HALF`] frames, where no window
//! fits. The window terms are stored, not recomputed, because they are running sums over the
//! whole clip: a tile that holds only its bands could not reproduce them bit for bit.
//!
//! Rows come in record batches of [`BATCH_ROWS`] (the last one shorter), so a tile reads only
//! the batches its bands touch, and only the bytes of the columns it needs
//! ([`super::ipc_prefix`]); the merge reads only the `lma` values of window centres
//! ([`super::ipc_floats`]). Size: 4 + 192 + 12 + 456 bytes
//! of values per frame plus validity bits and padding, about 664 MB (633 MiB) per million
//! frames, uncompressed (compression would add codecs to the build for data that compresses
//! poorly: f32 motion).
//!
//! The schema's metadata names the format, its version and the plan id, so a store from
//! another plan, a newer version or a truncated file is refused with the file's name.

use std::collections::HashMap;
use std::fs::File;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use arrow_array::cast::AsArray;
use arrow_array::types::{Float32Type, UInt32Type};
use arrow_array::{Array, ArrayRef, FixedSizeListArray, Float32Array, RecordBatch, UInt32Array};
use arrow_buffer::NullBuffer;
use arrow_ipc::writer::FileWriter;
use arrow_schema::{DataType, Field, Schema};
use glam::Vec3;

use super::ipc_floats::TrailingFloatRows;
use super::ipc_prefix::{read_footer, LeadingColumns};
use super::lma::MEASUREMENTS;
use super::posture::WindowTerms;
use super::roles::Role;
use super::search::FrameRows;
use super::GraphError;

/// Version of the feature store layout this build writes and reads.
pub const STORE_VERSION: u32 = 1;
/// IPC buffers of a record batch's first five columns (what a tile reads): `clip` 2, `points`
/// 3 (list validity, item validity and values), the three window terms 2 each.
const SEARCH_BUFFERS: usize = 11;
/// IPC buffers of a whole record batch: those and the `lma` column's 3.
const ALL_BUFFERS: usize = 14;
/// Field nodes of a whole record batch: one per column, and one for each list's items.
const ALL_NODES: usize = 8;
/// Rows per record batch (the last batch of a file may be shorter).
pub const BATCH_ROWS: usize = 65_536;
/// Floats per frame in the `points` column (16 role points × x y z).
pub const POINT_FLOATS: usize = 3 * Role::COUNT;
/// Schema metadata keys.
const KEY_FORMAT: &str = "figurine.format";
const KEY_VERSION: &str = "figurine.version";
const KEY_PLAN: &str = "figurine.plan";
/// Value of the format key.
const FORMAT: &str = "figurine-graph-features";

fn arrow_err(path: &Path, e: impl std::fmt::Display) -> GraphError {
    GraphError::format(path, format!("feature store: {e}"))
}

fn io_err(path: &Path, source: std::io::Error) -> GraphError {
    GraphError::Io {
        path: path.to_path_buf(),
        source,
    }
}

fn item() -> Arc<Field> {
    Arc::new(Field::new("item", DataType::Float32, false))
}

fn schema(plan: u64) -> Schema {
    let list = |n: usize| DataType::FixedSizeList(item(), n as i32);
    let meta = HashMap::from([
        (KEY_FORMAT.to_string(), FORMAT.to_string()),
        (KEY_VERSION.to_string(), STORE_VERSION.to_string()),
        (KEY_PLAN.to_string(), format!("{plan:016x}")),
    ]);
    Schema::new_with_metadata(
        vec![
            Field::new("clip", DataType::UInt32, false),
            Field::new("points", list(POINT_FLOATS), false),
            Field::new("window_mx", DataType::Float32, true),
            Field::new("window_mz", DataType::Float32, true),
            Field::new("window_sq", DataType::Float32, true),
            Field::new("lma", list(MEASUREMENTS), true),
        ],
        meta,
    )
}

/// One record batch of rows `range` (global frames; `rows.base` is 0), with the measurement
/// rows of its window centres starting at window `w0`.
fn batch(
    s: &Arc<Schema>,
    rows: &FrameRows,
    meas: &[f32],
    range: Range<usize>,
    w0: &mut usize,
) -> Result<RecordBatch, arrow_schema::ArrowError> {
    let len = range.len();
    let mut points = Vec::with_capacity(len * POINT_FLOATS);
    let mut lma = Vec::with_capacity(len * MEASUREMENTS);
    let (mut mx, mut mz, mut sq) = (Vec::new(), Vec::new(), Vec::new());
    for g in range.clone() {
        points.extend(rows.points[g].iter().flat_map(|p| [p.x, p.y, p.z]));
        let t = rows.terms[g];
        mx.push(t.map(|t| t.mx));
        mz.push(t.map(|t| t.mz));
        sq.push(t.map(|t| t.sq));
        match meas.get(*w0 * MEASUREMENTS..(*w0 + 1) * MEASUREMENTS) {
            Some(m) if t.is_some() => {
                lma.extend_from_slice(m);
                *w0 += 1;
            }
            _ => lma.extend(std::iter::repeat_n(0.0, MEASUREMENTS)),
        }
    }
    let valid = NullBuffer::from(
        rows.terms[range.clone()]
            .iter()
            .map(Option::is_some)
            .collect::<Vec<_>>(),
    );
    let columns: Vec<ArrayRef> = vec![
        Arc::new(UInt32Array::from(rows.clip_of[range].to_vec())),
        Arc::new(FixedSizeListArray::try_new(
            item(),
            POINT_FLOATS as i32,
            Arc::new(Float32Array::from(points)),
            None,
        )?),
        Arc::new(Float32Array::from(mx)),
        Arc::new(Float32Array::from(mz)),
        Arc::new(Float32Array::from(sq)),
        Arc::new(FixedSizeListArray::try_new(
            item(),
            MEASUREMENTS as i32,
            Arc::new(Float32Array::from(lma)),
            Some(valid),
        )?),
    ];
    RecordBatch::try_new(s.clone(), columns)
}

/// Writes the store of `rows` (the whole library, base 0) and its window `measurements`
/// (`windows × 114`) to `path` for plan `plan`, through a temporary file renamed into place.
/// Returns the file's size in bytes.
pub fn write_store(
    path: &Path,
    rows: &FrameRows,
    measurements: &[f32],
    plan: u64,
) -> Result<u64, GraphError> {
    let windows = rows.terms.iter().filter(|t| t.is_some()).count();
    if rows.base != 0 || windows * MEASUREMENTS != measurements.len() {
        return Err(GraphError::Invalid(format!(
            "{}: {} window centres but {} measurement rows",
            path.display(),
            windows,
            measurements.len() / MEASUREMENTS
        )));
    }
    let tmp = path.with_extension(format!("arrow.tmp{}", std::process::id()));
    let s = Arc::new(schema(plan));
    let write = || -> Result<(), arrow_schema::ArrowError> {
        let file = File::create(&tmp)?;
        let mut w = FileWriter::try_new_buffered(file, &s)?;
        let mut w0 = 0usize;
        for start in (0..rows.len()).step_by(BATCH_ROWS) {
            let end = (start + BATCH_ROWS).min(rows.len());
            w.write(&batch(&s, rows, measurements, start..end, &mut w0)?)?;
        }
        w.finish()?;
        let file = w.into_inner()?.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        Ok(())
    };
    if let Err(e) = write() {
        std::fs::remove_file(&tmp).ok();
        return Err(arrow_err(path, e));
    }
    std::fs::rename(&tmp, path).map_err(|e| io_err(path, e))?;
    std::fs::metadata(path)
        .map(|m| m.len())
        .map_err(|e| io_err(path, e))
}

/// An open feature store, checked against its plan and frame count.
pub struct Store {
    path: std::path::PathBuf,
    frames: usize,
}

impl Store {
    /// Opens `path` for plan `plan` with `frames` rows; refuses another plan, a newer version,
    /// a truncated file or a file that is no feature store.
    pub fn open(path: &Path, plan: u64, frames: usize) -> Result<Store, GraphError> {
        let s = Store {
            path: path.to_path_buf(),
            frames,
        };
        // Only the footer: schema and batch list, its lengths checked against the file's size.
        let footer = read_footer(path)?;
        let found_schema = &footer.schema;
        let meta = found_schema.metadata();
        if meta.get(KEY_FORMAT).map(String::as_str) != Some(FORMAT) {
            return Err(arrow_err(path, "not a figurine feature store"));
        }
        let version: u32 = meta
            .get(KEY_VERSION)
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| arrow_err(path, "no version"))?;
        if version > STORE_VERSION {
            return Err(arrow_err(
                path,
                format!("made by a newer figurine (store version {version}; this one reads {STORE_VERSION})"),
            ));
        }
        let found = meta.get(KEY_PLAN).cloned().unwrap_or_default();
        if found != format!("{plan:016x}") {
            return Err(arrow_err(
                path,
                format!("belongs to plan {found}, not to this job's plan {plan:016x}"),
            ));
        }
        if *found_schema != schema(plan) {
            return Err(arrow_err(path, "unexpected columns"));
        }
        if footer.blocks.len() != frames.div_ceil(BATCH_ROWS) {
            return Err(arrow_err(
                path,
                format!(
                    "{} record batches, the plan's {frames} frames need {}",
                    footer.blocks.len(),
                    frames.div_ceil(BATCH_ROWS)
                ),
            ));
        }
        Ok(s)
    }

    /// Checks that record batch `b`, number `k`, has the expected row count.
    fn check_rows(&self, b: &RecordBatch, k: usize) -> Result<(), GraphError> {
        let want = (self.frames - k * BATCH_ROWS).min(BATCH_ROWS);
        if b.num_rows() != want {
            return Err(arrow_err(
                &self.path,
                format!(
                    "record batch {k} has {} rows, expected {want}",
                    b.num_rows()
                ),
            ));
        }
        Ok(())
    }

    /// The search inputs of global frames `range` (clip, points, window terms).
    pub fn rows(&self, range: Range<usize>) -> Result<FrameRows, GraphError> {
        let mut out = FrameRows {
            base: range.start,
            ..Default::default()
        };
        if range.is_empty() {
            return Ok(out);
        }
        if range.end > self.frames {
            return Err(arrow_err(
                &self.path,
                format!("frames {range:?} past the end"),
            ));
        }
        // Only the bytes of the first five columns are read: the LMA column, last in every
        // batch, is two-thirds of the file and only the merge needs it.
        let mut r = LeadingColumns::open(&self.path, 5, SEARCH_BUFFERS, ALL_BUFFERS)?;
        for k in range.start / BATCH_ROWS..=(range.end - 1) / BATCH_ROWS {
            let b = r.batch(k)?;
            self.check_rows(&b, k)?;
            let lo = range.start.max(k * BATCH_ROWS) - k * BATCH_ROWS;
            let hi = range.end.min((k + 1) * BATCH_ROWS) - k * BATCH_ROWS;
            let bad = |what: &str| {
                arrow_err(&self.path, format!("record batch {k}: bad `{what}` column"))
            };
            let clip = b
                .column(0)
                .as_primitive_opt::<UInt32Type>()
                .ok_or_else(|| bad("clip"))?;
            let pts = b
                .column(1)
                .as_fixed_size_list_opt()
                .ok_or_else(|| bad("points"))?;
            let pv = pts
                .values()
                .as_primitive_opt::<Float32Type>()
                .ok_or_else(|| bad("points"))?;
            let pv: &[f32] = pv.values();
            let terms: Vec<&Float32Array> = (2..5)
                .map(|c| b.column(c).as_primitive_opt::<Float32Type>())
                .collect::<Option<_>>()
                .ok_or_else(|| bad("window"))?;
            for i in lo..hi {
                out.clip_of.push(clip.value(i));
                let p = pv
                    .get(pts.value_offset_at(i)..pts.value_offset_at(i + 1))
                    .ok_or_else(|| bad("points"))?;
                out.points.push(std::array::from_fn(|r| {
                    Vec3::new(p[3 * r], p[3 * r + 1], p[3 * r + 2])
                }));
                let valid = terms.iter().all(|t| t.is_valid(i));
                out.terms.push(valid.then(|| WindowTerms {
                    mx: terms[0].value(i),
                    mz: terms[1].value(i),
                    sq: terms[2].value(i),
                }));
            }
        }
        Ok(out)
    }

    /// The raw LMA measurements of every window (`windows × 114`, global order), checked to be
    /// `windows` rows, and the bytes read from the file for them.
    ///
    /// Only the `lma` column is read, and of it only the rows of window centres: 456 bytes per
    /// window of the 664 per frame, straight into the returned vector ([`super::ipc_floats`]).
    pub fn measurements(&self, windows: usize) -> Result<(Vec<f32>, u64), GraphError> {
        if windows > self.frames {
            return Err(arrow_err(
                &self.path,
                format!(
                    "the plan's {windows} windows exceed its {} frames",
                    self.frames
                ),
            ));
        }
        let mut r = TrailingFloatRows::open(&self.path, MEASUREMENTS, ALL_NODES, ALL_BUFFERS)?;
        let mut out = Vec::new();
        out.try_reserve_exact(windows * MEASUREMENTS)
            .map_err(|e| arrow_err(&self.path, format!("{windows} windows: {e}")))?;
        for k in 0..self.frames.div_ceil(BATCH_ROWS) {
            let rows = (self.frames - k * BATCH_ROWS).min(BATCH_ROWS);
            r.append_batch(k, rows, &mut out)?;
            if out.len() > windows * MEASUREMENTS {
                break;
            }
        }
        if out.len() != windows * MEASUREMENTS {
            return Err(arrow_err(
                &self.path,
                format!(
                    "{}{} windows, the plan has {windows}",
                    if out.len() > windows * MEASUREMENTS {
                        "more than "
                    } else {
                        ""
                    },
                    out.len() / MEASUREMENTS
                ),
            ));
        }
        Ok((out, r.bytes_read()))
    }
}

/// Bytes of column values per frame (what the store's size grows by, before validity bits,
/// padding and the footer).
pub const BYTES_PER_FRAME: usize = 4 + 4 * POINT_FLOATS + 3 * 4 + 4 * MEASUREMENTS;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::build::{measurements, tests::fake_clip};
    use crate::graph::lma::tests::synthetic;

    fn library() -> (FrameRows, Vec<f32>) {
        let clips = vec![
            fake_clip("a", synthetic(90, 0.8, 0.3)),
            fake_clip("b", synthetic(40, 0.2, 0.6)),
        ];
        (FrameRows::from_clips(&clips), measurements(&clips))
    }

    fn tmp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("figurine-store-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d.join("features.arrow")
    }

    /// The seed of the `graph_store` fuzz target: a frame count (u32) and a plan id (u64),
    /// little-endian, then the store of one 60-frame clip. Written again with
    /// FIGURINE_WRITE_FUZZ_SEEDS=1 (after a change of the store or of the features).
    #[test]
    fn the_fuzz_seed_is_a_store_the_readers_accept() {
        let seed =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/graph_store/one-clip.bin");
        if std::env::var_os("FIGURINE_WRITE_FUZZ_SEEDS").is_some() {
            let clips = vec![fake_clip("a", synthetic(60, 0.8, 0.3))];
            let path = tmp("seed");
            write_store(
                &path,
                &FrameRows::from_clips(&clips),
                &measurements(&clips),
                7,
            )
            .unwrap();
            let mut bytes = 60u32.to_le_bytes().to_vec();
            bytes.extend(7u64.to_le_bytes());
            bytes.extend(std::fs::read(&path).unwrap());
            std::fs::create_dir_all(seed.parent().unwrap()).unwrap();
            std::fs::write(&seed, bytes).unwrap();
            std::fs::remove_dir_all(path.parent().unwrap()).ok();
        }
        // What the fuzz target does with it, on the success path all the way.
        let bytes = std::fs::read(&seed).unwrap();
        let frames = u32::from_le_bytes(bytes[..4].try_into().unwrap()) as usize;
        let plan = u64::from_le_bytes(bytes[4..12].try_into().unwrap());
        let path = tmp("seed-read");
        std::fs::write(&path, &bytes[12..]).unwrap();
        let s = Store::open(&path, plan, frames).unwrap();
        assert_eq!(s.rows(0..frames).unwrap().clip_of.len(), frames);
        let windows = frames + 1 - crate::graph::WINDOW;
        assert_eq!(
            s.measurements(windows).unwrap().0.len(),
            windows * MEASUREMENTS
        );
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }

    #[test]
    fn round_trip_is_bit_exact_for_any_range() {
        let (rows, meas) = library();
        let path = tmp("rt");
        let size = write_store(&path, &rows, &meas, 7).unwrap();
        assert!(size as usize > rows.len() * BYTES_PER_FRAME);
        let s = Store::open(&path, 7, rows.len()).unwrap();
        assert_eq!(s.rows(0..rows.len()).unwrap(), rows);
        let part = s.rows(20..77).unwrap();
        assert_eq!(part.base, 20);
        assert_eq!(part.points, rows.points[20..77]);
        assert_eq!(part.terms, rows.terms[20..77]);
        let (back, read) = s.measurements(meas.len() / MEASUREMENTS).unwrap();
        // The measurements' own bytes and little more (messages, a validity bitmap).
        assert!(
            read >= 4 * meas.len() as u64 && read < 4 * meas.len() as u64 + 1024,
            "{read}"
        );
        assert_eq!(
            back.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            meas.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }

    #[test]
    fn foreign_truncated_and_short_stores_are_refused_by_name() {
        let (rows, meas) = library();
        let path = tmp("bad");
        write_store(&path, &rows, &meas, 7).unwrap();
        let e = Store::open(&path, 8, rows.len()).err().unwrap().to_string();
        assert!(e.contains("features.arrow") && e.contains("plan"), "{e}");
        let e = Store::open(&path, 7, rows.len() + BATCH_ROWS)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("features.arrow"), "{e}");
        let bytes = std::fs::read(&path).unwrap();
        for cut in [0, 8, bytes.len() / 2, bytes.len() - 3] {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            let e = Store::open(&path, 7, rows.len())
                .and_then(|s| s.rows(0..rows.len()).map(|_| ()))
                .err()
                .unwrap()
                .to_string();
            assert!(e.contains("features.arrow"), "cut {cut}: {e}");
        }
        std::fs::remove_dir_all(path.parent().unwrap()).ok();
    }
}
