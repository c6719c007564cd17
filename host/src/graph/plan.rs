//! `figurine graph plan`: the features computed once, a manifest, and the job's tile list.
//!
//! A job folder `JOB/` holds:
//! - `manifest.json` ([`Manifest`]): the clips, roles, build parameters, band size, the tile list
//!   and the plan id;
//! - `features.arrow` ([`super::store`]): per-frame role points and window terms, per-window LMA
//!   measurements;
//! - `tiles/tile-NNNNN.bin` ([`super::tile`]), written by `figurine graph tile`;
//! - `tile.sbatch`, `merge.sbatch`, `submit.sh` ([`super::slurm`]) and `logs/`.
//!
//! The window centres are cut into bands of `band` frames (a multiple of the kernel tile
//! side), and a job tile is one pair of bands (A ≤ B): the kernel tiles of
//! [`super::search`] whose rows lie in A and columns in B. So the job's tiles together run
//! exactly the kernel tiles of `graph build`, each once, and a tile reads only the frames of
//! its two bands. b bands make b (b + 1) / 2 tiles.
//!
//! The plan id is a CRC-64 of the manifest (without the id) and of every feature value, so
//! planning the same clips with the same options gives the same id (tiles already computed stay
//! valid), and a tile or store of any other plan is recognised as foreign.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::build::{check_clips, clip_entries, measurements};
use super::graph::BuildParams;
use super::graph::ClipEntry;
use super::search::{kernel_side, FrameRows};
use super::source::GraphClip;
use super::store::{write_store, STORE_VERSION};
use super::{GraphError, WINDOW};

/// Name of the manifest in a job folder.
pub const MANIFEST_FILE: &str = "manifest.json";
/// Name of the feature store in a job folder.
pub const STORE_FILE: &str = "features.arrow";
/// Folder of the tile files in a job folder.
pub const TILES_DIR: &str = "tiles";
/// Value of the manifest's `format` field.
pub const JOB_FORMAT: &str = "figurine-graph-job";
/// Version of the job layout (manifest, tile files) this build writes and reads.
pub const JOB_VERSION: u32 = 1;
/// Default band, frames: a tile of 65,536² window pairs lasts about 23 s on 2 cores (5.3 ns per
/// pair measured), long beside Slurm's ≈ 1 s per-task latency; smaller bands make more, shorter
/// tiles whose latency shows (`cargo xtask bench`). A 4 M-frame library makes 1,953 tiles with
/// it: raise Slurm's MaxArraySize or plan with `--band 131072` (496 tiles).
pub const DEFAULT_BAND: usize = 65_536;
/// Most frames a job may have (global frames are u32 in the graph and tile files).
pub const MAX_FRAMES: usize = u32::MAX as usize;
/// Most kernel tiles along one side of a band (band ÷ tile side): a job tile holds at most
/// its square, 4 M kernel tiles, so its list of work stays small (with 256-window kernel tiles,
/// bands up to 524,288 frames).
pub const MAX_KERNELS_PER_BAND: usize = 2048;

/// One job tile: window centres `rows` × `cols` (global frames, half-open).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct TileSpec {
    /// Index of the tile (its Slurm array task id).
    pub index: usize,
    /// Row band, global frames `[start, end)`.
    pub rows: [usize; 2],
    /// Column band, global frames `[start, end)`.
    pub cols: [usize; 2],
}

/// The manifest of a distributed graph job (`JOB/manifest.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Always [`JOB_FORMAT`].
    pub format: String,
    /// Job layout version ([`JOB_VERSION`]).
    pub version: u32,
    /// Plan id, 16 hex digits (CRC-64 of the manifest without it and of the features).
    pub plan: String,
    /// Build parameters (`progress` is always false).
    pub params: BuildParams,
    /// Role overrides the clips were loaded with (role name → joint name).
    pub roles: BTreeMap<String, String>,
    /// Source clips, in global frame order.
    pub clips: Vec<ClipEntry>,
    /// Frames in the library.
    pub frames: usize,
    /// Windows in the library (rows of LMA measurements).
    pub windows: usize,
    /// Band size, frames (a multiple of the kernel tile side).
    pub band: usize,
    /// Version of the feature store layout.
    pub store_version: u32,
    /// Every tile of the job, by index.
    pub tiles: Vec<TileSpec>,
}

