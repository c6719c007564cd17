//! Laban Time/Weight classifiers from labelled one-gesture logs (`figurine train-effort`, whose
//! command and report are in [`super::report`]).
//!
//! DIR holds `sudden-strong/`, `sudden-light/`, `sustained-strong/`, `sustained-light/` with
//! one-gesture pose logs. Each log's 58 features are computed by the device front end over the
//! gesture (first to last motion). Per axis, features are ranked by σ²inter / σ²intra
//! (seed 000 §5.3, eqs. 2–5); the number M of top features is chosen by stratified k-fold
//! cross-validated accuracy (ranking redone inside each fold, so the estimate is honest), for
//! each of two classifiers: the seed's Gaussian naive Bayes (§5.4) and a linear discriminant
//! (Gaussian classes with one shared covariance, ridge-regularised), which weighs correlated
//! features jointly instead of counting their evidence twice. Per axis the classifier and M
//! with the better cross-validated accuracy are kept (naive Bayes on ties); the final model
//! uses the top M over all data. Predictions use the device's own classifier code, so the
//! accuracies are the device's.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use figurine_recognizer::bayes::{MAX_EFFORT_FEATURES, MIN_VARIANCE};
use figurine_recognizer::features::{segment_features, FEATURES};

use super::effort_model::{feature_name, AxisFile, ClassifierKind, EffortFile, FeatureParams};
use super::feed::gesture_accum;
use crate::poselog::PoseLog;

/// The four state folders, in (time, weight) order: (+,+), (+,−), (−,+), (−,−).
pub const STATES: [&str; 4] = [
    "sudden-strong",
    "sudden-light",
    "sustained-strong",
    "sustained-light",
];
/// Cross-validation folds.
pub const FOLDS: usize = 5;
/// Variance floor added to fitted variances (log-domain feature units²).
pub const VAR_FLOOR: f32 = 1e-3;
/// Ridge added to the diagonal of the linear discriminant's shared covariance, in units of
/// each feature's own variance (the features are standardised first): keeps the solve stable
/// when selected features are nearly collinear (a mean and its spread).
pub const RIDGE: f64 = 0.1;

/// One labelled example: features and (sudden?, strong?).
#[derive(Debug, Clone)]
pub struct Example {
    /// The 58 log-domain features.
    pub f: [f32; FEATURES],
    /// Sudden (true) or sustained.
    pub sudden: bool,
    /// Strong (true) or light.
    pub strong: bool,
}

/// Features of a one-gesture log (None if it has no motion).
pub fn gesture_features(log: &PoseLog) -> Option<[f32; FEATURES]> {
    gesture_accum(log).map(|acc| segment_features(&acc))
}

/// Which axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Sudden (+) vs sustained.
    Time,
    /// Strong (+) vs light.
    Weight,
}

impl Axis {
    /// The example's class on this axis.
    pub fn label(self, e: &Example) -> bool {
        match self {
            Axis::Time => e.sudden,
            Axis::Weight => e.strong,
        }
    }
}

/// σ²inter / σ²intra of every feature (eqs. 2–5), for two classes.
pub fn relevance(ex: &[&Example], axis: Axis) -> [f64; FEATURES] {
    let mut out = [0.0; FEATURES];
    for (f, o) in out.iter_mut().enumerate() {
        let mut sum = [0.0f64; 2];
        let mut n = [0usize; 2];
        for e in ex {
            let c = usize::from(axis.label(e));
            sum[c] += f64::from(e.f[f]);
            n[c] += 1;
        }
        let total = (n[0] + n[1]).max(1) as f64;
        let mean = (sum[0] + sum[1]) / total;
        let cm = [sum[0] / n[0].max(1) as f64, sum[1] / n[1].max(1) as f64];
        let inter = (0..2)
            .map(|c| n[c] as f64 * (cm[c] - mean).powi(2))
            .sum::<f64>()
            / total;
        let intra = ex
            .iter()
            .map(|e| (f64::from(e.f[f]) - cm[usize::from(axis.label(e))]).powi(2))
            .sum::<f64>()
            / total;
        *o = inter / intra.max(1e-12);
    }
    out
}

/// Feature indices by decreasing relevance.
pub fn ranking(ex: &[&Example], axis: Axis) -> Vec<usize> {
    let r = relevance(ex, axis);
    let mut idx: Vec<usize> = (0..FEATURES).collect();
    idx.sort_by(|&a, &b| r[b].total_cmp(&r[a]).then(a.cmp(&b)));
    idx
}

