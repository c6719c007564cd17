//! `figurine graph merge JOB --out G.bin`: every tile of a job into the graph file.
//!
//! Merge first checks the whole job: the manifest, the feature store, and that every tile file
//! exists, belongs to this plan and is intact. A job with missing tiles is refused with the list
//! of missing files (the array tasks to re-run); a damaged or foreign tile is refused by name.
//! Then it joins the tiles' candidates, reads the LMA measurements from the store (only that
//! column, only its window rows: [`super::ipc_floats`]) and calls the same [`assemble`] as
//! `graph build`, so the file is byte-identical to a single-machine build of the same clips and
//! options.
//!
//! Tiles are read twice: headers first (the library-wide distance range), then the candidates,
//! keeping only those that pass T_MG. Memory is therefore the edges (12 bytes per candidate
//! kept, then the graph's edges), the measurements (456 bytes per window) and the style vectors
//! of assembly, not the local minima; time grows with the local minima read and the edges
//! kept (style similarity).

use std::path::Path;
use std::time::Instant;

use super::build::assemble;
use super::graph::MotionGraph;
use super::plan::{read_manifest, tile_path, STORE_FILE};
use super::search::{Candidate, Found};
use super::store::Store;
use super::tile::{read_tile, read_tile_header};
use super::GraphError;

/// Missing tile files listed by name in an error before the rest are only counted.
pub const LISTED_MISSING: usize = 20;

/// What a merge did.
#[derive(Debug, Clone, Default)]
pub struct MergeStats {
    /// Tiles merged.
    pub tiles: usize,
    /// Window pairs the tiles evaluated.
    pub pairs: u64,
    /// Local minima the tiles found.
    pub local_minima: usize,
    /// Seconds reading and checking tiles, and reading the measurements from the store.
    pub read_seconds: f64,
    /// Bytes read from the feature store for the measurements.
    pub store_bytes_read: u64,
    /// Seconds assembling the graph (style similarity of the survivors).
    pub assemble_seconds: f64,
}

