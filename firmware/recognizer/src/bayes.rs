//! Stage 8 — Laban effort: two Gaussian naive Bayes classifiers (seed 000 §5.4).
//!
//! One classifier per axis: Time (positive class *sudden*) and Weight (positive class
//! *strong*), each over its own subset of the 54 segment features, chosen on the host by the
//! inter/intra-class variance ratio and cross-validation. The output is continuous:
//! `L = tanh(Λ / (2·m))`, where Λ is the log posterior odds of the positive class and m the
//! number of features used — the posterior difference `2P − 1` with the evidence tempered per
//! feature, because naive Bayes multiplies correlated evidence and is otherwise almost always
//! ±1. L > 0 sudden / strong, L < 0 sustained / light. Quantised to i8 as `round(127·L)`.
//!
//! # Effort blob layout, version [`EFFORT_VERSION`] (little-endian)
//! ```text
//! 0   4   magic "FGE" + version byte (1)
//! then two axes (Time, Weight), each:
//! +0  1   m: number of features (1 ≤ m ≤ MAX_EFFORT_FEATURES)
//! +1  m   feature indices (< 50, distinct)
//! +..  4  prior log-odds of the positive class (f32)
//! +..  16m per feature: mean⁺, variance⁺, mean⁻, variance⁻ (f32, variances > 0)
//! ```

use crate::features::FEATURES;
use crate::fmath;
use crate::Error;

/// Maximum features per axis.
pub const MAX_EFFORT_FEATURES: usize = 16;
/// Effort blob format version.
pub const EFFORT_VERSION: u8 = 1;
/// Largest valid effort blob, bytes (558).
pub const MAX_EFFORT_BYTES: usize =
    4 + 2 * (1 + MAX_EFFORT_FEATURES + 4 + 16 * MAX_EFFORT_FEATURES);
/// Smallest variance accepted, to keep likelihoods finite.
pub const MIN_VARIANCE: f32 = 1e-6;

/// One axis' classifier. ~290 bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisModel {
    /// Number of features used.
    pub m: u8,
    /// Feature indices (first `m` valid).
    pub idx: [u8; MAX_EFFORT_FEATURES],
    /// Prior log-odds of the positive class.
    pub prior: f32,
    /// Per feature: mean⁺, var⁺, mean⁻, var⁻.
    pub params: [[f32; 4]; MAX_EFFORT_FEATURES],
}

impl AxisModel {
    /// Continuous value in [−1, 1] for a feature vector (> 0: positive class).
    pub fn value(&self, f: &[f32; FEATURES]) -> f32 {
        let m = usize::from(self.m).min(MAX_EFFORT_FEATURES);
        let mut llr = self.prior;
        for (&i, p) in self.idx.iter().zip(self.params.iter()).take(m) {
            let x = f.get(usize::from(i)).copied().unwrap_or(0.0);
            let lp = |mean: f32, var: f32| -> f32 {
                let d = x - mean;
                -0.5 * d * d / var - 0.5 * fmath::ln(var)
            };
            llr += lp(p[0], p[1]) - lp(p[2], p[3]);
        }
        let v = fmath::tanh(llr / (2.0 * m.max(1) as f32));
        if fmath::is_finite(v) {
            v
        } else {
            0.0
        }
    }
}

/// Quantises a value in [−1, 1] to i8 (`round(127·v)`, clamped).
pub fn quantise(v: f32) -> i8 {
    if v.is_nan() {
        return 0;
    }
    fmath::round(fmath::clamp(v, -1.0, 1.0) * 127.0) as i8
}

/// The two effort classifiers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EffortModel {
    /// Time: positive = sudden.
    pub time: AxisModel,
    /// Weight: positive = strong.
    pub weight: AxisModel,
}

fn rd_f32(b: &[u8], at: usize) -> Result<f32, Error> {
    let s = b.get(at..at + 4).ok_or(Error::Truncated)?;
    let v = f32::from_le_bytes([s[0], s[1], s[2], s[3]]);
    if fmath::is_finite(v) {
        Ok(v)
    } else {
        Err(Error::Invalid("non-finite parameter"))
    }
}

