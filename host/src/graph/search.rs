//! The O(N²) posture search: window pairs in square kernel tiles, local minima out.
//!
//! All clips' frames are concatenated (N frames). For every pair of window centres (i, j) the
//! posture distance of eq. 1 needs three cross sums over the windows' 35 × 16 point pairs,
//! `Σ (x x' + z z')`, `Σ (x z' − z x')`, `Σ y y'`. They are sums along a diagonal of the
//! frame-pair dot-product matrix, so a kernel tile of T × T window pairs is computed as:
//! 1. frame-pair dot products for the tile's (T + 36)² frame pairs: three small f32 matrix
//!    products over a structure-of-arrays layout (matrixmultiply's SIMD kernels);
//! 2. 35-long diagonal running sums (restarted every [`RESTART`] rows against f32 drift);
//! 3. the closed form of [`super::posture`] per pair, then 3 × 3 local minima of the distance.
//!
//! Only local minima leave a tile (with a one-window halo so tile borders see neighbours), and
//! only kernel tiles on or above the diagonal are computed (the distance is symmetric).
//!
//! A kernel tile's result depends only on its own rows and columns of the layout, never on
//! which other tiles run, in what order or on which machine of the same CPU kind: that is what
//! lets [`super::tile`] split the search across machines and still merge to the same bytes as
//! [`super::build::build_graph`]. A [`Layout`] therefore holds any contiguous range of global
//! frames (a band and its halo), not necessarily the whole library.

use std::ops::Range;

use glam::Vec3;
use indicatif::ProgressBar;
use ndarray::linalg::general_mat_mul;
use ndarray::{ArrayView2, ArrayViewMut2};
use rayon::prelude::*;

use super::graph::BuildParams;
use super::posture::{window_terms, WindowTerms, POINTS};
use super::roles::Role;
use super::source::GraphClip;
use super::{HALF, WINDOW};

/// Rows between exact recomputations of the diagonal running sums.
pub const RESTART: usize = 32;
/// Coordinates per frame in the kernel's xz layout: x (16) then z (16).
const XZ: usize = 2 * Role::COUNT;

/// One local minimum of the posture distance: window centres (global frames), distance m².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Earlier window centre (global frame).
    pub i: u32,
    /// Later window centre (global frame), `i < j`.
    pub j: u32,
    /// Posture distance of eq. 1, m² per point.
    pub d: f32,
}

/// What a set of kernel tiles found: local minima, the distance range and the pair count.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// Local minima, sorted by `(i, j)`.
    pub candidates: Vec<Candidate>,
    /// Smallest distance over the evaluated pairs, m² (∞ when there were none).
    pub dmin: f32,
    /// Largest finite distance over the evaluated pairs, m² (−∞ when there were none).
    pub dmax: f32,
    /// Window pairs evaluated.
    pub pairs: u64,
}

impl Found {
    /// Nothing found yet (the identity of [`Found::join`]).
    pub fn empty() -> Found {
        Found {
            candidates: Vec::new(),
            dmin: f32::INFINITY,
            dmax: f32::NEG_INFINITY,
            pairs: 0,
        }
    }

    /// Both results together (candidates unsorted until [`Found::sorted`]).
    pub fn join(mut self, other: Found) -> Found {
        self.candidates.extend(other.candidates);
        Found {
            candidates: self.candidates,
            dmin: fmin(self.dmin, other.dmin),
            dmax: fmax(self.dmax, other.dmax),
            pairs: self.pairs + other.pairs,
        }
    }

    /// The same result with candidates in `(i, j)` order, so it is independent of thread timing.
    pub fn sorted(mut self) -> Found {
        self.candidates.sort_unstable_by_key(|c| (c.i, c.j));
        self
    }
}

/// The per-frame inputs of the search for global frames `base .. base + len`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrameRows {
    /// First global frame held.
    pub base: usize,
    /// Clip index of every frame.
    pub clip_of: Vec<u32>,
    /// Role points of every frame, analysis metres.
    pub points: Vec<[Vec3; Role::COUNT]>,
    /// Window terms of every frame that is a window centre (computed over the whole clip).
    pub terms: Vec<Option<WindowTerms>>,
}

impl FrameRows {
    /// All frames of `clips`, concatenated (base 0).
    pub fn from_clips(clips: &[GraphClip]) -> FrameRows {
        let mut r = FrameRows::default();
        for (ci, c) in clips.iter().enumerate() {
            let t = window_terms(&c.points);
            for (f, p) in c.points.iter().enumerate() {
                r.clip_of.push(ci as u32);
                r.points.push(*p);
                r.terms
                    .push(f.checked_sub(HALF).and_then(|w| t.get(w)).copied());
            }
        }
        r
    }

    /// Number of frames held.
    pub fn len(&self) -> usize {
        self.clip_of.len()
    }

    /// Whether no frame is held.
    pub fn is_empty(&self) -> bool {
        self.clip_of.is_empty()
    }
}