/// Fits the Gaussian naive Bayes parameters of `features` on `ex`.
pub fn fit(ex: &[&Example], axis: Axis, features: &[usize]) -> AxisFile {
    let pos: Vec<&&Example> = ex.iter().filter(|e| axis.label(e)).collect();
    let neg: Vec<&&Example> = ex.iter().filter(|e| !axis.label(e)).collect();
    let stats = |set: &[&&Example], f: usize| -> [f32; 2] {
        let n = set.len().max(1) as f64;
        let m = set.iter().map(|e| f64::from(e.f[f])).sum::<f64>() / n;
        let v = set
            .iter()
            .map(|e| (f64::from(e.f[f]) - m).powi(2))
            .sum::<f64>()
            / n;
        [m as f32, (v as f32 + VAR_FLOOR).max(MIN_VARIANCE)]
    };
    let prior = ((pos.len() as f64 + 1.0) / (neg.len() as f64 + 1.0)).ln() as f32;
    AxisFile {
        positive_class: match axis {
            Axis::Time => "sudden".into(),
            Axis::Weight => "strong".into(),
        },
        classifier: ClassifierKind::NaiveBayes,
        prior_log_odds: prior,
        bias: None,
        features: features
            .iter()
            .map(|&f| FeatureParams {
                index: f as u8,
                name: feature_name(f),
                positive: stats(&pos, f),
                negative: stats(&neg, f),
                weight: None,
            })
            .collect(),
        cv_accuracy: None,
    }
}

/// Fits a linear discriminant over `features` on `ex`: classes as Gaussians sharing one
/// covariance (standardised features, [`RIDGE`] on the diagonal), whose log posterior odds is
/// `bias + Σ wₖ·xₖ` in the raw feature units. The class Gaussians are kept for the report.
pub fn fit_linear(ex: &[&Example], axis: Axis, features: &[usize]) -> AxisFile {
    let mut file = fit(ex, axis, features);
    let m = features.len();
    let n = ex.len().max(1) as f64;
    let x = |e: &Example, k: usize| f64::from(e.f[features[k]]);
    let mean: Vec<f64> = (0..m)
        .map(|k| ex.iter().map(|e| x(e, k)).sum::<f64>() / n)
        .collect();
    let sd: Vec<f64> = (0..m)
        .map(|k| {
            let v = ex.iter().map(|e| (x(e, k) - mean[k]).powi(2)).sum::<f64>() / n;
            v.sqrt().max(1e-9)
        })
        .collect();
    let z = |e: &Example, k: usize| (x(e, k) - mean[k]) / sd[k];
    let mut mu = [vec![0.0; m], vec![0.0; m]];
    let mut count = [0.0f64; 2];
    for e in ex {
        let c = usize::from(axis.label(e));
        count[c] += 1.0;
        for (k, v) in mu[c].iter_mut().enumerate() {
            *v += z(e, k);
        }
    }
    for c in 0..2 {
        mu[c].iter_mut().for_each(|v| *v /= count[c].max(1.0));
    }
    // [Σ + ridge·I | μ⁺ − μ⁻], solved by Gauss–Jordan (Σ + ridge·I is positive definite).
    let mut a = vec![vec![0.0; m + 1]; m];
    for e in ex {
        let c = usize::from(axis.label(e));
        for i in 0..m {
            for j in 0..m {
                a[i][j] += (z(e, i) - mu[c][i]) * (z(e, j) - mu[c][j]) / n;
            }
        }
    }
    for i in 0..m {
        a[i][i] += RIDGE;
        a[i][m] = mu[1][i] - mu[0][i];
    }
    for col in 0..m {
        let piv = a[col][col];
        a[col].iter_mut().for_each(|v| *v /= piv);
        let pivot_row = a[col].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != col {
                let f = row[col];
                row.iter_mut()
                    .zip(&pivot_row)
                    .for_each(|(v, p)| *v -= f * p);
            }
        }
    }
    let w: Vec<f64> = (0..m).map(|i| a[i][m]).collect();
    // Λ = wᵀ(z − (μ⁺ + μ⁻)/2) + ln(n⁺/n⁻), with z = (x − mean)/sd.
    let mid: f64 = (0..m).map(|k| w[k] * (mu[1][k] + mu[0][k]) / 2.0).sum();
    let shift: f64 = (0..m).map(|k| w[k] * mean[k] / sd[k]).sum();
    let prior = ((count[1] + 1.0) / (count[0] + 1.0)).ln();
    file.classifier = ClassifierKind::Linear;
    file.bias = Some((prior - mid - shift) as f32);
    for (k, p) in file.features.iter_mut().enumerate() {
        p.weight = Some((w[k] / sd[k]) as f32);
    }
    file
}

