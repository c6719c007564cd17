//! Style correlation (seed 003 eq. 2): Pearson's r between two windows' LMA measurements, per
//! component (BODY, EFFORT, SHAPE, SPACE), mapped to [0, 1], weighted, Gaussian-smoothed.
//!
//! The measurements have different units (m, m/s, m³ …), so before eq. 2 each measurement is
//! standardised over the whole library (z-score; the mean and std are saved with the graph so a
//! reference clip for synthesis by example is standardised alike). Then for each window and
//! component the z-scores are centred and scaled to unit length: the Pearson coefficient of two
//! windows is the dot product of their vectors (eq. 2's 1/(N−1) and the sample deviations
//! cancel). A component whose values are all equal has no defined r and contributes r = 0.
//!
//! The overall style similarity is `S = Σ_c w_c (1 + r_c)/2 / Σ_c w_c` ∈ [0, 1]; it is smoothed
//! along the pair's time diagonal with a Gaussian of σ = 1 window (μ = 0, σ² = 1, §4), and
//! compared with the threshold T_LMA (80 % in the paper).

use serde::{Deserialize, Serialize};

use super::lma::{Component, MEASUREMENTS};

/// Half width of the Gaussian smoothing kernel, windows (3σ).
pub const SMOOTH_HALF: usize = 3;

/// Gaussian weights for offsets −3..=3 (σ = 1, unnormalised).
pub fn gauss_weights() -> [f32; 2 * SMOOTH_HALF + 1] {
    let mut w = [0.0; 2 * SMOOTH_HALF + 1];
    for (k, v) in w.iter_mut().enumerate() {
        let x = k as f32 - SMOOTH_HALF as f32;
        *v = (-0.5 * x * x).exp();
    }
    w
}

/// User weights of the four LMA components (relative; 0.25 each weights them equally).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ComponentWeights {
    /// BODY weight.
    pub body: f32,
    /// EFFORT weight.
    pub effort: f32,
    /// SHAPE weight.
    pub shape: f32,
    /// SPACE weight.
    pub space: f32,
}

impl Default for ComponentWeights {
    fn default() -> Self {
        ComponentWeights {
            body: 0.25,
            effort: 0.25,
            shape: 0.25,
            space: 0.25,
        }
    }
}

impl ComponentWeights {
    /// Weights in component order, normalised to sum 1 (equal weights if all are ≤ 0).
    pub fn normalised(&self) -> [f32; 4] {
        let w = [self.body, self.effort, self.shape, self.space].map(|v| {
            if v.is_finite() {
                v.max(0.0)
            } else {
                0.0
            }
        });
        let s: f32 = w.iter().sum();
        if s > 0.0 {
            w.map(|v| v / s)
        } else {
            [0.25; 4]
        }
    }

    /// Parses `body,effort,shape,space` (e.g. `0.25,0.25,0.25,0.25`).
    pub fn parse(text: &str) -> Result<ComponentWeights, String> {
        let v: Vec<f32> = text
            .split(',')
            .map(|s| {
                s.trim()
                    .parse::<f32>()
                    .map_err(|e| format!("weight `{s}`: {e}"))
            })
            .collect::<Result<_, _>>()?;
        match v.as_slice() {
            [b, e, sh, sp] if v.iter().all(|x| x.is_finite() && *x >= 0.0) => {
                Ok(ComponentWeights {
                    body: *b,
                    effort: *e,
                    shape: *sh,
                    space: *sp,
                })
            }
            _ => Err(format!(
                "expected four non-negative weights body,effort,shape,space; got `{text}`"
            )),
        }
    }
}

/// Per-measurement mean and standard deviation over a library.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Standardiser {
    /// Mean of each measurement.
    pub mean: Vec<f32>,
    /// Standard deviation of each measurement (1 where it is 0).
    pub std: Vec<f32>,
}

impl Standardiser {
    /// Fits mean and std to measurement rows (`rows × MEASUREMENTS`, flat).
    pub fn fit(rows: &[f32]) -> Standardiser {
        let n = rows.len() / MEASUREMENTS;
        let mut sum = vec![0.0f64; MEASUREMENTS];
        let mut sq = vec![0.0f64; MEASUREMENTS];
        for row in rows.chunks_exact(MEASUREMENTS) {
            for (k, v) in row.iter().enumerate() {
                sum[k] += *v as f64;
                sq[k] += (*v as f64) * (*v as f64);
            }
        }
        let nf = n.max(1) as f64;
        let mean: Vec<f32> = sum.iter().map(|s| (s / nf) as f32).collect();
        let std = sum
            .iter()
            .zip(&sq)
            .map(|(s, q)| {
                let m = s / nf;
                let v = (q / nf - m * m).max(0.0).sqrt() as f32;
                if v > 1e-9 {
                    v
                } else {
                    1.0
                }
            })
            .collect();
        Standardiser { mean, std }
    }