/// The job tiles of `frames` frames cut into bands of `band` frames.
pub fn tile_list(frames: usize, band: usize) -> Vec<TileSpec> {
    let bands: Vec<[usize; 2]> = (0..frames.div_ceil(band.max(1)))
        .map(|k| [k * band, ((k + 1) * band).min(frames)])
        .collect();
    let mut out = Vec::new();
    for (a, ra) in bands.iter().enumerate() {
        for rb in &bands[a..] {
            out.push(TileSpec {
                index: out.len(),
                rows: *ra,
                cols: *rb,
            });
        }
    }
    out
}

impl Manifest {
    /// The plan id as a number.
    pub fn plan_id(&self) -> u64 {
        u64::from_str_radix(&self.plan, 16).unwrap_or(0)
    }

    /// The kernel tiles `(a, b)` of job tile `t` (see [`super::search::search`]).
    pub fn kernels(&self, t: &TileSpec) -> Vec<(usize, usize)> {
        let k = kernel_side(&self.params);
        let (a0, a1) = (t.rows[0] / k, t.rows[1].div_ceil(k));
        let (b0, b1) = (t.cols[0] / k, t.cols[1].div_ceil(k));
        (a0..a1)
            .flat_map(|a| (b0.max(a)..b1).map(move |b| (a, b)))
            .collect()
    }

    /// Checks everything a reader relies on, so later stages index without panicking.
    fn validate(&self) -> Result<(), String> {
        if u64::from_str_radix(&self.plan, 16).is_err() || self.plan.len() != 16 {
            return Err(format!("plan id `{}` is not 16 hex digits", self.plan));
        }
        let p = &self.params;
        if !(0.0..=1.0).contains(&p.t_mg) || !(0.0..=1.0).contains(&p.t_lma) {
            return Err("t_mg and t_lma must be within 0..1".into());
        }
        if p.min_gap == 0 || p.tile == 0 || p.tile > MAX_FRAMES {
            return Err("min_gap and tile must be positive".into());
        }
        if self.frames > MAX_FRAMES {
            return Err(format!("{} frames; at most {MAX_FRAMES}", self.frames));
        }
        let (mut start, mut windows) = (0usize, 0usize);
        for c in &self.clips {
            if c.start as usize != start || (c.frames as usize) < WINDOW {
                return Err(format!(
                    "clip `{}`: starts at {} with {} frames; expected start {start} and at least {WINDOW} frames",
                    c.name, c.start, c.frames
                ));
            }
            start += c.frames as usize;
            windows += c.frames as usize + 1 - WINDOW;
        }
        if start != self.frames || windows != self.windows || self.clips.is_empty() {
            return Err(format!(
                "{} frames and {} windows listed, the clips have {start} and {windows}",
                self.frames, self.windows
            ));
        }
        check_band(self.band, p)?;
        let b = self.frames.div_ceil(self.band);
        if self.tiles.len() != b * (b + 1) / 2 || self.tiles != tile_list(self.frames, self.band) {
            return Err("the tile list does not match the frames and band".into());
        }
        if self.store_version > STORE_VERSION {
            return Err(format!(
                "feature store version {} is newer than this figurine reads ({STORE_VERSION})",
                self.store_version
            ));
        }
        Ok(())
    }
}

/// A band must be a positive multiple of the kernel tile side, at most
/// [`MAX_KERNELS_PER_BAND`] of them.
fn check_band(band: usize, p: &BuildParams) -> Result<(), String> {
    let side = kernel_side(p);
    if band == 0 || !band.is_multiple_of(side) || band / side > MAX_KERNELS_PER_BAND {
        return Err(format!(
            "band {band} frames is not a positive multiple of the tile side ({side} windows) of at most {MAX_KERNELS_PER_BAND} tiles"
        ));
    }
    Ok(())
}

/// Parses and checks a manifest's bytes; errors name `path`. A manifest from a newer
/// figurine is refused as such before its fields are read (they may have changed).
pub fn parse_manifest(bytes: &[u8], path: &Path) -> Result<Manifest, GraphError> {
    #[derive(Deserialize)]
    struct Head {
        format: String,
        version: u32,
    }
    let bad = |e: String| GraphError::format(path, e);
    let head: Head =
        serde_json::from_slice(bytes).map_err(|e| bad(format!("not a graph job manifest: {e}")))?;
    if head.format != JOB_FORMAT {
        return Err(bad(format!(
            "format `{}`, expected `{JOB_FORMAT}`",
            head.format
        )));
    }
    if head.version > JOB_VERSION {
        return Err(bad(format!(
            "made by a newer figurine (job version {}; this one reads {JOB_VERSION}); re-plan or update figurine",
            head.version
        )));
    }
    let m: Manifest =
        serde_json::from_slice(bytes).map_err(|e| bad(format!("malformed manifest: {e}")))?;
    m.validate().map_err(bad)?;
    Ok(m)
}

