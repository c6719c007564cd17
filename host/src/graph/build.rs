//! Building the graph on one machine: features, the tiled posture search, then assembly.
//!
//! [`build_graph`] computes the LMA measurements and window terms of every clip, runs every
//! kernel tile of [`super::search`] on rayon's pool with an indicatif progress bar (stderr),
//! and [`assemble`]s the result. Memory is O(N + tiles in flight × T² + candidates), never
//! N × N. The distributed path ([`super::plan`], [`super::tile`], [`super::merge`]) runs the
//! same kernel tiles in other processes and calls the same [`assemble`], so its graph file is
//! byte-identical.
//!
//! Assembly normalises distances with the global min/max (d̂ = (d − d_min)/(d_max − d_min),
//! correlation 1 − d̂), thresholds with T_MG, and gives the survivors their Gaussian-smoothed
//! style similarity (eq. 2) — the paper's suggested optimisation of evaluating LMA only at the
//! pose-based transitions.

use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::graph::{BuildParams, ClipEntry, Edge, MotionGraph, GRAPH_VERSION};
use super::lma::{clip_measurements, MEASUREMENTS};
use super::search::{all_kernels, search, Found, FrameRows, Layout};
use super::source::GraphClip;
use super::style::{gauss_weights, pearson, similarity, Standardiser, SMOOTH_HALF};
use super::{cpu_seconds, GraphError, HALF, WINDOW};

/// Timings and counts of a build, for reports and benchmarks.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BuildStats {
    /// Frames analysed.
    pub frames: usize,
    /// Window pairs whose posture distance was evaluated.
    pub pairs: u64,
    /// Local minima found (before T_MG).
    pub local_minima: usize,
    /// Seconds spent on LMA features.
    pub lma_seconds: f64,
    /// Seconds spent on the posture search.
    pub posture_seconds: f64,
    /// CPU seconds of the posture search, all threads (NaN where /proc is missing): on a
    /// shared machine this compares with a tile's search where wall time does not.
    pub posture_cpu_seconds: f64,
    /// Seconds spent on style correlation of the candidates.
    pub style_seconds: f64,
}

/// Builds the motion graph of `clips` (all at 30 fps, each at least one window long).
pub fn build_graph(
    clips: &[GraphClip],
    p: &BuildParams,
) -> Result<(MotionGraph, BuildStats), GraphError> {
    check_clips(clips)?;
    let mut stats = BuildStats::default();
    let t0 = Instant::now();
    let meas = measurements(clips);
    stats.lma_seconds = t0.elapsed().as_secs_f64();

    let t1 = Instant::now();
    let c1 = cpu_seconds().unwrap_or(f64::NAN);
    let rows = FrameRows::from_clips(clips);
    let n = rows.len();
    stats.frames = n;
    let layout = Layout::new(&rows);
    drop(rows);
    let kernels = all_kernels(n, p);
    let bar = progress_bar(p.progress, kernels.len() as u64, "posture correlation");
    let found = search(&layout, &layout, n, p, &kernels, &bar);
    bar.finish_and_clear();
    drop(layout);
    stats.posture_seconds = t1.elapsed().as_secs_f64();
    stats.posture_cpu_seconds = cpu_seconds().unwrap_or(f64::NAN) - c1;
    stats.local_minima = found.candidates.len();
    stats.pairs = found.pairs;

    let t2 = Instant::now();
    let graph = assemble(clip_entries(clips), meas, &found, p);
    stats.style_seconds = t2.elapsed().as_secs_f64();
    Ok((graph, stats))
}

/// Refuses an empty library or a clip shorter than one window.
pub fn check_clips(clips: &[GraphClip]) -> Result<(), GraphError> {
    if clips.is_empty() {
        return Err(GraphError::Invalid(
            "no clip is at least one window (35 frames at 30 fps) long; nothing to build".into(),
        ));
    }
    if let Some(c) = clips.iter().find(|c| c.len() < WINDOW) {
        return Err(GraphError::Invalid(format!(
            "{}: shorter than one window ({} frames)",
            c.path.display(),
            c.len()
        )));
    }
    Ok(())
}

