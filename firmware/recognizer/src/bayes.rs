//! Stage 8 — Laban effort: one two-class classifier per axis (seed 000 §5.4).
//!
//! Time (positive class *sudden*) and Weight (positive class *strong*), each over its own
//! subset of the 58 segment features, chosen on the host by the inter/intra-class variance
//! ratio and cross-validation. Each axis is one of two [`Classifier`]s, whichever
//! cross-validated better when it was trained:
//! - Gaussian naive Bayes (the seed's): `L = tanh(Λ / (2·m))`, where Λ is the log posterior
//!   odds of the positive class and m the number of features used — the posterior difference
//!   `2P − 1` with the evidence tempered per feature, because naive Bayes multiplies
//!   correlated evidence and is otherwise almost always ±1;
//! - a linear discriminant (Gaussian classes sharing one covariance, ridge-regularised on
//!   the host): its log posterior odds is `Λ = b + Σ wₖ·xₖ`, and `L = tanh(Λ / 2) = 2P − 1`.
//!   It weighs correlated features jointly, where naive Bayes counts them twice.
//!
//! L > 0 sudden / strong, L < 0 sustained / light. Quantised to i8 as `round(127·L)`.
//!
//! # Effort blob layout, version [`EFFORT_VERSION`] (little-endian)
//! ```text
//! 0   4   magic "FGE" + version byte (3)
//! then two axes (Time, Weight), each:
//! +0  1   classifier: 0 = naive Bayes, 1 = linear discriminant
//! +1  1   m: number of features (1 ≤ m ≤ MAX_EFFORT_FEATURES)
//! +2  m   feature indices (< 58, distinct)
//! +..  4  naive Bayes: prior log-odds of the positive class; linear: the bias b (f32)
//! +..     naive Bayes: 16m, per feature mean⁺, variance⁺, mean⁻, variance⁻ (f32, variances
//!         > 0); linear: 4m, per feature its weight wₖ (f32)
//! ```

use crate::features::FEATURES;
use crate::fmath;
use crate::Error;

/// Maximum features per axis.
pub const MAX_EFFORT_FEATURES: usize = 16;
/// Effort blob format version.
pub const EFFORT_VERSION: u8 = 3;
/// Largest valid effort blob, bytes (560: two naive Bayes axes of 16 features).
pub const MAX_EFFORT_BYTES: usize =
    4 + 2 * (2 + MAX_EFFORT_FEATURES + 4 + 16 * MAX_EFFORT_FEATURES);

/// The classifier of one effort axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Classifier {
    /// Gaussian naive Bayes: per feature and class a mean and a variance.
    NaiveBayes,
    /// Linear discriminant: one weight per feature, a bias.
    Linear,
}
/// Smallest variance accepted, to keep likelihoods finite.
pub const MIN_VARIANCE: f32 = 1e-6;

/// One axis' classifier. ~290 bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisModel {
    /// Which classifier.
    pub kind: Classifier,
    /// Number of features used.
    pub m: u8,
    /// Feature indices (first `m` valid).
    pub idx: [u8; MAX_EFFORT_FEATURES],
    /// Naive Bayes: prior log-odds of the positive class; linear: the bias.
    pub prior: f32,
    /// Per feature — naive Bayes: mean⁺, var⁺, mean⁻, var⁻; linear: the weight, then zeros.
    pub params: [[f32; 4]; MAX_EFFORT_FEATURES],
}

