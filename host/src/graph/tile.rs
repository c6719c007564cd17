//! `figurine graph tile JOB --index I`: one tile of a planned job, and the tile file format.
//!
//! A tile reads the frames of its two bands from the feature store, runs its kernel tiles of
//! [`super::search`] on all cores, and writes what leaves a tile in `graph build` too: its local
//! minima (window pair and raw posture distance, m²), the min/max distance over its pairs and
//! their count. Posture correlations need the library-wide min/max and the style similarity is
//! only needed for the pairs that pass T_MG, so both are computed at merge, exactly as
//! `graph build` does after its search.
//!
//! Tiles are deterministic (candidates sorted, nothing depends on threads or timing), so a
//! re-run writes the same bytes. The file is written to a temporary name and renamed into place:
//! a tile killed half-way leaves at most a hidden temporary file that merge never reads, and two
//! runs of one tile at once each rename a complete, identical file.
//!
//! File format (`JOB/tiles/tile-NNNNN.bin`, little-endian):
//!
//! | bytes | field |
//! |---|---|
//! | 0..8 | magic `FIGTILE\0` |
//! | 8..12 | job version (u32) |
//! | 12..16 | tile index (u32) |
//! | 16..24 | plan id (u64) |
//! | 24..32 | window pairs evaluated (u64) |
//! | 32..36, 36..40 | min, max distance (f32; +∞, −∞ with no pairs) |
//! | 40..48 | candidate count c (u64) |
//! | 48..56 | CRC-64 of the body |
//! | 56.. | c × (i u32, j u32, d f32), sorted by (i, j), i < j |

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::build::progress_bar;
use super::plan::{
    read_manifest, tile_path, write_atomic, Manifest, TileSpec, CRC64, JOB_VERSION, STORE_FILE,
};
use super::search::{band_frames, search, Candidate, Found, Layout};
use super::store::Store;
use super::{cpu_seconds, GraphError};

/// Magic bytes at the start of a tile file.
pub const MAGIC: &[u8; 8] = b"FIGTILE\0";
/// Bytes of one candidate in the body.
pub const CANDIDATE_LEN: usize = 12;

/// Byte ranges of the header fields.
mod field {
    use std::ops::Range;
    pub const MAGIC: Range<usize> = 0..8;
    pub const VERSION: Range<usize> = 8..12;
    pub const INDEX: Range<usize> = 12..16;
    pub const PLAN: Range<usize> = 16..24;
    pub const PAIRS: Range<usize> = 24..32;
    pub const DMIN: Range<usize> = 32..36;
    pub const DMAX: Range<usize> = 36..40;
    pub const COUNT: Range<usize> = 40..48;
    pub const CRC: Range<usize> = 48..56;
}
/// Bytes before the body.
pub const HEADER_LEN: usize = field::CRC.end;

/// A tile file's content.
#[derive(Debug, Clone, PartialEq)]
pub struct TileFile {
    /// Job version that wrote it.
    pub version: u32,
    /// Tile index.
    pub index: u32,
    /// Plan id.
    pub plan: u64,
    /// What the tile found (candidates sorted).
    pub found: Found,
}

/// Encodes a tile file.
pub fn encode_tile(t: &TileFile) -> Vec<u8> {
    let mut body = Vec::with_capacity(t.found.candidates.len() * CANDIDATE_LEN);
    for c in &t.found.candidates {
        body.extend_from_slice(&c.i.to_le_bytes());
        body.extend_from_slice(&c.j.to_le_bytes());
        body.extend_from_slice(&c.d.to_bits().to_le_bytes());
    }
    let mut out = Vec::with_capacity(HEADER_LEN + body.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&t.version.to_le_bytes());
    out.extend_from_slice(&t.index.to_le_bytes());
    out.extend_from_slice(&t.plan.to_le_bytes());
    out.extend_from_slice(&t.found.pairs.to_le_bytes());
    out.extend_from_slice(&t.found.dmin.to_bits().to_le_bytes());
    out.extend_from_slice(&t.found.dmax.to_bits().to_le_bytes());
    out.extend_from_slice(&(t.found.candidates.len() as u64).to_le_bytes());
    out.extend_from_slice(&CRC64.checksum(&body).to_le_bytes());
    out.extend_from_slice(&body);
    out
}

fn u32_at(b: &[u8], r: std::ops::Range<usize>) -> u32 {
    let mut a = [0u8; 4];
    a.copy_from_slice(&b[r]);
    u32::from_le_bytes(a)
}

fn u64_at(b: &[u8], r: std::ops::Range<usize>) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[r]);
    u64::from_le_bytes(a)
}