/// The frames a band of window centres needs (its one-window halo and the windows around it),
/// clamped to the library's `n` frames.
pub fn band_frames(centres: Range<usize>, n: usize) -> Range<usize> {
    centres.start.saturating_sub(HALF + 1)..(centres.end + HALF + 1).min(n)
}

/// Frame-level layout of a range of the concatenated library, structure of arrays (row-major).
pub struct Layout {
    /// First global frame held.
    base: usize,
    /// Clip index of every frame held.
    clip_of: Vec<u32>,
    /// Window terms of every frame held that is a valid window centre.
    terms: Vec<Option<WindowTerms>>,
    /// Per frame: x of the 16 role points, then z (`len × 32`).
    xz: Vec<f32>,
    /// Per frame: z of the 16 role points, then −x (`len × 32`): `xz · zx` = Σ x z' − z x'.
    zx: Vec<f32>,
    /// Per frame: y of the 16 role points (`len × 16`).
    y: Vec<f32>,
}

impl Layout {
    /// The kernel's layout of `rows`.
    pub fn new(rows: &FrameRows) -> Layout {
        let n = rows.len();
        let mut l = Layout {
            base: rows.base,
            clip_of: rows.clip_of.clone(),
            terms: rows.terms.clone(),
            xz: Vec::with_capacity(n * XZ),
            zx: Vec::with_capacity(n * XZ),
            y: Vec::with_capacity(n * Role::COUNT),
        };
        for p in &rows.points {
            l.xz.extend(p.iter().map(|v| v.x));
            l.xz.extend(p.iter().map(|v| v.z));
            l.zx.extend(p.iter().map(|v| v.z));
            l.zx.extend(p.iter().map(|v| -v.x));
            l.y.extend(p.iter().map(|v| v.y));
        }
        l
    }

    /// Global frames held.
    pub fn frames(&self) -> Range<usize> {
        self.base..self.base + self.clip_of.len()
    }

    fn clip(&self, g: usize) -> u32 {
        self.clip_of[g - self.base]
    }

    fn term(&self, g: usize) -> Option<WindowTerms> {
        self.terms[g - self.base]
    }
}

/// Frame-pair dot products for global rows `r0..r0+nr` × columns `c0..c0+nc`:
/// (Σ xx'+zz', Σ xz'−zx', Σ yy'), each `nr × nc` row-major. Three small matrix products
/// (matrixmultiply's kernels, which pick AVX2/FMA at run time when the CPU has them).
fn frame_products(
    rows: &Layout,
    r0: usize,
    nr: usize,
    cols: &Layout,
    c0: usize,
    nc: usize,
) -> [Vec<f32>; 3] {
    fn view(v: &[f32], w: usize, at: usize, rows: usize) -> Option<ArrayView2<'_, f32>> {
        ArrayView2::from_shape((rows, w), v.get(at * w..(at + rows) * w)?).ok()
    }
    let mut out = [
        vec![0.0f32; nr * nc],
        vec![0.0f32; nr * nc],
        vec![0.0f32; nr * nc],
    ];
    let jobs = [
        (&rows.xz, &cols.xz, XZ),
        (&rows.xz, &cols.zx, XZ),
        (&rows.y, &cols.y, Role::COUNT),
    ];
    let (ra, ca) = (r0 - rows.base, c0 - cols.base);
    for ((left, right, w), o) in jobs.into_iter().zip(out.iter_mut()) {
        let (Some(a), Some(b)) = (view(left, w, ra, nr), view(right, w, ca, nc)) else {
            continue;
        };
        if let Ok(mut c) = ArrayViewMut2::from_shape((nr, nc), o.as_mut_slice()) {
            general_mat_mul(1.0, &a, &b.t(), 0.0, &mut c);
        }
    }
    out
}

