//! `figurine eval sweep`: how recognition holds up as the tracker gets noisier or slower and
//! the doodle smaller or bigger.
//!
//! Each point of an axis reruns `figurine eval --pairs K` with that one knob pinned (learning
//! and test alike, as a user records examples with the tracker they play with) and every other
//! knob at its default range; a row is the mean over the K seed pairs of isolated-gesture
//! accuracy and sequence F1. The axes:
//! - **noise**: multiplier of the generator's sensor noise, hand tremor and drift (1 = the
//!   middle of the default 0.5..1.5);
//! - **rate**: nominal tracker rate, Hz (default range 30..240);
//! - **scale**: spatial scale of the doodle. At scale 1 the strokes have the sizes written in
//!   [`mod@crate::synth::gesture`] (a punch reaches 10–20 cm, a jump travels 10–35 cm forward and
//!   rises 15–30 cm); one gesture's bounding box is then 14 cm across at the median over all
//!   actions (3 cm for a turn or a wave, 30 cm for a jump, walk or throw, 70 cm for a run).
//!   Sizes scale linearly, durations as scale^0.4: 0.1 is a tabletop doodle of a few
//!   centimetres, 4 a sweep of the arms up to metres.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use rayon::prelude::*;

use super::eval::{evaluate, prepare, EvalArgs};
use super::eval_pairs::{PairLine, TEST_SEED_STEP};
use crate::chart::{line_chart, save_png, LineChart, LinePanel};
use crate::synth::Range;

/// Arguments of `figurine eval sweep`.
#[derive(Args, Debug, Clone)]
pub struct SweepArgs {
    /// The knob to sweep.
    #[arg(long, value_enum, default_value_t = AxisChoice::All)]
    pub axis: AxisChoice,
    /// Seed pairs per point (pair i learns at --train-seed + i, tests at --seed + 1000·i).
    #[arg(long, default_value_t = 3)]
    pub pairs: usize,
    /// Isolated test gestures per action and pair.
    #[arg(long, default_value_t = 20)]
    pub isolated: usize,
    /// Test sequences per pair.
    #[arg(long, default_value_t = 10)]
    pub sequences: usize,
    /// Test seed of the first pair.
    #[arg(long, default_value_t = 1000)]
    pub seed: u64,
    /// Train seed of the first pair.
    #[arg(long, default_value_t = 1)]
    pub train_seed: u64,
    /// Also draw each axis as a panel of a PNG here (isolated accuracy and F1, 0-100 %).
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// Which axes `--axis` asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AxisChoice {
    /// Sensor noise multiplier.
    Noise,
    /// Tracker rate.
    Rate,
    /// Doodle scale.
    Scale,
    /// All three.
    All,
}

impl AxisChoice {
    /// The axes chosen.
    pub fn axes(self) -> Vec<Axis> {
        match self {
            AxisChoice::Noise => vec![Axis::Noise],
            AxisChoice::Rate => vec![Axis::Rate],
            AxisChoice::Scale => vec![Axis::Scale],
            AxisChoice::All => Axis::ALL.to_vec(),
        }
    }
}

/// A knob of the generator swept by itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Multiplier of sensor noise, tremor and drift (dimensionless).
    Noise,
    /// Nominal tracker rate, Hz.
    Rate,
    /// Spatial scale of the doodle (dimensionless; see the module docs for metres).
    Scale,
}

impl Axis {
    /// Every axis, in the order printed and plotted.
    pub const ALL: [Axis; 3] = [Axis::Noise, Axis::Rate, Axis::Scale];