/// Raw LMA measurements of every window of `clips` (`windows × 114`, clip order).
pub fn measurements(clips: &[GraphClip]) -> Vec<f32> {
    let meas: Vec<Vec<f32>> = clips
        .par_iter()
        .map(|c| clip_measurements(&c.points))
        .collect();
    meas.concat()
}

/// The graph's clip table: names, paths, first global frame, length, rig, scale.
pub fn clip_entries(clips: &[GraphClip]) -> Vec<ClipEntry> {
    let mut start = 0u32;
    clips
        .iter()
        .map(|c| {
            let e = ClipEntry {
                name: c.clip.name.clone(),
                path: c.path.to_string_lossy().into_owned(),
                start,
                frames: c.len() as u32,
                rig: c.rig_key(),
                scale: c.scale,
            };
            start += c.len() as u32;
            e
        })
        .collect()
}

/// The graph from the search's result: distances normalised by the global range, T_MG, the
/// smoothed style similarity of the survivors, edges in `(from, to)` order.
///
/// `measurements` are the raw LMA rows of every window (`windows × 114`, clip order). The
/// graph records `p` with `progress` off: whether a bar was shown is no property of the graph,
/// and the single-machine and distributed builds must write the same bytes.
pub fn assemble(
    clips: Vec<ClipEntry>,
    measurements: Vec<f32>,
    found: &Found,
    p: &BuildParams,
) -> MotionGraph {
    let n: usize = clips.iter().map(|c| c.frames as usize).sum();
    let standardiser = Standardiser::fit(&measurements);
    let style = standardiser.style_vectors(&measurements);
    // Window index of each global frame (centre), for the style vectors.
    let mut window_of = vec![u32::MAX; n];
    let mut w0 = 0usize;
    for c in &clips {
        let (f0, len) = (c.start as usize, c.frames as usize);
        for w in 0..(len + 1).saturating_sub(WINDOW) {
            window_of[f0 + w + HALF] = (w0 + w) as u32;
        }
        w0 += (len + 1).saturating_sub(WINDOW);
    }
    let (dmin, dmax) = (found.dmin, found.dmax);
    let span = (dmax - dmin).max(f32::MIN_POSITIVE);
    let weights = p.weights.normalised();
    let gauss = gauss_weights();
    let style_at = |wi: u32, wj: u32| -> f32 {
        let (a, b) = (wi as usize * MEASUREMENTS, wj as usize * MEASUREMENTS);
        similarity(
            pearson(&style[a..a + MEASUREMENTS], &style[b..b + MEASUREMENTS]),
            &weights,
        )
    };
    let bar = progress_bar(
        p.progress,
        found.candidates.len() as u64,
        "style correlation",
    );
    let mut edges: Vec<Edge> = found
        .candidates
        .par_iter()
        .filter_map(|c| {
            bar.inc(1);
            let posture = 1.0 - (c.d - dmin) / span;
            if posture < p.t_mg {
                return None;
            }
            let (mut num, mut den) = (0.0f32, 0.0f32);
            for (k, g) in gauss.iter().enumerate() {
                let off = k as i64 - SMOOTH_HALF as i64;
                let (fi, fj) = (c.i as i64 + off, c.j as i64 + off);
                if fi < 0 || fj < 0 || fi as usize >= n || fj as usize >= n {
                    continue;
                }
                let (wi, wj) = (window_of[fi as usize], window_of[fj as usize]);
                if wi == u32::MAX || wj == u32::MAX {
                    continue;
                }
                num += g * style_at(wi, wj);
                den += g;
            }
            Some(Edge {
                from: c.i,
                to: c.j,
                posture,
                style: if den > 0.0 { num / den } else { 0.0 },
            })
        })
        .collect();
    bar.finish_and_clear();
    edges.sort_by_key(|e| (e.from, e.to));
    MotionGraph {
        version: GRAPH_VERSION,
        clips,
        params: BuildParams {
            progress: false,
            ..*p
        },
        dmin,
        dmax,
        edges,
        standardiser,
        measurements,
        roles: Default::default(),
    }
}