/// Fits `kind` over `features` on `ex`.
pub fn fit_kind(ex: &[&Example], axis: Axis, features: &[usize], kind: ClassifierKind) -> AxisFile {
    match kind {
        ClassifierKind::NaiveBayes => fit(ex, axis, features),
        ClassifierKind::Linear => fit_linear(ex, axis, features),
    }
}

/// Device-side prediction with an axis file (0 when the device would refuse it).
pub fn predict(ax: &AxisFile, f: &[f32; FEATURES]) -> f32 {
    ax.to_device().map_or(0.0, |m| m.value(f))
}

/// Stratified fold of example `i` (deterministic).
fn fold_of(ex: &[Example]) -> Vec<usize> {
    let mut counters = [0usize; 4];
    ex.iter()
        .map(|e| {
            let s = usize::from(e.sudden) * 2 + usize::from(e.strong);
            counters[s] += 1;
            counters[s] % FOLDS
        })
        .collect()
}

/// Cross-validated predictions (one value per example) of an axis with the top `m` features.
pub fn cv_predictions(ex: &[Example], axis: Axis, m: usize, kind: ClassifierKind) -> Vec<f32> {
    let folds = fold_of(ex);
    let mut out = vec![0.0; ex.len()];
    for k in 0..FOLDS {
        let train: Vec<&Example> = ex
            .iter()
            .zip(&folds)
            .filter(|(_, &f)| f != k)
            .map(|(e, _)| e)
            .collect();
        if train.is_empty() {
            continue;
        }
        let top: Vec<usize> = ranking(&train, axis).into_iter().take(m).collect();
        let model = fit_kind(&train, axis, &top, kind);
        for (i, e) in ex.iter().enumerate() {
            if folds[i] == k {
                out[i] = predict(&model, &e.f);
            }
        }
    }
    out
}

/// Accuracy of predictions against labels.
pub fn accuracy(ex: &[Example], axis: Axis, pred: &[f32]) -> f64 {
    let ok = ex
        .iter()
        .zip(pred)
        .filter(|(e, &p)| (p > 0.0) == axis.label(e))
        .count();
    ok as f64 / ex.len().max(1) as f64
}

/// A trained model with its selection curve.
#[derive(Debug, Clone)]
pub struct Trained {
    /// The model.
    pub file: EffortFile,
    /// CV accuracy for M = 1..=MAX per axis, of the chosen classifier.
    pub curves: [Vec<f64>; 2],
    /// Best CV accuracy of each classifier per axis: (naive Bayes, linear).
    pub best_of: [(f64, f64); 2],
    /// Relevance ratios (all data) per axis.
    pub relevance: [[f64; FEATURES]; 2],
    /// CV predictions with the chosen M, per axis.
    pub cv_pred: [Vec<f32>; 2],
}

/// Trains both axes on labelled examples.
pub fn train(ex: &[Example]) -> Result<Trained> {
    if ex.len() < 2 * FOLDS {
        bail!(
            "{} examples; need at least {} (some of each class)",
            ex.len(),
            2 * FOLDS
        );
    }
    let all: Vec<&Example> = ex.iter().collect();
    let mut axes = Vec::new();
    let mut curves: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    let mut rel = [[0.0; FEATURES]; 2];
    let mut cv_pred: [Vec<f32>; 2] = [Vec::new(), Vec::new()];
    let mut best_of = [(0.0, 0.0); 2];
    for (a, axis) in [Axis::Time, Axis::Weight].into_iter().enumerate() {
        let (pos, neg) = (
            ex.iter().filter(|e| axis.label(e)).count(),
            ex.iter().filter(|e| !axis.label(e)).count(),
        );
        if pos == 0 || neg == 0 {
            bail!("{axis:?}: need examples of both classes ({pos} positive, {neg} negative)");
        }
        let mut best = (0.0, 1usize, ClassifierKind::NaiveBayes);
        for kind in [ClassifierKind::NaiveBayes, ClassifierKind::Linear] {
            let curve: Vec<f64> = (1..=MAX_EFFORT_FEATURES)
                .map(|m| accuracy(ex, axis, &cv_predictions(ex, axis, m, kind)))
                .collect();
            let top = curve.iter().copied().fold(0.0, f64::max);
            match kind {
                ClassifierKind::NaiveBayes => best_of[a].0 = top,
                ClassifierKind::Linear => best_of[a].1 = top,
            }
            if top > best.0 + 1e-9 {
                let m = curve.iter().position(|&c| c == top).unwrap_or(0) + 1;
                best = (top, m, kind);
                curves[a] = curve;
            }
        }
        rel[a] = relevance(&all, axis);
        let top: Vec<usize> = ranking(&all, axis).into_iter().take(best.1).collect();
        let mut file = fit_kind(&all, axis, &top, best.2);
        file.cv_accuracy = Some(best.0);
        cv_pred[a] = cv_predictions(ex, axis, best.1, best.2);
        axes.push(file);
    }
    let weight = axes.pop().context("weight axis")?;
    let time = axes.pop().context("time axis")?;
    Ok(Trained {
        file: EffortFile::new(time, weight)?,
        curves,
        best_of,
        relevance: rel,
        cv_pred,
    })
}