impl EffortModel {
    /// Validates and decodes an effort blob. Never panics.
    pub fn from_bytes(b: &[u8]) -> Result<Self, Error> {
        if b.len() > MAX_EFFORT_BYTES {
            return Err(Error::TooLarge);
        }
        let head = b.get(..4).ok_or(Error::Truncated)?;
        if head[..3] != *b"FGE" {
            return Err(Error::BadMagic);
        }
        if head[3] != EFFORT_VERSION {
            return Err(Error::Version(head[3]));
        }
        let mut at = 4;
        let mut axes = [AxisModel {
            m: 0,
            idx: [0; MAX_EFFORT_FEATURES],
            prior: 0.0,
            params: [[0.0; 4]; MAX_EFFORT_FEATURES],
        }; 2];
        for ax in &mut axes {
            let m = usize::from(*b.get(at).ok_or(Error::Truncated)?);
            if m == 0 || m > MAX_EFFORT_FEATURES {
                return Err(Error::Capacity);
            }
            at += 1;
            let idx = b.get(at..at + m).ok_or(Error::Truncated)?;
            for (k, &i) in idx.iter().enumerate() {
                if usize::from(i) >= FEATURES || idx[..k].contains(&i) {
                    return Err(Error::Invalid("feature index"));
                }
                ax.idx[k] = i;
            }
            at += m;
            ax.m = m as u8;
            ax.prior = rd_f32(b, at)?;
            at += 4;
            for p in ax.params.iter_mut().take(m) {
                for (c, v) in p.iter_mut().enumerate() {
                    *v = rd_f32(b, at)?;
                    at += 4;
                    if c % 2 == 1 && *v < MIN_VARIANCE {
                        return Err(Error::Invalid("variance"));
                    }
                }
            }
        }
        if at != b.len() {
            return Err(Error::Invalid("trailing bytes"));
        }
        let [time, weight] = axes;
        Ok(EffortModel { time, weight })
    }

    /// Encodes the model (inverse of [`EffortModel::from_bytes`]).
    #[cfg(any(feature = "std", test))]
    pub fn to_bytes(&self) -> heapless::Vec<u8, MAX_EFFORT_BYTES> {
        let mut out = heapless::Vec::new();
        let _ = out.extend_from_slice(b"FGE");
        let _ = out.push(EFFORT_VERSION);
        for ax in [&self.time, &self.weight] {
            let m = usize::from(ax.m).min(MAX_EFFORT_FEATURES);
            let _ = out.push(m as u8);
            let _ = out.extend_from_slice(&ax.idx[..m]);
            let _ = out.extend_from_slice(&ax.prior.to_le_bytes());
            for p in &ax.params[..m] {
                for v in p {
                    let _ = out.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        out
    }

    /// (Lt, Lw) for a segment's features.
    pub fn classify(&self, f: &[f32; FEATURES]) -> (f32, f32) {
        (self.time.value(f), self.weight.value(f))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> EffortModel {
        let mut ax = AxisModel {
            m: 1,
            idx: [0; MAX_EFFORT_FEATURES],
            prior: 0.0,
            params: [[0.0; 4]; MAX_EFFORT_FEATURES],
        };
        ax.idx[0] = 3;
        ax.params[0] = [1.0, 0.25, -1.0, 0.25];
        EffortModel {
            time: ax,
            weight: AxisModel { prior: 0.5, ..ax },
        }
    }

    #[test]
    fn classifies_by_the_selected_feature_and_round_trips() {
        let m = model();
        let mut f = [0.0; FEATURES];
        f[3] = 1.2;
        let (lt, _) = m.classify(&f);
        assert!(lt > 0.5, "{lt}");
        f[3] = -0.9;
        assert!(m.classify(&f).0 < -0.5);
        let bytes = m.to_bytes();
        assert_eq!(EffortModel::from_bytes(&bytes).unwrap(), m);
        assert_eq!(quantise(1.0), 127);
        assert_eq!(quantise(-2.0), -127);
        assert_eq!(quantise(f32::NAN), 0);
    }

    #[test]
    fn bad_blobs_are_errors() {
        let bytes = model().to_bytes();
        for cut in 0..bytes.len() {
            assert!(EffortModel::from_bytes(&bytes[..cut]).is_err());
        }
        let mut b = bytes.clone();
        b[6..10].copy_from_slice(&f32::NAN.to_le_bytes()); // the Time prior
        assert!(EffortModel::from_bytes(&b).is_err());
    }
}

#[cfg(test)]
mod sizes {
    #[test]
    fn documented_blob_limits() {
        assert_eq!(super::MAX_EFFORT_BYTES, 558);
        assert_eq!(crate::pattern::MAX_LIBRARY_BYTES, 11_656);
    }
}
