//! Building the graph: the O(N²) posture search, tiled, on both cores, streaming.
//!
//! All clips' frames are concatenated (N frames). For every pair of window centres (i, j) the
//! posture distance of eq. 1 needs three cross sums over the windows' 35 × 16 point pairs,
//! `Σ (x x' + z z')`, `Σ (x z' − z x')`, `Σ y y'`. They are sums along a diagonal of the
//! frame-pair dot-product matrix, so a tile of T × T window pairs is computed as:
//! 1. frame-pair dot products for the tile's (T + 36)² frame pairs: three small f32 matrix
//!    products over a structure-of-arrays layout (matrixmultiply's SIMD kernels);
//! 2. 35-long diagonal running sums (restarted every [`RESTART`] rows against f32 drift);
//! 3. the closed form of [`super::posture`] per pair, then 3 × 3 local minima of the distance.
//!
//! Only local minima leave a tile (with a one-window halo so tile borders see neighbours), and
//! only tiles on or above the diagonal are computed (the distance is symmetric). Memory is
//! O(N + tiles in flight × T² + candidates), never N × N. Tiles run on rayon's pool with an
//! indicatif progress bar (stderr). Afterwards distances are normalised with the global min/max
//! (d̂ = (d − d_min)/(d_max − d_min), correlation 1 − d̂), thresholded with T_MG, and the
//! survivors get their Gaussian-smoothed style similarity (eq. 2) — the paper's suggested
//! optimisation of evaluating LMA only at the pose-based transitions.

use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use ndarray::linalg::general_mat_mul;
use ndarray::{ArrayView2, ArrayViewMut2};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::graph::{ClipEntry, Edge, MotionGraph, GRAPH_VERSION};
use super::lma::{clip_measurements, MEASUREMENTS};
use super::posture::{window_terms, WindowTerms, POINTS};
use super::roles::Role;
use super::source::GraphClip;
use super::style::{
    gauss_weights, pearson, similarity, ComponentWeights, Standardiser, SMOOTH_HALF,
};
use super::{GraphError, HALF, WINDOW};

/// Rows between exact recomputations of the diagonal running sums.
pub const RESTART: usize = 32;
/// Coordinates per frame in the kernel's xz layout: x (16) then z (16).
const XZ: usize = 2 * Role::COUNT;

/// Parameters of a graph build.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BuildParams {
    /// Posture-correlation threshold T_MG ∈ [0, 1] (paper: 0.9).
    pub t_mg: f32,
    /// Style-correlation threshold T_LMA ∈ [0, 1] (paper: 0.8).
    pub t_lma: f32,
    /// LMA component weights of the style similarity.
    pub weights: ComponentWeights,
    /// Minimum distance in frames between two windows of the same clip for a transition.
    pub min_gap: usize,
    /// Tile side in windows (memory per tile ≈ 3 × (tile + 36)² × 4 bytes).
    pub tile: usize,
    /// Show a progress bar on stderr.
    pub progress: bool,
}

impl Default for BuildParams {
    fn default() -> Self {
        BuildParams {
            t_mg: 0.9,
            t_lma: 0.8,
            weights: ComponentWeights::default(),
            min_gap: WINDOW,
            tile: 256,
            progress: false,
        }
    }
}

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
    /// Seconds spent on style correlation of the candidates.
    pub style_seconds: f64,
}

/// One local minimum of the posture distance: window centres (global frames), distance m².
#[derive(Debug, Clone, Copy, PartialEq)]
struct Candidate {
    i: u32,
    j: u32,
    d: f32,
}

/// Frame-level layout of the concatenated library, structure of arrays (row-major, f32).
struct Layout {
    /// Clip index of every global frame.
    clip_of: Vec<u32>,
    /// Window terms of every global frame that is a valid window centre.
    terms: Vec<Option<WindowTerms>>,
    /// Per frame: x of the 16 role points, then z (`N × 32`).
    xz: Vec<f32>,
    /// Per frame: z of the 16 role points, then −x (`N × 32`): `xz · zx` = Σ x z' − z x'.
    zx: Vec<f32>,
    /// Per frame: y of the 16 role points (`N × 16`).
    y: Vec<f32>,
}