/// Reads the four state folders.
pub fn read_dir(dir: &Path) -> Result<Vec<Example>> {
    let mut out = Vec::new();
    for (s, state) in STATES.iter().enumerate() {
        let sub = dir.join(state);
        let mut files: Vec<PathBuf> = std::fs::read_dir(&sub)
            .with_context(|| {
                format!(
                    "reading {} (DIR needs {})",
                    sub.display(),
                    STATES.join("/, ")
                )
            })?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "csv"))
            .collect();
        files.sort();
        for p in files {
            let log = PoseLog::read_path(&p)?;
            match gesture_features(&log) {
                Some(f) => out.push(Example {
                    f,
                    sudden: s < 2,
                    strong: s % 2 == 0,
                }),
                None => eprintln!("warning: {}: no motion found, skipped", p.display()),
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Strong when feature 3 exceeds feature 7: each alone tells little (both vary widely and
    /// together), their difference everything — correlated evidence naive Bayes cannot weigh.
    fn examples() -> Vec<Example> {
        let mut state = 12345u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..200)
            .map(|i| {
                let strong = i % 2 == 0;
                let common = 4.0 * uniform();
                let gap = 0.3 + 0.4 * uniform();
                let mut f = [0.0f32; FEATURES];
                f[3] = (common + if strong { gap } else { 0.0 }) as f32;
                f[7] = (common + if strong { 0.0 } else { gap }) as f32;
                f[11] = uniform() as f32;
                Example {
                    f,
                    sudden: i % 4 < 2,
                    strong,
                }
            })
            .collect()
    }

    #[test]
    fn the_linear_discriminant_weighs_correlated_features_jointly() {
        let ex = examples();
        let all: Vec<&Example> = ex.iter().collect();
        let feats = [3, 7];
        let lin = fit_linear(&all, Axis::Weight, &feats);
        let nb = fit(&all, Axis::Weight, &feats);
        let acc = |ax: &AxisFile| {
            let p: Vec<f32> = ex.iter().map(|e| predict(ax, &e.f)).collect();
            accuracy(&ex, Axis::Weight, &p)
        };
        assert!(acc(&lin) > 0.97, "linear {}", acc(&lin));
        assert!(acc(&nb) < 0.8, "naive Bayes {}", acc(&nb));
        // Opposite weights on the two features: the difference is what counts.
        let w: Vec<f32> = lin.features.iter().map(|f| f.weight.unwrap()).collect();
        assert!(w[0] > 0.0 && w[1] < 0.0, "{w:?}");
    }

    #[test]
    fn training_keeps_the_classifier_that_cross_validates_better() {
        let t = train(&examples()).unwrap();
        assert_eq!(t.file.weight.classifier, ClassifierKind::Linear);
        assert!(t.best_of[1].1 > t.best_of[1].0 + 0.1, "{:?}", t.best_of);
        assert!(t.file.weight.cv_accuracy.unwrap() > 0.95);
        // The device runs the saved model.
        let m = t.file.model().unwrap();
        let ex = examples();
        let ok = ex
            .iter()
            .filter(|e| (m.classify(&e.f).1 > 0.0) == e.strong)
            .count();
        assert!(ok > 190, "{ok} of 200");
    }
}