/// Reads `JOB/manifest.json`.
pub fn read_manifest(job: &Path) -> Result<Manifest, GraphError> {
    let path = job.join(MANIFEST_FILE);
    let bytes = std::fs::read(&path).map_err(|source| GraphError::Io {
        path: path.clone(),
        source,
    })?;
    parse_manifest(&bytes, &path)
}

/// Writes `bytes` to `path` through a temporary file in the same folder, renamed into place,
/// so a reader sees the old file or the new one, never half of one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), GraphError> {
    use std::io::Write;
    let io = |source| GraphError::Io {
        path: path.to_path_buf(),
        source,
    };
    // Host name, pid and a counter: two writers of the same file (a tile run twice at once, on
    // one machine or two sharing the folder, or two threads) never share a temporary file.
    static WRITES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let k = WRITES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap_or_default();
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
    let tmp = path.with_file_name(format!(
        ".{}.{}.{}.{k}.tmp",
        name.unwrap_or_default(),
        host.trim(),
        std::process::id()
    ));
    let write = || -> std::io::Result<()> {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    };
    if let Err(e) = write() {
        std::fs::remove_file(&tmp).ok();
        return Err(io(e));
    }
    std::fs::rename(&tmp, path).map_err(io)
}

/// What `plan` wrote.
#[derive(Debug, Clone)]
pub struct Planned {
    /// The manifest written.
    pub manifest: Manifest,
    /// Size of the feature store, bytes.
    pub store_bytes: u64,
    /// Tile files of an earlier, different plan that were removed.
    pub stale_removed: usize,
    /// Seconds computing the features (LMA measurements, window terms) and the plan id.
    pub features_seconds: f64,
    /// Seconds writing the feature store and the manifest.
    pub write_seconds: f64,
}

/// Plans the job of `clips` into folder `job`: features, store, manifest, an empty `tiles/`.
///
/// `band` is in frames (a positive multiple of the kernel tile side). Tiles of an earlier plan
/// with another id are removed; those of the same plan are kept (they are still valid).
pub fn plan_job(
    clips: &[GraphClip],
    roles: &BTreeMap<String, String>,
    p: &BuildParams,
    band: usize,
    job: &Path,
) -> Result<Planned, GraphError> {
    check_clips(clips)?;
    check_band(band, p).map_err(|e| GraphError::Invalid(format!("--band: {e}")))?;
    let t0 = std::time::Instant::now();
    let rows = FrameRows::from_clips(clips);
    if rows.len() > MAX_FRAMES {
        return Err(GraphError::Invalid(format!(
            "{} frames; a job holds at most {MAX_FRAMES}",
            rows.len()
        )));
    }
    let meas = measurements(clips);
    let mut m = Manifest {
        format: JOB_FORMAT.into(),
        version: JOB_VERSION,
        plan: String::new(),
        params: BuildParams {
            progress: false,
            ..*p
        },
        roles: roles.clone(),
        clips: clip_entries(clips),
        frames: rows.len(),
        windows: meas.len() / super::lma::MEASUREMENTS,
        band,
        store_version: STORE_VERSION,
        tiles: tile_list(rows.len(), band),
    };
    let id = plan_hash(&m, &rows, &meas);
    m.plan = format!("{id:016x}");
    let features_seconds = t0.elapsed().as_secs_f64();
    let t1 = std::time::Instant::now();
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| GraphError::Io { path, source }
    };
    let tiles = job.join(TILES_DIR);
    let old = read_manifest(job).ok().map(|o| o.plan);
    let mut stale_removed = 0;
    if old.as_deref().is_some_and(|o| o != m.plan) && tiles.is_dir() {
        for e in std::fs::read_dir(&tiles).map_err(io(&tiles))?.flatten() {
            if std::fs::remove_file(e.path()).is_ok() {
                stale_removed += 1;
            }
        }
    }
    for d in [job.to_path_buf(), tiles, job.join("logs")] {
        std::fs::create_dir_all(&d).map_err(io(&d))?;
    }
    let store_bytes = write_store(&job.join(STORE_FILE), &rows, &meas, id)?;
    let text = serde_json::to_vec_pretty(&m)
        .map_err(|e| GraphError::Invalid(format!("encoding the manifest: {e}")))?;
    write_atomic(&job.join(MANIFEST_FILE), &text)?;
    Ok(Planned {
        manifest: m,
        store_bytes,
        stale_removed,
        features_seconds,
        write_seconds: t1.elapsed().as_secs_f64(),
    })
}