/// Merges job folder `job` into a graph (not yet saved).
pub fn merge_job(job: &Path) -> Result<(MotionGraph, MergeStats), GraphError> {
    let m = read_manifest(job)?;
    let store = Store::open(&job.join(STORE_FILE), m.plan_id(), m.frames)?;
    let missing: Vec<String> = m
        .tiles
        .iter()
        .map(|t| tile_path(job, t.index))
        .filter(|p| !p.is_file())
        .map(|p| p.display().to_string())
        .collect();
    if !missing.is_empty() {
        let more = missing.len().saturating_sub(LISTED_MISSING);
        let listed = missing[..missing.len().min(LISTED_MISSING)].join(", ");
        return Err(GraphError::Invalid(format!(
            "{} of {} tiles missing: {listed}{}; run `figurine graph tile {} --index I` for them",
            missing.len(),
            m.tiles.len(),
            if more > 0 {
                format!(" and {more} more")
            } else {
                String::new()
            },
            job.display()
        )));
    }
    let mut stats = MergeStats {
        tiles: m.tiles.len(),
        ..Default::default()
    };
    let t0 = Instant::now();
    // Pass 1, headers only: the library-wide distance range, so that pass 2 keeps only the
    // local minima that pass T_MG (memory grows with the edges, not with all local minima).
    let mut range = Found::empty();
    let mut minima = 0u64;
    for t in &m.tiles {
        let (f, count) = read_tile_header(&tile_path(job, t.index), &m, t)?;
        range = range.join(f);
        minima += count;
    }
    let (dmin, span) = (range.dmin, (range.dmax - range.dmin).max(f32::MIN_POSITIVE));
    // The same expression as `assemble`'s, so exactly the same candidates survive.
    let keep = |c: &Candidate| 1.0 - (c.d - dmin) / span >= m.params.t_mg;
    let mut found = range;
    for t in &m.tiles {
        let f = read_tile(&tile_path(job, t.index), &m, t, keep)?;
        found.candidates.extend(f.candidates);
    }
    // Tiles are disjoint and each sorted; one sort makes the order independent of tile order.
    let found = found.sorted();
    let (measurements, store_bytes_read) = store.measurements(m.windows)?;
    stats.store_bytes_read = store_bytes_read;
    stats.read_seconds = t0.elapsed().as_secs_f64();
    stats.pairs = found.pairs;
    stats.local_minima = minima as usize;
    let t1 = Instant::now();
    let mut g = assemble(m.clips, measurements, &found, &m.params);
    g.roles = m.roles;
    stats.assemble_seconds = t1.elapsed().as_secs_f64();
    Ok((g, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::build::{build_graph, tests::fake_clip};
    use crate::graph::lma::tests::synthetic;
    use crate::graph::plan::{plan_job, MANIFEST_FILE};
    use crate::graph::tile::{encode_tile, parse_tile, run_tile};
    use crate::graph::BuildParams;

    fn job(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("figurine-merge-{}-{name}", std::process::id()));
        std::fs::remove_dir_all(&d).ok();
        d
    }

    fn clips() -> Vec<crate::graph::GraphClip> {
        vec![
            fake_clip("a", synthetic(150, 0.8, 0.3)),
            fake_clip("b", synthetic(120, 0.2, 0.6)),
            fake_clip("c", synthetic(60, 1.5, 0.1)),
        ]
    }

    fn params() -> BuildParams {
        BuildParams {
            t_mg: 0.6,
            t_lma: 0.3,
            tile: 16,
            ..Default::default()
        }
    }

    fn bytes(g: &MotionGraph, dir: &Path, name: &str) -> Vec<u8> {
        let p = dir.join(name);
        g.save(&p).unwrap();
        std::fs::read(p).unwrap()
    }

    #[test]
    fn tiles_merge_to_the_bytes_of_the_single_machine_build() {
        let dir = job("same");
        let (built, _) = build_graph(&clips(), &params()).unwrap();
        assert!(!built.edges.is_empty());
        let planned = plan_job(&clips(), &Default::default(), &params(), 64, &dir).unwrap();
        assert_eq!(planned.manifest.tiles.len(), 21);
        // Reverse order, one tile again and twice at once: order and repetition change nothing.
        for i in (0..21).rev() {
            run_tile(&dir, i, false).unwrap();
        }
        let before = std::fs::read(tile_path(&dir, 5)).unwrap();
        std::thread::scope(|s| {
            let a = s.spawn(|| run_tile(&dir, 5, false).map(|_| ()));
            let b = s.spawn(|| run_tile(&dir, 5, false).map(|_| ()));
            assert!(a.join().unwrap().is_ok() && b.join().unwrap().is_ok());
        });
        assert_eq!(std::fs::read(tile_path(&dir, 5)).unwrap(), before);
        let (merged, st) = merge_job(&dir).unwrap();
        assert_eq!(st.tiles, 21);
        assert_eq!(bytes(&merged, &dir, "m.bin"), bytes(&built, &dir, "b.bin"));
        // Planning again gives the same plan: existing tiles stay valid.
        let again = plan_job(&clips(), &Default::default(), &params(), 64, &dir).unwrap();
        assert_eq!(again.manifest.plan, planned.manifest.plan);
        assert_eq!(again.stale_removed, 0);
        assert!(merge_job(&dir).is_ok());
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn missing_foreign_and_half_written_tiles_are_refused_by_name() {
        let dir = job("bad");
        let m = plan_job(&clips(), &Default::default(), &params(), 128, &dir)
            .unwrap()
            .manifest;
        for i in 0..m.tiles.len() {
            run_tile(&dir, i, false).unwrap();
        }
        // A tile that died half-way left only its temporary file: merge names the missing tile.
        let t1 = tile_path(&dir, 1);
        std::fs::rename(&t1, t1.with_file_name(".tile-00001.bin.host.1.tmp")).unwrap();
        let e = merge_job(&dir).err().unwrap().to_string();
        assert!(
            e.contains("1 of 6 tiles missing") && e.contains("tile-00001.bin"),
            "{e}"
        );
        run_tile(&dir, 1, false).unwrap();
        // A tile of another plan (same index) is foreign.
        let t2 = tile_path(&dir, 2);
        let mut t = parse_tile(&std::fs::read(&t2).unwrap(), &t2).unwrap();
        t.plan ^= 1;
        std::fs::write(&t2, encode_tile(&t)).unwrap();
        let e = merge_job(&dir).err().unwrap().to_string();
        assert!(
            e.contains("tile-00002.bin") && e.contains("another plan"),
            "{e}"
        );
        // A truncated tile.
        run_tile(&dir, 2, false).unwrap();
        let b = std::fs::read(&t2).unwrap();
        std::fs::write(&t2, &b[..b.len() - 5]).unwrap();
        let e = merge_job(&dir).err().unwrap().to_string();
        assert!(
            e.contains("tile-00002.bin") && e.contains("truncated"),
            "{e}"
        );
        // A truncated feature store.
        run_tile(&dir, 2, false).unwrap();
        let s = dir.join(STORE_FILE);
        let b = std::fs::read(&s).unwrap();
        std::fs::write(&s, &b[..b.len() / 2]).unwrap();
        let e = merge_job(&dir).err().unwrap().to_string();
        assert!(e.contains("features.arrow"), "{e}");
        let e = run_tile(&dir, 0, false).err().unwrap().to_string();
        assert!(e.contains("features.arrow"), "{e}");
        // A manifest from a newer figurine.
        let mp = dir.join(MANIFEST_FILE);
        let text = std::fs::read_to_string(&mp).unwrap();
        std::fs::write(&mp, text.replacen("\"version\": 1", "\"version\": 2", 1)).unwrap();
        let e = merge_job(&dir).err().unwrap().to_string();
        assert!(e.contains("manifest.json") && e.contains("newer"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