/// Decodes a tile file's header (the file's first [`HEADER_LEN`] bytes or more): everything
/// but the candidates, whose count is returned. Errors name `path`.
pub fn parse_header(bytes: &[u8], path: &Path) -> Result<(TileFile, u64), GraphError> {
    let bad = |r: String| GraphError::format(path, r);
    if bytes.len() < HEADER_LEN || &bytes[field::MAGIC] != MAGIC {
        return Err(bad("not a figurine tile file (no FIGTILE header)".into()));
    }
    let version = u32_at(bytes, field::VERSION);
    if version > JOB_VERSION {
        return Err(bad(format!(
            "made by a newer figurine (job version {version}; this one reads {JOB_VERSION})"
        )));
    }
    let f32_at = |r| f32::from_bits(u32_at(bytes, r));
    let t = TileFile {
        version,
        index: u32_at(bytes, field::INDEX),
        plan: u64_at(bytes, field::PLAN),
        found: Found {
            candidates: Vec::new(),
            dmin: f32_at(field::DMIN),
            dmax: f32_at(field::DMAX),
            pairs: u64_at(bytes, field::PAIRS),
        },
    };
    if t.found.dmin.is_nan() || t.found.dmax.is_nan() {
        return Err(bad("distance range is not a number".into()));
    }
    Ok((t, u64_at(bytes, field::COUNT)))
}

/// Decodes a tile file; errors name `path`. Checks the magic, the version, the length, the
/// checksum and that candidates are sorted pairs with a finite, non-negative distance.
pub fn parse_tile(bytes: &[u8], path: &Path) -> Result<TileFile, GraphError> {
    parse_tile_keeping(bytes, path, |_| true)
}

/// [`parse_tile`], keeping only the candidates `keep` accepts (all are checked).
pub fn parse_tile_keeping(
    bytes: &[u8],
    path: &Path,
    keep: impl Fn(&Candidate) -> bool,
) -> Result<TileFile, GraphError> {
    let bad = |r: String| GraphError::format(path, r);
    let (mut t, count) = parse_header(bytes, path)?;
    let body = &bytes[HEADER_LEN..];
    if Some(body.len() as u64) != count.checked_mul(CANDIDATE_LEN as u64) {
        return Err(bad(format!(
            "truncated or padded: {} bytes of candidates, the header says {count} × {CANDIDATE_LEN}",
            body.len()
        )));
    }
    if CRC64.checksum(body) != u64_at(bytes, field::CRC) {
        return Err(bad("checksum mismatch: the file is damaged".into()));
    }
    let mut last: Option<(u32, u32)> = None;
    for c in body.chunks_exact(CANDIDATE_LEN) {
        let c = Candidate {
            i: u32_at(c, 0..4),
            j: u32_at(c, 4..8),
            d: f32::from_bits(u32_at(c, 8..12)),
        };
        let sorted = last.is_none_or(|p| p < (c.i, c.j));
        if c.i >= c.j || !sorted || !(c.d.is_finite() && c.d >= 0.0) {
            return Err(bad(format!(
                "candidate ({}, {}, {}) out of order or invalid",
                c.i, c.j, c.d
            )));
        }
        last = Some((c.i, c.j));
        if keep(&c) {
            t.found.candidates.push(c);
        }
    }
    Ok(t)
}