    /// Style vectors of measurement rows: z-scored, then per component centred and unit-length.
    pub fn style_vectors(&self, rows: &[f32]) -> Vec<f32> {
        let mut out = Vec::with_capacity(rows.len());
        for row in rows.chunks_exact(MEASUREMENTS) {
            let start = out.len();
            out.extend(
                row.iter()
                    .zip(self.mean.iter().zip(&self.std))
                    .map(|(v, (m, s))| (v - m) / s),
            );
            let z = &mut out[start..];
            for c in Component::ALL {
                let seg = &mut z[c.range()];
                let mean = seg.iter().sum::<f32>() / seg.len() as f32;
                seg.iter_mut().for_each(|v| *v -= mean);
                let norm = seg.iter().map(|v| v * v).sum::<f32>().sqrt();
                if norm > 1e-6 {
                    seg.iter_mut().for_each(|v| *v /= norm);
                } else {
                    seg.iter_mut().for_each(|v| *v = 0.0);
                }
            }
        }
        out
    }
}

/// Pearson's r per component between two style vectors (each `MEASUREMENTS` long).
pub fn pearson(a: &[f32], b: &[f32]) -> [f32; 4] {
    Component::ALL.map(|c| {
        let r = c.range();
        match (a.get(r.clone()), b.get(r)) {
            (Some(x), Some(y)) => x
                .iter()
                .zip(y)
                .map(|(p, q)| p * q)
                .sum::<f32>()
                .clamp(-1.0, 1.0),
            _ => 0.0,
        }
    })
}

/// Weighted style similarity ∈ [0, 1] from per-component r (weights from
/// [`ComponentWeights::normalised`]).
pub fn similarity(r: [f32; 4], w: &[f32; 4]) -> f32 {
    r.iter().zip(w).map(|(r, w)| w * 0.5 * (1.0 + r)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(f: impl Fn(usize) -> f32) -> Vec<f32> {
        (0..MEASUREMENTS).map(f).collect()
    }

    #[test]
    fn pearson_matches_textbook_formula() {
        let mut rows = row(|k| (k as f32 * 0.37).sin() * (k as f32 + 1.0));
        rows.extend(row(|k| (k as f32 * 0.11).cos() + k as f32 * 0.01));
        rows.extend(row(|k| k as f32));
        let st = Standardiser::fit(&rows);
        let v = st.style_vectors(&rows);
        let (a, b) = (&v[..MEASUREMENTS], &v[MEASUREMENTS..2 * MEASUREMENTS]);
        let r = pearson(a, b);
        // Textbook eq. 2 on the z-scored rows, BODY component.
        let z = |i: usize, k: usize| (rows[i * MEASUREMENTS + k] - st.mean[k]) / st.std[k];
        let range = Component::Body.range();
        let n = range.len() as f32;
        let (xa, xb): (Vec<f32>, Vec<f32>) = range.clone().map(|k| (z(0, k), z(1, k))).unzip();
        let ma = xa.iter().sum::<f32>() / n;
        let mb = xb.iter().sum::<f32>() / n;
        let sa = (xa.iter().map(|x| (x - ma).powi(2)).sum::<f32>() / (n - 1.0)).sqrt();
        let sb = (xb.iter().map(|x| (x - mb).powi(2)).sum::<f32>() / (n - 1.0)).sqrt();
        let expect = xa
            .iter()
            .zip(&xb)
            .map(|(x, y)| (x - ma) / sa * (y - mb) / sb)
            .sum::<f32>()
            / (n - 1.0);
        assert!((r[0] - expect).abs() < 1e-4, "{} vs {expect}", r[0]);
        // Self-correlation is 1, similarity 1.
        let s = similarity(pearson(a, a), &ComponentWeights::default().normalised());
        assert!((s - 1.0).abs() < 1e-4, "{s}");
    }

    #[test]
    fn weights_parse_and_normalise() {
        let w = ComponentWeights::parse("1,1,2,0").unwrap().normalised();
        assert_eq!(w, [0.25, 0.25, 0.5, 0.0]);
        assert!(ComponentWeights::parse("1,2").is_err());
        assert!(ComponentWeights::parse("1,2,x,3").is_err());
        assert!(ComponentWeights::parse("1,-2,1,3").is_err());
        assert_eq!(
            ComponentWeights::parse("0,0,0,0").unwrap().normalised(),
            [0.25; 4]
        );
    }

    #[test]
    fn gaussian_is_symmetric_and_peaked() {
        let g = gauss_weights();
        assert_eq!(g[SMOOTH_HALF], 1.0);
        assert!((g[0] - g[6]).abs() < 1e-7 && g[2] > g[1]);
    }
}
