//! `figurine train-effort` and its report: the model trained ([`super::effort_train`]), what
//! it prints (each axis's classifier, features and cross-validated accuracy) and its PNG
//! (feature ranking, selection curves, confusion matrices).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use figurine_recognizer::bayes::MAX_EFFORT_FEATURES;
use figurine_recognizer::features::FEATURES;
use image::{Rgb, RgbImage};

use super::effort_model::ClassifierKind;
use super::effort_train::{read_dir, train, Example, Trained};
use crate::raster::{draw_text, fill_rect, line};

/// Short name of a classifier for the report.
fn classifier(k: ClassifierKind) -> &'static str {
    match k {
        ClassifierKind::NaiveBayes => "NB",
        ClassifierKind::Linear => "LDA",
    }
}

const W: u32 = 960;
const H: u32 = 720;
const INK: Rgb<u8> = Rgb([30, 30, 40]);
const GRID: Rgb<u8> = Rgb([215, 215, 222]);
const TIME_C: Rgb<u8> = Rgb([215, 95, 40]);
const WEIGHT_C: Rgb<u8> = Rgb([40, 110, 200]);
const DIM: Rgb<u8> = Rgb([180, 180, 190]);

#[allow(clippy::too_many_arguments)] // a plot panel: position, size, data, style
fn bars(
    img: &mut RgbImage,
    x: i64,
    y: i64,
    w: i64,
    h: i64,
    ratio: &[f64; FEATURES],
    chosen: &[u8],
    c: Rgb<u8>,
    title: &str,
) {
    draw_text(img, x, y - 22, title, 2, INK);
    let max = ratio.iter().cloned().fold(1e-9, f64::max);
    let bw = w / FEATURES as i64;
    line(img, (x, y + h), (x + w, y + h), INK);
    for (i, &r) in ratio.iter().enumerate() {
        let bh = ((r / max) * h as f64).round() as i64;
        let col = if chosen.contains(&(i as u8)) { c } else { DIM };
        fill_rect(img, x + i as i64 * bw + 1, y + h - bh, bw - 2, bh, col);
        if i % 5 == 0 {
            draw_text(img, x + i as i64 * bw, y + h + 4, &i.to_string(), 1, INK);
        }
    }
    draw_text(
        img,
        x,
        y + h + 16,
        "FEATURE (0-26 MEAN, 27-53 CV), COLOURED = SELECTED",
        1,
        INK,
    );
    draw_text(img, x + w - 90, y - 10, &format!("MAX {max:.2}"), 1, INK);
}

fn curves(img: &mut RgbImage, x: i64, y: i64, w: i64, h: i64, t: &Trained) {
    draw_text(img, x, y - 22, "CV ACCURACY VS M", 2, INK);
    let lo = 0.4;
    for k in 0..=6 {
        let v = lo + k as f64 * 0.1;
        let yy = y + h - ((v - lo) / (1.0 - lo) * h as f64) as i64;
        line(img, (x, yy), (x + w, yy), GRID);
        draw_text(img, x - 30, yy - 3, &format!("{:.0}", v * 100.0), 1, INK);
    }
    for (a, c) in [TIME_C, WEIGHT_C].into_iter().enumerate() {
        let n = t.curves[a].len().max(2);
        let pt = |i: usize, v: f64| {
            (
                x + (i as i64 * w) / (n as i64 - 1),
                y + h - (((v - lo) / (1.0 - lo)).clamp(0.0, 1.0) * h as f64) as i64,
            )
        };
        for i in 1..t.curves[a].len() {
            let (p0, p1) = (pt(i - 1, t.curves[a][i - 1]), pt(i, t.curves[a][i]));
            line(img, p0, p1, c);
            line(img, (p0.0, p0.1 + 1), (p1.0, p1.1 + 1), c);
        }
        let chosen = if a == 0 {
            t.file.time.features.len()
        } else {
            t.file.weight.features.len()
        };
        if chosen >= 1 {
            let p = pt(chosen - 1, t.curves[a][chosen - 1]);
            fill_rect(img, p.0 - 3, p.1 - 3, 7, 7, c);
        }
    }
    draw_text(
        img,
        x,
        y + h + 6,
        "M = 1 ... 16   TIME (ORANGE)  WEIGHT (BLUE)",
        1,
        INK,
    );
}