/// Checks that tile `t` read from `path` belongs to job `m` as tile `spec`.
fn check_belongs(
    t: &TileFile,
    path: &Path,
    m: &Manifest,
    spec: &TileSpec,
) -> Result<(), GraphError> {
    if t.plan != m.plan_id() {
        return Err(GraphError::format(
            path,
            format!(
                "from another plan ({:016x}; this job is {}): re-run `figurine graph tile` for it",
                t.plan, m.plan
            ),
        ));
    }
    if t.index as usize != spec.index {
        return Err(GraphError::format(
            path,
            format!("holds tile {}, not tile {}", t.index, spec.index),
        ));
    }
    let inside = |c: &Candidate| {
        (spec.rows[0]..spec.rows[1]).contains(&(c.i as usize))
            && (spec.cols[0]..spec.cols[1]).contains(&(c.j as usize))
    };
    if let Some(c) = t.found.candidates.iter().find(|c| !inside(c)) {
        return Err(GraphError::format(
            path,
            format!("candidate ({}, {}) lies outside the tile", c.i, c.j),
        ));
    }
    Ok(())
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> GraphError + '_ {
    move |source| GraphError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Reads only the header of tile `spec` of job `m` and checks it belongs (plan and index):
/// the tile's distance range, pair count, and its candidate count.
pub fn read_tile_header(
    path: &Path,
    m: &Manifest,
    spec: &TileSpec,
) -> Result<(Found, u64), GraphError> {
    use std::io::Read;
    let mut head = Vec::with_capacity(HEADER_LEN);
    std::fs::File::open(path)
        .map_err(io(path))?
        .take(HEADER_LEN as u64)
        .read_to_end(&mut head)
        .map_err(io(path))?;
    let (t, count) = parse_header(&head, path)?;
    check_belongs(&t, path, m, spec)?;
    Ok((t.found, count))
}

/// Reads tile `spec` of job `m` from `path`, keeping the candidates `keep` accepts, and checks
/// it belongs: same plan, same index, every candidate inside the tile's bands.
pub fn read_tile(
    path: &Path,
    m: &Manifest,
    spec: &TileSpec,
    keep: impl Fn(&Candidate) -> bool,
) -> Result<Found, GraphError> {
    let bytes = std::fs::read(path).map_err(io(path))?;
    let t = parse_tile_keeping(&bytes, path, keep)?;
    check_belongs(&t, path, m, spec)?;
    Ok(t.found)
}

/// What one tile run did.
#[derive(Debug, Clone)]
pub struct TileRun {
    /// The tile file written.
    pub path: PathBuf,
    /// What it found.
    pub found: Found,
    /// Kernel tiles run.
    pub kernels: usize,
    /// Seconds reading the store.
    pub read_seconds: f64,
    /// Seconds of the search.
    pub search_seconds: f64,
    /// CPU seconds of the search, all threads (NaN where /proc is missing).
    pub search_cpu_seconds: f64,
    /// Seconds writing the tile file.
    pub write_seconds: f64,
}

/// Runs tile `index` of job folder `job` and writes its file (atomically).
pub fn run_tile(job: &Path, index: usize, progress: bool) -> Result<TileRun, GraphError> {
    let t0 = Instant::now();
    let m = read_manifest(job)?;
    let spec = *m.tiles.get(index).ok_or_else(|| {
        GraphError::Invalid(format!(
            "{}: tile {index} does not exist (the job has tiles 0..={})",
            job.display(),
            m.tiles.len().saturating_sub(1)
        ))
    })?;
    let store = Store::open(&job.join(STORE_FILE), m.plan_id(), m.frames)?;
    let n = m.frames;
    let row_frames = band_frames(spec.rows[0]..spec.rows[1], n);
    let col_frames = band_frames(spec.cols[0]..spec.cols[1], n);
    let rows = Layout::new(&store.rows(row_frames.clone())?);
    let cols = if col_frames == row_frames {
        None
    } else {
        Some(Layout::new(&store.rows(col_frames)?))
    };
    let read_seconds = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let c1 = cpu_seconds().unwrap_or(f64::NAN);
    let kernels = m.kernels(&spec);
    let bar = progress_bar(progress, kernels.len() as u64, "posture correlation");
    let found = search(
        &rows,
        cols.as_ref().unwrap_or(&rows),
        n,
        &m.params,
        &kernels,
        &bar,
    );
    bar.finish_and_clear();
    let search_seconds = t1.elapsed().as_secs_f64();
    let search_cpu_seconds = cpu_seconds().unwrap_or(f64::NAN) - c1;
    let file = TileFile {
        version: JOB_VERSION,
        index: index as u32,
        plan: m.plan_id(),
        found,
    };
    let t2 = Instant::now();
    let path = tile_path(job, index);
    write_atomic(&path, &encode_tile(&file))?;
    Ok(TileRun {
        path,
        found: file.found,
        kernels: kernels.len(),
        read_seconds,
        search_seconds,
        search_cpu_seconds,
        write_seconds: t2.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> TileFile {
        TileFile {
            version: JOB_VERSION,
            index: 3,
            plan: 0xfeed,
            found: Found {
                candidates: vec![
                    Candidate {
                        i: 20,
                        j: 90,
                        d: 0.5,
                    },
                    Candidate {
                        i: 20,
                        j: 140,
                        d: 0.25,
                    },
                    Candidate {
                        i: 31,
                        j: 99,
                        d: 0.0,
                    },
                ],
                dmin: 0.0,
                dmax: 2.5,
                pairs: 1234,
            },
        }
    }

    #[test]
    fn round_trip() {
        let t = sample();
        assert_eq!(parse_tile(&encode_tile(&t), Path::new("t.bin")).unwrap(), t);
    }

    #[test]
    fn damaged_truncated_and_newer_files_are_refused_by_name() {
        let bytes = encode_tile(&sample());
        let p = Path::new("tiles/tile-00003.bin");
        for cut in [0, 7, HEADER_LEN - 1, HEADER_LEN, bytes.len() - 1] {
            let e = parse_tile(&bytes[..cut], p).unwrap_err().to_string();
            assert!(e.contains("tile-00003.bin"), "cut {cut}: {e}");
        }
        let mut flipped = bytes.clone();
        flipped[HEADER_LEN + 2] ^= 1;
        let e = parse_tile(&flipped, p).unwrap_err().to_string();
        assert!(e.contains("checksum"), "{e}");
        let mut newer = bytes.clone();
        newer[field::VERSION].copy_from_slice(&(JOB_VERSION + 1).to_le_bytes());
        let e = parse_tile(&newer, p).unwrap_err().to_string();
        assert!(e.contains("newer figurine"), "{e}");
        // A huge count in a short file must not allocate or panic.
        let mut huge = bytes[..HEADER_LEN].to_vec();
        huge[field::COUNT].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(parse_tile(&huge, p).is_err());
    }
}