impl AxisModel {
    /// Continuous value in [−1, 1] for a feature vector (> 0: positive class).
    pub fn value(&self, f: &[f32; FEATURES]) -> f32 {
        let m = usize::from(self.m).min(MAX_EFFORT_FEATURES);
        let mut llr = self.prior;
        for (&i, p) in self.idx.iter().zip(self.params.iter()).take(m) {
            let x = f.get(usize::from(i)).copied().unwrap_or(0.0);
            llr += match self.kind {
                Classifier::Linear => p[0] * x,
                Classifier::NaiveBayes => {
                    let lp = |mean: f32, var: f32| -> f32 {
                        let d = x - mean;
                        -0.5 * d * d / var - 0.5 * fmath::ln(var)
                    };
                    lp(p[0], p[1]) - lp(p[2], p[3])
                }
            };
        }
        let temper = match self.kind {
            Classifier::Linear => 2.0,
            Classifier::NaiveBayes => 2.0 * m.max(1) as f32,
        };
        let v = fmath::tanh(llr / temper);
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
            kind: Classifier::NaiveBayes,
            m: 0,
            idx: [0; MAX_EFFORT_FEATURES],
            prior: 0.0,
            params: [[0.0; 4]; MAX_EFFORT_FEATURES],
        }; 2];
        for ax in &mut axes {
            ax.kind = match *b.get(at).ok_or(Error::Truncated)? {
                0 => Classifier::NaiveBayes,
                1 => Classifier::Linear,
                _ => return Err(Error::Invalid("classifier")),
            };
            at += 1;
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
            let per_feature = match ax.kind {
                Classifier::NaiveBayes => 4,
                Classifier::Linear => 1,
            };
            for p in ax.params.iter_mut().take(m) {
                for (c, v) in p.iter_mut().enumerate().take(per_feature) {
                    *v = rd_f32(b, at)?;
                    at += 4;
                    if ax.kind == Classifier::NaiveBayes && c % 2 == 1 && *v < MIN_VARIANCE {
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
            let (kind, per_feature) = match ax.kind {
                Classifier::NaiveBayes => (0, 4),
                Classifier::Linear => (1, 1),
            };
            let _ = out.push(kind);
            let _ = out.push(m as u8);
            let _ = out.extend_from_slice(&ax.idx[..m]);
            let _ = out.extend_from_slice(&ax.prior.to_le_bytes());
            for p in &ax.params[..m] {
                for v in &p[..per_feature] {
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
            kind: Classifier::NaiveBayes,
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
        b[7..11].copy_from_slice(&f32::NAN.to_le_bytes()); // the Time prior
        assert!(EffortModel::from_bytes(&b).is_err());
        let mut b = bytes.clone();
        b[4] = 2; // no such classifier
        assert!(EffortModel::from_bytes(&b).is_err());
    }

    #[test]
    fn a_linear_axis_weighs_its_features_together() {
        // Λ = −1 + 2·x₃ − 1·x₅: the two features pull against each other.
        let mut weight = AxisModel {
            kind: Classifier::Linear,
            m: 2,
            idx: [0; MAX_EFFORT_FEATURES],
            prior: -1.0,
            params: [[0.0; 4]; MAX_EFFORT_FEATURES],
        };
        weight.idx[..2].copy_from_slice(&[3, 5]);
        weight.params[0][0] = 2.0;
        weight.params[1][0] = -1.0;
        let m = EffortModel {
            time: model().time,
            weight,
        };
        let mut f = [0.0; FEATURES];
        f[3] = 2.0;
        f[5] = 1.0;
        // Λ = 2: L = tanh(1) = 2P − 1 with P = σ(2).
        let lw = m.classify(&f).1;
        assert!((lw - libm::tanhf(1.0)).abs() < 1e-6, "{lw}");
        f[5] = 4.0;
        assert!(m.classify(&f).1 < 0.0);
        let bytes = m.to_bytes();
        // Time: 2 + 1 + 4 + 16 bytes; Weight: 2 + 2 + 4 + 8.
        assert_eq!(bytes.len(), 4 + 23 + 16);
        assert_eq!(EffortModel::from_bytes(&bytes).unwrap(), m);
        for cut in 0..bytes.len() {
            assert!(EffortModel::from_bytes(&bytes[..cut]).is_err());
        }
    }
}

#[cfg(test)]
mod sizes {
    #[test]
    fn documented_blob_limits() {
        assert_eq!(super::MAX_EFFORT_BYTES, 560);
        assert_eq!(crate::pattern::MAX_LIBRARY_BYTES, 12_296);
    }
}