/// A progress bar with ETA on stderr (hidden when `show` is false).
pub fn progress_bar(show: bool, len: u64, msg: &'static str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template(
        "{msg:>20} [{elapsed_precise}] {wide_bar} {pos}/{len} ETA {eta}",
    ) {
        bar.set_style(style);
    }
    bar.set_message(msg);
    bar
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::graph::lma::tests::synthetic;
    use crate::graph::posture::align_windows;
    use crate::graph::roles::Role;
    use crate::graph::roles::RoleMap;
    use crate::motion::Clip;

    pub(crate) fn fake_clip(name: &str, points: Vec<[glam::Vec3; Role::COUNT]>) -> GraphClip {
        GraphClip {
            clip: Clip {
                name: name.into(),
                skeleton: Default::default(),
                frame_time: 1.0 / 30.0,
                frames: vec![],
            },
            path: format!("{name}.bvh").into(),
            roles: RoleMap {
                joints: [0; Role::COUNT],
            },
            scale: 1.0,
            points,
        }
    }

    /// Brute force: every valid pair's distance through the reference implementation.
    fn brute(clips: &[GraphClip], p: &BuildParams) -> Vec<(u32, u32, f32)> {
        let layout = FrameRows::from_clips(clips);
        let all: Vec<&[glam::Vec3; Role::COUNT]> =
            clips.iter().flat_map(|c| c.points.iter()).collect();
        let n = all.len();
        let valid = |f: usize| layout.terms[f].is_some();
        let mut out = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                if !valid(i)
                    || !valid(j)
                    || (layout.clip_of[i] == layout.clip_of[j] && j - i < p.min_gap)
                {
                    continue;
                }
                let a: Vec<_> = all[i - HALF..=i + HALF].iter().map(|x| **x).collect();
                let b: Vec<_> = all[j - HALF..=j + HALF].iter().map(|x| **x).collect();
                out.push((i as u32, j as u32, align_windows(&a, &b).1));
            }
        }
        out
    }

    #[test]
    fn tiled_search_matches_brute_force_across_tile_sizes() {
        let clips = vec![
            fake_clip("a", synthetic(70, 0.8, 0.3)),
            fake_clip("b", synthetic(60, 0.2, 0.6)),
            fake_clip("c", synthetic(36, 1.5, 0.1)),
        ];
        let p = BuildParams {
            t_mg: 0.0,
            t_lma: 0.0,
            ..Default::default()
        };
        let reference = brute(&clips, &p);
        let rmin = reference.iter().map(|r| r.2).fold(f32::INFINITY, f32::min);
        let rmax = reference
            .iter()
            .map(|r| r.2)
            .fold(f32::NEG_INFINITY, f32::max);
        let mut results = Vec::new();
        for tile_size in [8, 19, 256] {
            let (g, st) = build_graph(
                &clips,
                &BuildParams {
                    tile: tile_size,
                    ..p
                },
            )
            .unwrap();
            assert_eq!(st.pairs as usize, reference.len(), "tile {tile_size}");
            assert!((g.dmin - rmin).abs() < 1e-3 && (g.dmax - rmax).abs() < 1e-3 * rmax);
            // Every edge is a true local minimum of the reference distances.
            let get = |i: u32, j: u32| reference.iter().find(|r| r.0 == i && r.1 == j).map(|r| r.2);
            for e in &g.edges {
                let v = get(e.from, e.to).unwrap();
                for (di, dj) in [(-1i64, 0i64), (1, 0), (0, 1), (0, -1), (1, 1), (-1, -1)] {
                    if let Some(w) = get((e.from as i64 + di) as u32, (e.to as i64 + dj) as u32) {
                        assert!(
                            w >= v - 1e-3,
                            "tile {tile_size} ({},{}) {v} has neighbour {w} at {di},{dj}",
                            e.from,
                            e.to
                        );
                    }
                }
            }
            results.push(g.edges.iter().map(|e| (e.from, e.to)).collect::<Vec<_>>());
        }
        assert_eq!(results[0], results[1]);
        assert_eq!(results[1], results[2]);
        assert!(!results[0].is_empty());
    }

    #[test]
    fn same_clip_pairs_respect_min_gap() {
        let clips = vec![fake_clip("a", synthetic(150, 0.0, 0.4))];
        let (g, _) = build_graph(
            &clips,
            &BuildParams {
                t_mg: 0.5,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(g.edges.iter().all(|e| e.to - e.from >= WINDOW as u32));
        // A periodic motion (period ≈ 31 frames) links to itself one period later.
        assert!(!g.edges.is_empty());
    }
}