    /// The `figurine eval` option it pins.
    pub fn name(self) -> &'static str {
        match self {
            Axis::Noise => "noise",
            Axis::Rate => "rate",
            Axis::Scale => "scale",
        }
    }

    /// The values swept.
    pub fn values(self) -> &'static [f64] {
        match self {
            Axis::Noise => &[0.0, 0.5, 1.0, 2.0, 3.0, 4.0],
            Axis::Rate => &[30.0, 60.0, 120.0, 240.0, 500.0, 1000.0],
            Axis::Scale => &[0.1, 0.25, 0.5, 1.0, 2.0, 4.0],
        }
    }

    /// What the values mean, with the unit, for the table heading.
    pub fn meaning(self) -> &'static str {
        match self {
            Axis::Noise => {
                "sensor noise, tremor and drift, times the generator's (default 0.5..1.5)"
            }
            Axis::Rate => "nominal tracker rate, Hz (default 30..240)",
            Axis::Scale => {
                "doodle scale (default 0.5..2): 1 = one gesture 14 cm across at the median \
                 (3 cm turn or wave, 30 cm jump or walk, 70 cm run); 0.1 a tabletop doodle, \
                 4 a sweep of the arms"
            }
        }
    }

    /// The x axis label of its plot panel.
    pub fn x_label(self) -> &'static str {
        match self {
            Axis::Noise => "NOISE MULTIPLIER (1 = TYPICAL)",
            Axis::Rate => "TRACKER RATE (HZ)",
            Axis::Scale => "DOODLE SCALE (1 = 14 CM MEDIAN GESTURE)",
        }
    }

    /// The `figurine eval` arguments of pair `pair` at `value`.
    pub fn eval_args(self, s: &SweepArgs, value: f64, pair: u64) -> EvalArgs {
        let pin = Some(Range::fixed(value));
        EvalArgs {
            seed: s.seed.wrapping_add(TEST_SEED_STEP.wrapping_mul(pair)),
            train_seed: s.train_seed.wrapping_add(pair),
            examples: 3,
            effort_per_class: 40,
            isolated: s.isolated,
            sequences: s.sequences,
            sequence_len: 6,
            library: None,
            effort: None,
            save_library: None,
            save_effort: None,
            verbose: false,
            pairs: 1,
            noise: if self == Axis::Noise { pin } else { None },
            rate: if self == Axis::Rate { pin } else { None },
            scale: if self == Axis::Scale { pin } else { None },
        }
    }
}

/// One row: a value and the means (and ranges) over its seed pairs, as fractions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepPoint {
    /// The knob's value.
    pub value: f64,
    /// Isolated-gesture accuracy: mean, smallest, largest over the pairs.
    pub isolated: (f64, f64, f64),
    /// Sequence F1: mean, smallest, largest over the pairs.
    pub f1: (f64, f64, f64),
}