/// Evaluates one kernel tile of window centres `i` × `j` (global, `n` frames in the library)
/// with row frames from `rows` and column frames from `cols`, which must hold
/// [`band_frames`] of the two ranges.
///
/// Every inner loop runs over a contiguous row with no data-dependent branch, so it vectorises;
/// invalid column centres carry an infinite `sq` term, which makes their distance infinite.
pub fn kernel_tile(
    rows: &Layout,
    cols: &Layout,
    n: usize,
    p: &BuildParams,
    i: Range<usize>,
    j: Range<usize>,
) -> Found {
    let (i0, i1, j0, j1) = (i.start, i.end, j.start, j.end);
    // Centres with a one-window halo, restricted to where a full window fits.
    let lo = |a: usize| a.saturating_sub(1).max(HALF);
    let hi = |b: usize| (b + 1).min(n.saturating_sub(HALF));
    let (ri0, ri1, cj0, cj1) = (lo(i0), hi(i1), lo(j0), hi(j1));
    if ri0 >= ri1 || cj0 >= cj1 {
        return Found::empty();
    }
    let (nr, nc) = (ri1 - ri0, cj1 - cj0);
    let (fr, fc) = (nr + WINDOW - 1, nc + WINDOW - 1);
    let [pa, pb, py] = frame_products(rows, ri0 - HALF, fr, cols, cj0 - HALF, fc);
    let stride = fc;
    // Column terms, structure of arrays.
    let w = POINTS as f32;
    let mut cmx = vec![0.0f32; nc];
    let mut cmz = vec![0.0f32; nc];
    let mut csq = vec![f32::INFINITY; nc];
    for c in 0..nc {
        if let Some(t) = cols.term(cj0 + c) {
            cmx[c] = t.mx;
            cmz[c] = t.mz;
            csq[c] = t.sq;
        }
    }
    let mut sums = [vec![0.0f32; nc], vec![0.0f32; nc], vec![0.0f32; nc]];
    let mut next = sums.clone();
    let mut d = vec![f32::INFINITY; nr * nc];
    let mut found = Found::empty();
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
        let Some(ti) = rows.term(gi) else { continue };
        let row = &mut d[r * nc..(r + 1) * nc];
        let colterms = cmx.iter().zip(&cmz).zip(&csq);
        let s = sums[0].iter().zip(&sums[1]).zip(&sums[2]);
        for (out, (((sa, sb), syy), ((mx, mz), sq))) in row.iter_mut().zip(s.zip(colterms)) {
            let a = sa - w * (ti.mx * mx + ti.mz * mz);
            let b = sb - w * (ti.mx * mz - ti.mz * mx);
            let v = (ti.sq + sq - 2.0 * (syy + (a * a + b * b).sqrt())) / w;
            *out = v.max(0.0);
        }
        // Windows of the same clip closer than the gap are no transitions.
        let ci = rows.clip(gi);
        let near = gi.saturating_sub(p.min_gap - 1).max(cj0)..(gi + p.min_gap).min(cj1);
        for gj in near {
            if cols.clip(gj) == ci {
                row[gj - cj0] = f32::INFINITY;
            }
        }
        if (i0..i1).contains(&gi) {
            let c_lo = j0.max(gi + 1).max(cj0) - cj0;
            let c_hi = j1.min(cj1).saturating_sub(cj0);
            if c_lo < c_hi {
                let (lo, hi, cnt) = row_stats(&row[c_lo..c_hi]);
                found.dmin = fmin(found.dmin, lo);
                found.dmax = fmax(found.dmax, hi);
                found.pairs += cnt;
            }
        }
    }
    found.candidates = local_minima(&d, nr, nc, ri0, cj0, &i, &j);
    found
}

/// The strict-or-first-tied 3 × 3 local minima of the `nr × nc` distances `d` whose row lies
/// in `i` and column in `j` above the diagonal (rows start at global `ri0`, columns at `cj0`).
fn local_minima(
    d: &[f32],
    nr: usize,
    nc: usize,
    ri0: usize,
    cj0: usize,
    i: &Range<usize>,
    j: &Range<usize>,
) -> Vec<Candidate> {
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
    let mut around = vec![0.0f32; nc];
    for r in 0..nr {
        let gi = ri0 + r;
        if !i.contains(&gi) {
            continue;
        }
        let up = &hmin[r.saturating_sub(1) * nc..][..nc];
        let down = &hmin[(r + 1).min(nr - 1) * nc..][..nc];
        let mid = &hmin[r * nc..(r + 1) * nc];
        let row = &d[r * nc..(r + 1) * nc];
        for (m, ((a, b), c)) in around.iter_mut().zip(up.iter().zip(mid).zip(down)) {
            *m = fmin(fmin(*a, *b), *c);
        }
        for (c, (&v, &m)) in row.iter().zip(&around).enumerate() {
            if v <= m && v < f32::INFINITY {
                // Rare: v is a (possibly tied) minimum. Ties go to the earlier cell in raster order.
                let gj = cj0 + c;
                if !j.contains(&gj) || gi >= gj {
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
    out
}

/// Runs kernel tiles `(a, b)` (kernel tile indices, side `p.tile` windows) on rayon's pool,
/// with rows from `rows` and columns from `cols`; `bar` ticks once per kernel tile.
pub fn search(
    rows: &Layout,
    cols: &Layout,
    n: usize,
    p: &BuildParams,
    kernels: &[(usize, usize)],
    bar: &ProgressBar,
) -> Found {
    let t = kernel_side(p);
    kernels
        .par_iter()
        .map(|&(a, b)| {
            let r = kernel_tile(
                rows,
                cols,
                n,
                p,
                a * t..((a + 1) * t).min(n),
                b * t..((b + 1) * t).min(n),
            );
            bar.inc(1);
            r
        })
        .reduce(Found::empty, Found::join)
        .sorted()
}

/// Kernel tile side in windows (the `tile` parameter, at least 8).
pub fn kernel_side(p: &BuildParams) -> usize {
    p.tile.max(8)
}

/// Every kernel tile on or above the diagonal for `n` frames, row-major.
pub fn all_kernels(n: usize, p: &BuildParams) -> Vec<(usize, usize)> {
    let nt = n.div_ceil(kernel_side(p));
    (0..nt).flat_map(|a| (a..nt).map(move |b| (a, b))).collect()
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
