//! `figurine train-effort`: Laban Time/Weight classifiers from labelled one-gesture logs.
//!
//! DIR holds `sudden-strong/`, `sudden-light/`, `sustained-strong/`, `sustained-light/` with
//! one-gesture pose logs. Each log's 54 features are computed by the device front end over the
//! gesture (first to last motion). Per axis, features are ranked by σ²inter / σ²intra
//! (seed 000 §5.3, eqs. 2–5); the number M of top features is chosen by stratified k-fold
//! cross-validated accuracy of the Gaussian naive Bayes classifier (§5.4; ranking redone
//! inside each fold, so the estimate is honest); the final model uses the top M over all data.
//! Predictions use the device's own classifier code, so the accuracies are the device's.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use figurine_recognizer::bayes::{AxisModel, MAX_EFFORT_FEATURES, MIN_VARIANCE};
use figurine_recognizer::features::{segment_features, Accum, FEATURES};

use super::effort_model::{feature_name, AxisFile, EffortFile, FeatureParams};
use super::feed::{gesture_runs, log_runs, log_samples};
use super::report;
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

/// Arguments of `figurine train-effort`.
#[derive(Args, Debug)]
pub struct TrainEffortArgs {
    /// Output model (EFFORT.json); a PNG report is written next to it (EFFORT.png).
    #[arg(long)]
    pub out: PathBuf,
    /// Folder with the four state sub-folders of one-gesture logs.
    pub dir: PathBuf,
}

/// One labelled example: features and (sudden?, strong?).
#[derive(Debug, Clone)]
pub struct Example {
    /// The 50 log-domain features.
    pub f: [f32; FEATURES],
    /// Sudden (true) or sustained.
    pub sudden: bool,
    /// Strong (true) or light.
    pub strong: bool,
}

/// Features of a one-gesture log (None if it has no motion).
pub fn gesture_features(log: &PoseLog) -> Option<[f32; FEATURES]> {
    let (samples, _) = log_samples(log);
    let runs = log_runs(&samples);
    let g = gesture_runs(&runs);
    if g.is_empty() {
        return None;
    }
    let mut acc = Accum::new();
    for r in g {
        acc.merge(&r.acc);
    }
    Some(segment_features(&acc))
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
        prior_log_odds: prior,
        features: features
            .iter()
            .map(|&f| FeatureParams {
                index: f as u8,
                name: feature_name(f),
                positive: stats(&pos, f),
                negative: stats(&neg, f),
            })
            .collect(),
        cv_accuracy: None,
    }
}

/// Device-side prediction with an axis file.
pub fn predict(ax: &AxisFile, f: &[f32; FEATURES]) -> f32 {
    let mut m = AxisModel {
        m: ax.features.len().min(MAX_EFFORT_FEATURES) as u8,
        idx: [0; MAX_EFFORT_FEATURES],
        prior: ax.prior_log_odds,
        params: [[0.0; 4]; MAX_EFFORT_FEATURES],
    };
    for (k, p) in ax.features.iter().take(MAX_EFFORT_FEATURES).enumerate() {
        m.idx[k] = p.index;
        m.params[k] = [p.positive[0], p.positive[1], p.negative[0], p.negative[1]];
    }
    m.value(f)
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
pub fn cv_predictions(ex: &[Example], axis: Axis, m: usize) -> Vec<f32> {
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
        let model = fit(&train, axis, &top);
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
    /// CV accuracy for M = 1..=MAX per axis.
    pub curves: [Vec<f64>; 2],
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
    for (a, axis) in [Axis::Time, Axis::Weight].into_iter().enumerate() {
        let (pos, neg) = (
            ex.iter().filter(|e| axis.label(e)).count(),
            ex.iter().filter(|e| !axis.label(e)).count(),
        );
        if pos == 0 || neg == 0 {
            bail!("{axis:?}: need examples of both classes ({pos} positive, {neg} negative)");
        }
        let mut best = (0.0, 1usize);
        for m in 1..=MAX_EFFORT_FEATURES {
            let acc = accuracy(ex, axis, &cv_predictions(ex, axis, m));
            curves[a].push(acc);
            if acc > best.0 + 1e-9 {
                best = (acc, m);
            }
        }
        rel[a] = relevance(&all, axis);
        let top: Vec<usize> = ranking(&all, axis).into_iter().take(best.1).collect();
        let mut file = fit(&all, axis, &top);
        file.cv_accuracy = Some(best.0);
        cv_pred[a] = cv_predictions(ex, axis, best.1);
        axes.push(file);
    }
    let weight = axes.pop().context("weight axis")?;
    let time = axes.pop().context("time axis")?;
    Ok(Trained {
        file: EffortFile::new(time, weight)?,
        curves,
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

/// `figurine train-effort`.
pub fn run(args: &TrainEffortArgs) -> Result<()> {
    let ex = read_dir(&args.dir)?;
    let t = train(&ex).with_context(|| format!("training from {}", args.dir.display()))?;
    t.file.write(&args.out)?;
    for (a, (name, ax)) in [("Time", &t.file.time), ("Weight", &t.file.weight)]
        .iter()
        .enumerate()
    {
        println!(
            "{name}: {} features, cross-validated accuracy {:.1}% (M=1..{}: {})",
            ax.features.len(),
            100.0 * ax.cv_accuracy.unwrap_or(0.0),
            MAX_EFFORT_FEATURES,
            t.curves[a]
                .iter()
                .map(|c| format!("{:.0}", 100.0 * c))
                .collect::<Vec<_>>()
                .join(" ")
        );
        for f in &ax.features {
            println!(
                "  {:>2} {:<24} ratio {:.3}",
                f.index,
                f.name,
                t.relevance[a][usize::from(f.index)]
            );
        }
    }
    let state_ok = ex
        .iter()
        .enumerate()
        .filter(|(i, e)| {
            (t.cv_pred[0][*i] > 0.0) == e.sudden && (t.cv_pred[1][*i] > 0.0) == e.strong
        })
        .count();
    println!(
        "state (both axes) cross-validated accuracy {:.1}% over {} examples",
        100.0 * state_ok as f64 / ex.len() as f64,
        ex.len()
    );
    let png = args.out.with_extension("png");
    report::effort_report(&png, &ex, &t)?;
    println!("wrote {} and {}", args.out.display(), png.display());
    Ok(())
}