/// Mean, smallest and largest of `v` (NaNs for none).
fn spread(v: impl Iterator<Item = f64> + Clone) -> (f64, f64, f64) {
    let n = v.clone().count();
    if n == 0 {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    (
        v.clone().sum::<f64>() / n as f64,
        v.clone().fold(f64::INFINITY, f64::min),
        v.fold(f64::NEG_INFINITY, f64::max),
    )
}

/// One pair's evaluation: learn and train at its train seed with the pinned knob, test at its
/// test seed — what `figurine eval` does without `--library` / `--effort`.
fn evaluate_pair(args: &EvalArgs) -> Result<PairLine> {
    let knobs = args.knobs();
    knobs.validate().map_err(anyhow::Error::msg)?;
    let (mut lib, effort) = prepare(args, &knobs)?;
    Ok(PairLine::of(&evaluate(args, &mut lib, effort, &knobs)?))
}

/// Evaluates `values` of `axis`, every (value, pair) in parallel; rows in `values` order.
pub fn sweep_axis(s: &SweepArgs, axis: Axis, values: &[f64]) -> Result<Vec<SweepPoint>> {
    let jobs: Vec<(usize, u64)> = (0..values.len())
        .flat_map(|v| (0..s.pairs as u64).map(move |p| (v, p)))
        .collect();
    let lines: Vec<(usize, PairLine)> = jobs
        .par_iter()
        .map(|&(v, p)| Ok((v, evaluate_pair(&axis.eval_args(s, values[v], p))?)))
        .collect::<Result<_>>()?;
    Ok(values
        .iter()
        .enumerate()
        .map(|(v, &value)| {
            let of = lines.iter().filter(|(i, _)| *i == v).map(|(_, l)| l);
            SweepPoint {
                value,
                isolated: spread(of.clone().map(|l| l.isolated)),
                f1: spread(of.map(|l| l.f1)),
            }
        })
        .collect())
}

/// A value as the table and plot show it: no trailing zeros.
fn value_text(v: f64) -> String {
    let s = format!("{v}");
    s.strip_suffix(".0").map_or(s.clone(), str::to_string)
}

/// The printed table of one axis: a heading, the equivalent `figurine eval` command, and a row
/// per value (percentages).
pub fn table(s: &SweepArgs, axis: Axis, points: &[SweepPoint]) -> String {
    let mut out = format!(
        "{}: {}\n  each row: figurine eval --pairs {} --isolated {} --sequences {} --seed {} \
         --train-seed {} --{} VALUE (mean over the pairs, and their range)\n",
        axis.name(),
        axis.meaning(),
        s.pairs,
        s.isolated,
        s.sequences,
        s.seed,
        s.train_seed,
        axis.name()
    );
    out += &format!(
        "{:>8} {:>9} {:>13} {:>8} {:>13}\n",
        axis.name(),
        "isolated",
        "(range)",
        "F1",
        "(range)"
    );
    for p in points {
        out += &format!(
            "{:>8} {:>8.1}% {:>13} {:>7.1}% {:>13}\n",
            value_text(p.value),
            100.0 * p.isolated.0,
            format!("[{:.1}-{:.1}]", 100.0 * p.isolated.1, 100.0 * p.isolated.2),
            100.0 * p.f1.0,
            format!("[{:.1}-{:.1}]", 100.0 * p.f1.1, 100.0 * p.f1.2),
        );
    }
    out
}

/// The line chart: a panel per axis, isolated accuracy and F1 over the values, 0–100 %.
pub fn chart(s: &SweepArgs, results: &[(Axis, Vec<SweepPoint>)]) -> LineChart {
    LineChart {
        title: format!(
            "ROBUSTNESS: MEAN OF {} SEED PAIRS, {} GESTURES PER ACTION, {} SEQUENCES",
            s.pairs, s.isolated, s.sequences
        ),
        y_label: "ACCURACY (%)".into(),
        y_range: (0.0, 100.0),
        y_step: 10.0,
        series: vec!["ISOLATED GESTURES".into(), "SEQUENCE F1".into()],
        panels: results
            .iter()
            .map(|(axis, points)| LinePanel {
                title: format!("{} (OTHERS AT DEFAULT RANGES)", axis.name()),
                x_label: axis.x_label().into(),
                xs: points.iter().map(|p| value_text(p.value)).collect(),
                ys: vec![
                    points.iter().map(|p| 100.0 * p.isolated.0).collect(),
                    points.iter().map(|p| 100.0 * p.f1.0).collect(),
                ],
            })
            .collect(),
    }
}

/// `figurine eval sweep`.
pub fn run(s: &SweepArgs) -> Result<()> {
    if s.pairs == 0 || s.isolated == 0 || s.sequences == 0 {
        bail!("--pairs, --isolated and --sequences must be at least 1");
    }
    let mut results = Vec::new();
    for axis in s.axis.axes() {
        let clock = Instant::now();
        let points = sweep_axis(s, axis, axis.values())?;
        print!("{}", table(s, axis, &points));
        println!("  ({:.1} s)", clock.elapsed().as_secs_f64());
        results.push((axis, points));
    }
    if let Some(p) = &s.plot {
        save_png(&line_chart(&chart(s, &results)), p)?;
        println!("wrote {}", p.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args() -> SweepArgs {
        SweepArgs {
            axis: AxisChoice::All,
            pairs: 3,
            isolated: 20,
            sequences: 10,
            seed: 1000,
            train_seed: 1,
            plot: None,
        }
    }

    #[test]
    fn the_sweep_has_the_rows_asked_for() {
        let s = args();
        assert_eq!(s.axis.axes(), Axis::ALL);
        assert_eq!(Axis::Noise.values(), [0.0, 0.5, 1.0, 2.0, 3.0, 4.0]);
        assert_eq!(
            Axis::Rate.values(),
            [30.0, 60.0, 120.0, 240.0, 500.0, 1000.0]
        );
        assert_eq!(Axis::Scale.values(), [0.1, 0.25, 0.5, 1.0, 2.0, 4.0]);
        for axis in Axis::ALL {
            let points: Vec<SweepPoint> = axis
                .values()
                .iter()
                .map(|&value| SweepPoint {
                    value,
                    isolated: (0.9, 0.8, 1.0),
                    f1: (0.95, 0.9, 1.0),
                })
                .collect();
            let t = table(&s, axis, &points);
            let rows: Vec<&str> = t.lines().skip(3).collect();
            assert_eq!(rows.len(), axis.values().len());
            for (row, &v) in rows.iter().zip(axis.values()) {
                let cols: Vec<&str> = row.split_whitespace().collect();
                assert_eq!(cols[0], value_text(v));
                assert_eq!(cols[1], "90.0%");
                assert_eq!(cols[3], "95.0%");
            }
        }
        // Only the pinned knob changes; the pairs step as in `eval --pairs`.
        let e = Axis::Rate.eval_args(&s, 500.0, 2);
        assert_eq!(e.rate, Some(Range::fixed(500.0)));
        assert_eq!((e.noise, e.scale), (None, None));
        assert_eq!((e.seed, e.train_seed), (3000, 3));
        assert!(e.knobs().validate().is_ok());
    }

    #[test]
    fn a_point_is_the_mean_of_its_pairs() {
        let s = SweepArgs {
            pairs: 2,
            isolated: 1,
            sequences: 1,
            ..args()
        };
        let p = sweep_axis(&s, Axis::Noise, &[0.0]).unwrap();
        assert_eq!(p.len(), 1);
        let (mean, lo, hi) = p[0].isolated;
        assert!((0.0..=1.0).contains(&mean) && lo <= mean && mean <= hi);
        let c = chart(&s, &[(Axis::Noise, p)]);
        assert_eq!(c.panels[0].ys.len(), 2);
        assert_eq!(c.panels[0].xs, ["0"]);
    }
}