/// CRC-64 (ECMA-182) with a 16-way table: the plan id and the tile checksums run over tens of
/// megabytes, which the crate's default byte-at-a-time table took a fifth of a second for at
/// 54k frames. The table is an implementation choice: the checksums are the same.
pub const CRC64: crc::Crc<u64, crc::Table<16>> =
    crc::Crc::<u64, crc::Table<16>>::new(&crc::CRC_64_ECMA_182);

/// CRC-64 of the manifest (id empty) and every feature value, in a fixed order: per frame its
/// clip, its points and its window terms (where it is a window centre), then every
/// measurement, each value as its 4 little-endian bytes.
fn plan_hash(m: &Manifest, rows: &FrameRows, meas: &[f32]) -> u64 {
    /// Bytes gathered before each checksum update.
    const CHUNK: usize = 1 << 20;
    let mut d = CRC64.digest();
    d.update(&serde_json::to_vec(m).unwrap_or_default());
    let mut buf: Vec<u8> = Vec::with_capacity(CHUNK + 256);
    let put = |buf: &mut Vec<u8>, v: u32| buf.extend_from_slice(&v.to_le_bytes());
    for (g, pts) in rows.points.iter().enumerate() {
        put(&mut buf, rows.clip_of[g]);
        for p in pts {
            for v in [p.x, p.y, p.z] {
                put(&mut buf, v.to_bits());
            }
        }
        if let Some(t) = rows.terms[g] {
            for v in [t.mx, t.mz, t.sq] {
                put(&mut buf, v.to_bits());
            }
        }
        if buf.len() >= CHUNK {
            d.update(&buf);
            buf.clear();
        }
    }
    for part in meas.chunks(CHUNK / 4) {
        for &v in part {
            put(&mut buf, v.to_bits());
        }
        d.update(&buf);
        buf.clear();
    }
    d.update(&buf);
    d.finalize()
}

/// Path of tile `index` in job folder `job`.
pub fn tile_path(job: &Path, index: usize) -> PathBuf {
    job.join(TILES_DIR).join(format!("tile-{index:05}.bin"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_every_kernel_tile_once() {
        for (frames, band, tile) in [(1000, 256, 256), (1000, 512, 64), (300, 64, 8)] {
            let p = BuildParams {
                tile,
                ..Default::default()
            };
            let m = Manifest {
                format: JOB_FORMAT.into(),
                version: JOB_VERSION,
                plan: format!("{:016x}", 1),
                params: p,
                roles: Default::default(),
                clips: vec![],
                frames,
                windows: 0,
                band,
                store_version: STORE_VERSION,
                tiles: tile_list(frames, band),
            };
            let b = frames.div_ceil(band);
            assert_eq!(m.tiles.len(), b * (b + 1) / 2);
            let mut all: Vec<_> = m.tiles.iter().flat_map(|t| m.kernels(t)).collect();
            all.sort();
            assert_eq!(all, crate::graph::search::all_kernels(frames, &p));
        }
    }

    #[test]
    fn newer_and_malformed_manifests_are_refused_by_name() {
        let path = Path::new("JOB/manifest.json");
        let e = parse_manifest(
            br#"{"format":"figurine-graph-job","version":99,"whatever":1}"#,
            path,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("manifest.json") && e.contains("newer figurine"),
            "{e}"
        );
        for bad in [
            &b"{"[..],
            br#"{"format":"parquet","version":1}"#,
            br#"{"format":"figurine-graph-job","version":1}"#,
        ] {
            let e = parse_manifest(bad, path).unwrap_err().to_string();
            assert!(e.contains("manifest.json"), "{e}");
        }
    }
}