fn matrix(
    img: &mut RgbImage,
    x: i64,
    y: i64,
    cell: i64,
    m: &[Vec<usize>],
    labels: &[&str],
    title: &str,
) {
    draw_text(img, x, y - 22, title, 2, INK);
    let n = m.len();
    for (r, row) in m.iter().enumerate() {
        let total: usize = row.iter().sum::<usize>().max(1);
        for (c, &v) in row.iter().enumerate() {
            let f = v as f64 / total as f64;
            let shade = (255.0 - 170.0 * f) as u8;
            let col = if r == c {
                Rgb([shade, 255, shade])
            } else {
                Rgb([255, shade, shade])
            };
            fill_rect(
                img,
                x + 70 + c as i64 * cell,
                y + r as i64 * cell,
                cell - 2,
                cell - 2,
                col,
            );
            draw_text(
                img,
                x + 74 + c as i64 * cell,
                y + r as i64 * cell + cell / 2 - 4,
                &v.to_string(),
                1,
                INK,
            );
        }
        draw_text(
            img,
            x,
            y + r as i64 * cell + cell / 2 - 4,
            labels[r],
            1,
            INK,
        );
    }
    let _ = n;
    draw_text(
        img,
        x + 70,
        y + n as i64 * cell + 2,
        "ROWS TRUE, COLUMNS PREDICTED",
        1,
        INK,
    );
}

/// Writes the report PNG.
pub fn effort_report(path: &Path, ex: &[Example], t: &Trained) -> Result<()> {
    let mut img = RgbImage::from_pixel(W, H, Rgb([250, 250, 252]));
    let sel = |ax: &super::effort_model::AxisFile| -> Vec<u8> {
        ax.features.iter().map(|f| f.index).collect()
    };
    bars(
        &mut img,
        40,
        50,
        400,
        160,
        &t.relevance[0],
        &sel(&t.file.time),
        TIME_C,
        "TIME: RATIO INTER/INTRA",
    );
    bars(
        &mut img,
        520,
        50,
        400,
        160,
        &t.relevance[1],
        &sel(&t.file.weight),
        WEIGHT_C,
        "WEIGHT: RATIO INTER/INTRA",
    );
    curves(&mut img, 70, 300, 360, 160, t);
    let mut tm = vec![vec![0usize; 2]; 2];
    let mut wm = vec![vec![0usize; 2]; 2];
    let mut sm = vec![vec![0usize; 4]; 4];
    for (i, e) in ex.iter().enumerate() {
        let (ps, pw) = (t.cv_pred[0][i] > 0.0, t.cv_pred[1][i] > 0.0);
        tm[usize::from(!e.sudden)][usize::from(!ps)] += 1;
        wm[usize::from(!e.strong)][usize::from(!pw)] += 1;
        let s = |a: bool, b: bool| usize::from(!a) * 2 + usize::from(!b);
        sm[s(e.sudden, e.strong)][s(ps, pw)] += 1;
    }
    matrix(&mut img, 520, 300, 40, &tm, &["SUDDEN", "SUSTAIN"], "TIME");
    matrix(&mut img, 740, 300, 40, &wm, &["STRONG", "LIGHT"], "WEIGHT");
    matrix(
        &mut img,
        520,
        470,
        40,
        &sm,
        &["SUD-STR", "SUD-LIG", "SUS-STR", "SUS-LIG"],
        "STATE",
    );
    let acc = |a: usize| {
        let n = ex.len().max(1) as f64;
        100.0
            * t.cv_pred[a]
                .iter()
                .zip(ex)
                .filter(|(p, e)| (**p > 0.0) == if a == 0 { e.sudden } else { e.strong })
                .count() as f64
            / n
    };
    let state = 100.0 * (0..4).map(|i| sm[i][i]).sum::<usize>() as f64 / ex.len().max(1) as f64;
    draw_text(
        &mut img,
        40,
        560,
        &format!("CROSS-VALIDATED ({} EXAMPLES, 5 FOLDS)", ex.len()),
        2,
        INK,
    );
    draw_text(
        &mut img,
        40,
        590,
        &format!(
            "TIME {:.1}%   WEIGHT {:.1}%   STATE {:.1}%",
            acc(0),
            acc(1),
            state
        ),
        2,
        INK,
    );
    draw_text(
        &mut img,
        40,
        620,
        &format!(
            "TIME {} M={}   WEIGHT {} M={}",
            classifier(t.file.time.classifier),
            t.file.time.features.len(),
            classifier(t.file.weight.classifier),
            t.file.weight.features.len()
        ),
        2,
        INK,
    );
    img.save(path)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}
/// Arguments of `figurine train-effort`.
#[derive(Args, Debug)]
pub struct TrainEffortArgs {
    /// Output model (EFFORT.json); a PNG report is written next to it (EFFORT.png).
    #[arg(long)]
    pub out: PathBuf,
    /// Folder with the four state sub-folders of one-gesture logs.
    pub dir: PathBuf,
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
            "{name}: {} with {} features, cross-validated accuracy {:.1}% (best naive Bayes \
             {:.1}%, linear {:.1}%; M=1..{}: {})",
            match ax.classifier {
                ClassifierKind::NaiveBayes => "naive Bayes",
                ClassifierKind::Linear => "linear discriminant",
            },
            ax.features.len(),
            100.0 * ax.cv_accuracy.unwrap_or(0.0),
            100.0 * t.best_of[a].0,
            100.0 * t.best_of[a].1,
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
    effort_report(&png, &ex, &t)?;
    println!("wrote {} and {}", args.out.display(), png.display());
    Ok(())
}