impl Layout {
    fn new(clips: &[GraphClip]) -> Layout {
        let n: usize = clips.iter().map(|c| c.len()).sum();
        let mut l = Layout {
            clip_of: Vec::with_capacity(n),
            terms: Vec::with_capacity(n),
            xz: Vec::with_capacity(n * XZ),
            zx: Vec::with_capacity(n * XZ),
            y: Vec::with_capacity(n * Role::COUNT),
        };
        for (ci, c) in clips.iter().enumerate() {
            let t = window_terms(&c.points);
            for (f, p) in c.points.iter().enumerate() {
                l.clip_of.push(ci as u32);
                l.terms
                    .push(f.checked_sub(HALF).and_then(|w| t.get(w)).copied());
                l.xz.extend(p.iter().map(|v| v.x));
                l.xz.extend(p.iter().map(|v| v.z));
                l.zx.extend(p.iter().map(|v| v.z));
                l.zx.extend(p.iter().map(|v| -v.x));
                l.y.extend(p.iter().map(|v| v.y));
            }
        }
        l
    }

    fn len(&self) -> usize {
        self.clip_of.len()
    }
}

/// Frame-pair dot products for rows `r0..r0+nr` × columns `c0..c0+nc` (global frames):
/// (Σ xx'+zz', Σ xz'−zx', Σ yy'), each `nr × nc` row-major. Three small matrix products
/// (matrixmultiply's kernels, which pick AVX2/FMA at run time when the CPU has them).
fn frame_products(l: &Layout, r0: usize, nr: usize, c0: usize, nc: usize) -> [Vec<f32>; 3] {
    fn view(v: &[f32], w: usize, at: usize, rows: usize) -> Option<ArrayView2<'_, f32>> {
        ArrayView2::from_shape((rows, w), v.get(at * w..(at + rows) * w)?).ok()
    }
    let mut out = [
        vec![0.0f32; nr * nc],
        vec![0.0f32; nr * nc],
        vec![0.0f32; nr * nc],
    ];
    let jobs = [
        (&l.xz, &l.xz, XZ),
        (&l.xz, &l.zx, XZ),
        (&l.y, &l.y, Role::COUNT),
    ];
    for ((left, right, w), o) in jobs.into_iter().zip(out.iter_mut()) {
        let (Some(a), Some(b)) = (view(left, w, r0, nr), view(right, w, c0, nc)) else {
            continue;
        };
        if let Ok(mut c) = ArrayViewMut2::from_shape((nr, nc), o.as_mut_slice()) {
            general_mat_mul(1.0, &a, &b.t(), 0.0, &mut c);
        }
    }
    out
}

/// Evaluates one tile of window centres `i0..i1` × `j0..j1` and returns its local minima, the
/// (min, max) distance over its valid pairs above the diagonal, and their number.
///
/// Every inner loop runs over a contiguous row with no data-dependent branch, so it vectorises;
/// invalid column centres carry an infinite `sq` term, which makes their distance infinite.
fn tile(
    l: &Layout,
    p: &BuildParams,
    i0: usize,
    i1: usize,
    j0: usize,
    j1: usize,
) -> (Vec<Candidate>, f32, f32, u64) {
    let n = l.len();
    // Centres with a one-window halo, restricted to where a full window fits.
    let lo = |a: usize| a.saturating_sub(1).max(HALF);
    let hi = |b: usize| (b + 1).min(n.saturating_sub(HALF));
    let (ri0, ri1, cj0, cj1) = (lo(i0), hi(i1), lo(j0), hi(j1));
    if ri0 >= ri1 || cj0 >= cj1 {
        return (Vec::new(), f32::INFINITY, f32::NEG_INFINITY, 0);
    }
    let (nr, nc) = (ri1 - ri0, cj1 - cj0);
    let (fr, fc) = (nr + WINDOW - 1, nc + WINDOW - 1);
    let [pa, pb, py] = frame_products(l, ri0 - HALF, fr, cj0 - HALF, fc);
    let stride = fc;
    // Column terms, structure of arrays.
    let w = POINTS as f32;
    let mut cmx = vec![0.0f32; nc];
    let mut cmz = vec![0.0f32; nc];
    let mut csq = vec![f32::INFINITY; nc];
    for c in 0..nc {
        if let Some(t) = l.terms[cj0 + c] {
            cmx[c] = t.mx;
            cmz[c] = t.mz;
            csq[c] = t.sq;
        }
    }
    let mut sums = [vec![0.0f32; nc], vec![0.0f32; nc], vec![0.0f32; nc]];
    let mut next = sums.clone();
    let mut d = vec![f32::INFINITY; nr * nc];
    let (mut dmin, mut dmax) = (f32::INFINITY, f32::NEG_INFINITY);
    let mut pairs = 0u64;
    for r in 0..nr {
        for (m, (s, nx)) in [&pa, &pb, &py].iter().zip(sums.iter().zip(next.iter_mut())) {
            if r % RESTART == 0 {
                nx.iter_mut().for_each(|v| *v = 0.0);
                for k in 0..WINDOW {
                    let src = &m[(r + k) * stride + k..(r + k) * stride + k + nc];
                    nx.iter_mut().zip(src).for_each(|(v, x)| *v += x);
                }
            } else {
                nx[0] = (0..WINDOW).map(|k| m[(r + k) * stride + k]).sum();
                let add = &m[(r + WINDOW - 1) * stride + WINDOW..][..nc - 1];
                let sub = &m[(r - 1) * stride..][..nc - 1];
                for (((v, s), a), b) in nx[1..].iter_mut().zip(&s[..nc - 1]).zip(add).zip(sub) {
                    *v = s + a - b;
                }
            }
        }
        std::mem::swap(&mut sums, &mut next);
        let gi = ri0 + r;
        let Some(ti) = l.terms[gi] else { continue };
        let row = &mut d[r * nc..(r + 1) * nc];
        let cols = cmx.iter().zip(&cmz).zip(&csq);
        let s = sums[0].iter().zip(&sums[1]).zip(&sums[2]);
        for (out, (((sa, sb), syy), ((mx, mz), sq))) in row.iter_mut().zip(s.zip(cols)) {
            let a = sa - w * (ti.mx * mx + ti.mz * mz);
            let b = sb - w * (ti.mx * mz - ti.mz * mx);
            let v = (ti.sq + sq - 2.0 * (syy + (a * a + b * b).sqrt())) / w;
            *out = v.max(0.0);
        }
        // Windows of the same clip closer than the gap are no transitions.
        let ci = l.clip_of[gi];
        let near = gi.saturating_sub(p.min_gap - 1).max(cj0)..(gi + p.min_gap).min(cj1);
        for gj in near {
            if l.clip_of[gj] == ci {
                row[gj - cj0] = f32::INFINITY;
            }
        }
        if (i0..i1).contains(&gi) {
            let c_lo = j0.max(gi + 1).max(cj0) - cj0;
            let c_hi = j1.min(cj1).saturating_sub(cj0);
            if c_lo < c_hi {
                let (lo, hi, cnt) = row_stats(&row[c_lo..c_hi]);
                dmin = fmin(dmin, lo);
                dmax = fmax(dmax, hi);
                pairs += cnt;
            }
        }
    }
    // 3 × 3 minimum filter, separable: along rows, then across rows.
    let mut hmin = vec![f32::INFINITY; nr * nc];
    for r in 0..nr {
        let row = &d[r * nc..(r + 1) * nc];
        let out = &mut hmin[r * nc..(r + 1) * nc];
        out[0] = fmin(row[0], row.get(1).copied().unwrap_or(f32::INFINITY));
        if nc >= 2 {
            out[nc - 1] = fmin(row[nc - 1], row[nc - 2]);
        }
        if nc >= 3 {
            let three = row[..nc - 2].iter().zip(&row[1..nc - 1]).zip(&row[2..]);
            for (o, ((a, b), c)) in out[1..nc - 1].iter_mut().zip(three) {
                *o = fmin(fmin(*a, *b), *c);
            }
        }
    }
    let mut out = Vec::new();
    let get = |r: usize, c: usize| d[r * nc + c];
    for r in 0..nr {
        let gi = ri0 + r;
        if !(i0..i1).contains(&gi) {
            continue;
        }
        let up = if r > 0 {
            &hmin[(r - 1) * nc..r * nc]
        } else {
            &hmin[r * nc..(r + 1) * nc]
        };
        let down = if r + 1 < nr {
            &hmin[(r + 1) * nc..(r + 2) * nc]
        } else {
            &hmin[r * nc..(r + 1) * nc]
        };
        let mid = &hmin[r * nc..(r + 1) * nc];
        let row = &d[r * nc..(r + 1) * nc];
        let mut around = vec![0.0f32; nc];
        for (m, ((a, b), c)) in around.iter_mut().zip(up.iter().zip(mid).zip(down)) {
            *m = fmin(fmin(*a, *b), *c);
        }
        for (c, (&v, &m)) in row.iter().zip(&around).enumerate() {
            if v <= m && v < f32::INFINITY {
                // Rare: v is a (possibly tied) minimum. Ties go to the earlier cell in raster order.
                let gj = cj0 + c;
                if !(j0..j1).contains(&gj) || gi >= gj {
                    continue;
                }
                let tied_before = (c > 0 && get(r, c - 1) == v)
                    || (r > 0
                        && (c.saturating_sub(1)..(c + 2).min(nc)).any(|cc| get(r - 1, cc) == v));
                if !tied_before {
                    out.push(Candidate {
                        i: gi as u32,
                        j: gj as u32,
                        d: v,
                    });
                }
            }
        }
    }
    (out, dmin, dmax, pairs)
}

/// Minimum without NaN handling (the distances are never NaN), so loops vectorise.
#[inline(always)]
fn fmin(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// Maximum without NaN handling.
#[inline(always)]
fn fmax(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// (min, max over finite values, number of finite values) of a row, in 8 independent lanes.
fn row_stats(row: &[f32]) -> (f32, f32, u64) {
    const L: usize = 8;
    let mut lo = [f32::INFINITY; L];
    let mut hi = [f32::NEG_INFINITY; L];
    let mut cnt = [0u32; L];
    let chunks = row.chunks_exact(L);
    let rest = chunks.remainder();
    for ch in chunks {
        for k in 0..L {
            let v = ch[k];
            let finite = v < f32::INFINITY;
            lo[k] = fmin(lo[k], v);
            hi[k] = fmax(hi[k], if finite { v } else { f32::NEG_INFINITY });
            cnt[k] += u32::from(finite);
        }
    }
    let mut out = (
        lo.iter().copied().fold(f32::INFINITY, fmin),
        hi.iter().copied().fold(f32::NEG_INFINITY, fmax),
        cnt.iter().map(|&c| c as u64).sum::<u64>(),
    );
    for &v in rest {
        if v < f32::INFINITY {
            out = (fmin(out.0, v), fmax(out.1, v), out.2 + 1);
        }
    }
    out
}

/// Builds the motion graph of `clips` (all at 30 fps, each at least one window long).
pub fn build_graph(
    clips: &[GraphClip],
    p: &BuildParams,
) -> Result<(MotionGraph, BuildStats), GraphError> {
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
    let mut stats = BuildStats::default();
    let t0 = Instant::now();
    let meas: Vec<Vec<f32>> = clips
        .par_iter()
        .map(|c| clip_measurements(&c.points))
        .collect();
    let meas: Vec<f32> = meas.concat();
    let standardiser = Standardiser::fit(&meas);
    let style = standardiser.style_vectors(&meas);
    stats.lma_seconds = t0.elapsed().as_secs_f64();

    let t1 = Instant::now();
    let layout = Layout::new(clips);
    let n = layout.len();
    stats.frames = n;
    let t = p.tile.max(8);
    let nt = n.div_ceil(t);
    let jobs: Vec<(usize, usize)> = (0..nt).flat_map(|a| (a..nt).map(move |b| (a, b))).collect();
    let bar = progress_bar(p.progress, jobs.len() as u64, "posture correlation");
    let (cands, dmin, dmax, pairs) = jobs
        .par_iter()
        .map(|&(a, b)| {
            let r = tile(
                &layout,
                p,
                a * t,
                ((a + 1) * t).min(n),
                b * t,
                ((b + 1) * t).min(n),
            );
            bar.inc(1);
            r
        })
        .fold(
            || (Vec::new(), f32::INFINITY, f32::NEG_INFINITY, 0u64),
            |mut acc, (c, lo, hi, np)| {
                acc.0.extend(c);
                (acc.0, acc.1.min(lo), acc.2.max(hi), acc.3 + np)
            },
        )
        .reduce(
            || (Vec::new(), f32::INFINITY, f32::NEG_INFINITY, 0u64),
            |mut a, b| {
                a.0.extend(b.0);
                (a.0, a.1.min(b.1), a.2.max(b.2), a.3 + b.3)
            },
        );
    bar.finish_and_clear();
    stats.posture_seconds = t1.elapsed().as_secs_f64();
    stats.local_minima = cands.len();
    stats.pairs = pairs;

    let t2 = Instant::now();
    // Window index of each global frame (centre), for the style vectors.
    let mut window_of = vec![u32::MAX; n];
    let mut frame_start = Vec::with_capacity(clips.len());
    let (mut f0, mut w0) = (0usize, 0usize);
    for c in clips {
        frame_start.push(f0);
        for w in 0..=c.len() - WINDOW {
            window_of[f0 + w + HALF] = (w0 + w) as u32;
        }
        f0 += c.len();
        w0 += c.len() - WINDOW + 1;
    }
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
    let bar = progress_bar(p.progress, cands.len() as u64, "style correlation");
    let mut edges: Vec<Edge> = cands
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
    stats.style_seconds = t2.elapsed().as_secs_f64();

    let graph = MotionGraph {
        version: GRAPH_VERSION,
        clips: clips
            .iter()
            .zip(&frame_start)
            .map(|(c, &start)| ClipEntry {
                name: c.clip.name.clone(),
                path: c.path.to_string_lossy().into_owned(),
                start: start as u32,
                frames: c.len() as u32,
                rig: c.rig_key(),
                scale: c.scale,
            })
            .collect(),
        params: *p,
        dmin,
        dmax,
        edges,
        standardiser,
        measurements: meas,
        roles: Default::default(),
    };
    Ok((graph, stats))
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
        let layout = Layout::new(clips);
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
