//! `figurine eval rest`: false alarms per hour of a figurine that plays no action.
//!
//! Hours of generated rest ([`crate::synth::rest`]: held in a hand, set on a table, mounted on
//! a stand, each under every tracker level) go through the recognizer exactly as `simulate`
//! feeds it — wire-quantised samples, revisions folded into the events they revise
//! ([`log_events`]) — so the count is what the firmware would send. Every event is a
//! false alarm. Counted with the shipped library (compiled into the binary) and with libraries
//! learnt from 3 examples per action at other seeds, since a user's own library may be looser
//! or tighter than the shipped one.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Result};
use clap::Args;
use figurine_recognizer::EffortModel;
use rayon::prelude::*;

use super::eval::learn_synth_library;
use super::feed::log_events;
use super::simulate::{load_effort, load_library};
use crate::chart::{bar_chart, save_png, BarChart, BarPanel};
use crate::synth::rest::MAX_REST_SECONDS;
use crate::synth::sequence::item_seed;
use crate::synth::{rest_log, Knobs, Range, RestKind, RestSpec, TrackerLevel, TRACKER_LEVELS};

/// Arguments of `figurine eval rest`.
#[derive(Args, Debug, Clone)]
pub struct RestBenchArgs {
    /// Rest to generate in all, hours: at least this much, in whole logs, the same number for
    /// every kind × tracker level.
    #[arg(long, default_value_t = 3.0)]
    pub hours: f64,
    /// Length of each rest log, minutes.
    #[arg(long, default_value_t = 5.0)]
    pub minutes: f64,
    /// Master seed of the rest logs.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Libraries learnt from synthetic examples to count with, besides the shipped one.
    #[arg(long, default_value_t = 3)]
    pub learnt: usize,
    /// Seed of the first learnt library; the others take the next seeds (the shipped library
    /// was learnt at seed 1).
    #[arg(long, default_value_t = 2)]
    pub train_seed: u64,
    /// Examples per action of the learnt libraries.
    #[arg(long, default_value_t = 3)]
    pub examples: usize,
    /// Spatial scale of the learnt libraries' examples (default 0.5..2; a tabletop player's
    /// 0.3 makes gestures of about 4 cm, only a few times a fidget's reach).
    #[arg(long)]
    pub scale: Option<Range>,
    /// Also draw false alarms per hour by tracker level and kind as a PNG bar chart here.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// List every false alarm of the shipped library, and every log a learnt library fired on,
    /// with the commands that replay them (through the written CSV, whose rounding can tip an
    /// alarm at the edge either way).
    #[arg(long)]
    pub verbose: bool,
}

impl RestBenchArgs {
    /// The generator's knobs for the learnt libraries' examples (`--scale`, else the defaults).
    pub fn learn_knobs(&self) -> Knobs {
        let mut k = Knobs::default();
        if let Some(r) = self.scale {
            k.scale = r;
        }
        k
    }
}

/// One kind of rest under one tracker level: a row of the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// What the figurine rests on.
    pub kind: RestKind,
    /// Which tracker sees it.
    pub tracker: TrackerLevel,
}

/// Every kind × tracker level, kind by kind.
pub fn cells() -> Vec<Cell> {
    RestKind::ALL
        .iter()
        .flat_map(|&kind| {
            TRACKER_LEVELS
                .iter()
                .map(move |&tracker| Cell { kind, tracker })
        })
        .collect()
}

/// Logs of `minutes` each per cell, so that all cells together hold at least `hours`.
pub fn logs_per_cell(hours: f64, minutes: f64) -> usize {
    let per_cell_min = hours * 60.0 / cells().len() as f64;
    ((per_cell_min / minutes).ceil() as usize).max(1)
}

/// A library to count with: action names and device blob.
#[derive(Debug, Clone)]
pub struct Counted {
    /// Action names, by device index.
    pub names: Vec<String>,
    /// The library as the device loads it.
    pub blob: Vec<u8>,
}

/// One false alarm of the shipped library.
#[derive(Debug, Clone, PartialEq)]
pub struct Alarm {
    /// The action reported.
    pub action: String,
    /// Its start and end, seconds on the log's clock.
    pub span: (f64, f64),
}

/// What the recognizer reported on one rest log.
#[derive(Debug, Clone, PartialEq)]
pub struct LogCount {
    /// Index into [`cells`].
    pub cell: usize,
    /// The log's seed (`figurine synth rest --seed`).
    pub seed: u64,
    /// Time the log spans, seconds.
    pub seconds: f64,
    /// Samples in the log.
    pub samples: usize,
    /// The shipped library's events.
    pub shipped: Vec<Alarm>,
    /// Event count of each learnt library.
    pub learnt: Vec<usize>,
}

/// Sums over logs: a row of the table.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Tally {
    /// Logs counted.
    pub logs: usize,
    /// Rest they span, hours.
    pub hours: f64,
    /// Events of the shipped library.
    pub shipped: usize,
    /// Events of the learnt libraries, summed over them.
    pub learnt: usize,
}

impl Tally {
    /// Adds one log.
    pub fn add(&mut self, c: &LogCount) {
        self.logs += 1;
        self.hours += c.seconds / 3600.0;
        self.shipped += c.shipped.len();
        self.learnt += c.learnt.iter().sum::<usize>();
    }

    /// Shipped-library false alarms per hour.
    pub fn shipped_per_hour(&self) -> f64 {
        self.shipped as f64 / self.hours.max(1e-12)
    }

    /// Learnt libraries' false alarms per hour, the mean over `libraries` of them (NaN without).
    pub fn learnt_per_hour(&self, libraries: usize) -> f64 {
        if libraries == 0 {
            return f64::NAN;
        }
        self.learnt as f64 / (libraries as f64 * self.hours.max(1e-12))
    }
}

/// Generates every rest log and counts each library's events on it, in parallel over logs.
pub fn measure(
    args: &RestBenchArgs,
    shipped: &Counted,
    learnt: &[Counted],
    effort: EffortModel,
) -> Result<Vec<LogCount>> {
    let cells = cells();
    let per_cell = logs_per_cell(args.hours, args.minutes);
    let jobs: Vec<(usize, u64)> = (0..cells.len())
        .flat_map(|c| (0..per_cell).map(move |k| (c, k)))
        .map(|(c, k)| (c, item_seed(args.seed, (c * 1000 + k) as u64)))
        .collect();
    let blobs: Vec<&[u8]> = std::iter::once(shipped)
        .chain(learnt)
        .map(|l| l.blob.as_slice())
        .collect();
    jobs.par_iter()
        .map(|&(cell, seed)| {
            let spec = RestSpec {
                seconds: args.minutes * 60.0,
                kind: Some(cells[cell].kind),
                tracker: Some(cells[cell].tracker),
                rate_hz: None,
                knobs: Knobs::default(),
            };
            let r = rest_log(seed, &spec);
            let s = &r.log.samples;
            let seconds = match (s.first(), s.last()) {
                (Some(a), Some(b)) => b.t - a.t,
                _ => 0.0,
            };
            let mut events = log_events(&r.log, &blobs, effort)?.into_iter();
            let shipped_events = events.next().unwrap_or_default();
            Ok(LogCount {
                cell,
                seed,
                seconds,
                samples: s.len(),
                shipped: shipped_events
                    .iter()
                    .map(|e| Alarm {
                        action: shipped
                            .names
                            .get(usize::from(e.action))
                            .cloned()
                            .unwrap_or_else(|| format!("#{}", e.action)),
                        span: (e.start_us as f64 * 1e-6, e.end_us as f64 * 1e-6),
                    })
                    .collect(),
                learnt: events.map(|e| e.len()).collect(),
            })
        })
        .collect()
}

/// Per-cell tallies (in [`cells`] order) and the total.
pub fn tally(counts: &[LogCount]) -> (Vec<Tally>, Tally) {
    let mut rows = vec![Tally::default(); cells().len()];
    let mut total = Tally::default();
    for c in counts {
        rows[c.cell].add(c);
        total.add(c);
    }
    (rows, total)
}

fn per_hour(v: f64) -> String {
    if v.is_nan() {
        "-".into()
    } else {
        format!("{v:.2}")
    }
}

/// The printed table: a row per kind × tracker level and a total row.
pub fn table(rows: &[Tally], total: &Tally, libraries: usize) -> String {
    let mut out = format!(
        "{:<8} {:<12} {:>6} {:>5} {:>15} {:>15} {:>15}\n",
        "kind", "tracker", "hours", "logs", "events shipped", "shipped /h", "learnt /h"
    );
    let line = |kind: &str, tracker: &str, t: &Tally| {
        format!(
            "{:<8} {:<12} {:>6.2} {:>5} {:>15} {:>15} {:>15}\n",
            kind,
            tracker,
            t.hours,
            t.logs,
            t.shipped,
            per_hour(t.shipped_per_hour()),
            per_hour(t.learnt_per_hour(libraries))
        )
    };
    for (cell, t) in cells().iter().zip(rows) {
        out += &line(cell.kind.name(), cell.tracker.name, t);
    }
    out + &line("ALL", "", total)
}

/// The summary line: `rest: X h, false alarms per hour: shipped A, learnt B`.
pub fn summary(total: &Tally, libraries: usize) -> String {
    format!(
        "rest: {:.1} h, false alarms per hour: shipped {}, learnt {}",
        total.hours,
        per_hour(total.shipped_per_hour()),
        per_hour(total.learnt_per_hour(libraries))
    )
}

/// The bar chart: false alarms per hour by tracker level (groups) and kind (bars), one panel
/// for the shipped library and one for the learnt libraries' mean.
pub fn chart(rows: &[Tally], total: &Tally, libraries: usize, minutes: f64) -> BarChart {
    let cells = cells();
    let panel = |title: String, value: &dyn Fn(&Tally) -> f64| BarPanel {
        title,
        groups: TRACKER_LEVELS.iter().map(|l| l.name.to_string()).collect(),
        values: TRACKER_LEVELS
            .iter()
            .map(|l| {
                RestKind::ALL
                    .iter()
                    .map(|&k| {
                        cells
                            .iter()
                            .position(|c| c.kind == k && c.tracker.name == l.name)
                            .map_or(f64::NAN, |i| value(&rows[i]))
                    })
                    .collect()
            })
            .collect(),
    };
    let mut panels = vec![panel(
        format!(
            "SHIPPED LIBRARY: {} PER HOUR OVERALL",
            per_hour(total.shipped_per_hour())
        ),
        &|t: &Tally| t.shipped_per_hour(),
    )];
    if libraries > 0 {
        panels.push(panel(
            format!(
                "{libraries} LEARNT LIBRARIES (MEAN): {} PER HOUR",
                per_hour(total.learnt_per_hour(libraries))
            ),
            &|t: &Tally| t.learnt_per_hour(libraries),
        ));
    }
    BarChart {
        title: format!(
            "FALSE ALARMS AT REST: {:.1} H OF LOGS ({} OF {} MIN)",
            total.hours, total.logs, minutes
        ),
        y_label: "FALSE ALARMS PER HOUR".into(),
        x_label: "TRACKER LEVEL".into(),
        series: RestKind::ALL
            .iter()
            .map(|k| format!("{} REST", k.name()))
            .collect(),
        panels,
    }
}

/// `figurine eval rest`.
pub fn run(args: &RestBenchArgs) -> Result<()> {
    if !(args.minutes > 0.0 && args.minutes * 60.0 <= MAX_REST_SECONDS) {
        bail!(
            "--minutes {}: must be above 0 and at most {}",
            args.minutes,
            MAX_REST_SECONDS / 60.0
        );
    }
    if !(args.hours > 0.0 && args.hours <= 1000.0) {
        bail!("--hours {}: must be above 0 and at most 1000", args.hours);
    }
    let clock = Instant::now();
    let (lib, blob) = load_library(None)?;
    let shipped = Counted {
        names: lib.names(),
        blob,
    };
    let effort = load_effort(None)?;
    let seeds: Vec<u64> = (0..args.learnt as u64)
        .map(|i| args.train_seed.wrapping_add(i))
        .collect();
    eprintln!(
        "learning {} libraries from {} examples per action (seeds {seeds:?})…",
        args.learnt, args.examples
    );
    let learnt: Vec<Counted> = seeds
        .par_iter()
        .map(|&s| {
            let mut lib = learn_synth_library(s, args.examples, &args.learn_knobs())?;
            Ok(Counted {
                names: lib.names(),
                blob: lib.blob()?,
            })
        })
        .collect::<Result<_>>()?;
    let learn_s = clock.elapsed().as_secs_f64();
    let per_cell = logs_per_cell(args.hours, args.minutes);
    eprintln!(
        "generating and recognising {} rest logs of {} min…",
        per_cell * cells().len(),
        args.minutes
    );
    let counts = measure(args, &shipped, &learnt, effort)?;
    let (rows, total) = tally(&counts);
    let samples: usize = counts.iter().map(|c| c.samples).sum();
    println!(
        "Rest logs (seed {}): {per_cell} of {} min per kind × tracker level; every event is a \
         false alarm. Libraries: shipped, and {} learnt from {} examples per action at scale \
         {} (seeds {seeds:?}).",
        args.seed,
        args.minutes,
        args.learnt,
        args.examples,
        args.learn_knobs().scale
    );
    print!("{}", table(&rows, &total, learnt.len()));
    let mut by_action = std::collections::BTreeMap::<&str, usize>::new();
    for a in counts.iter().flat_map(|c| &c.shipped) {
        *by_action.entry(a.action.as_str()).or_default() += 1;
    }
    if !by_action.is_empty() {
        let list: Vec<String> = by_action.iter().map(|(a, n)| format!("{a} {n}")).collect();
        println!(
            "shipped library's false alarms by action: {}",
            list.join(", ")
        );
    }
    let each: Vec<String> = (0..learnt.len())
        .map(|n| {
            counts
                .iter()
                .map(|c| c.learnt[n])
                .sum::<usize>()
                .to_string()
        })
        .collect();
    println!(
        "learnt libraries' events (seeds {seeds:?}): {}",
        each.join(", ")
    );
    for c in counts.iter().filter(|_| args.verbose) {
        let (kind, tracker) = (cells()[c.cell].kind, cells()[c.cell].tracker.name);
        for a in &c.shipped {
            println!(
                "  {} {:.2}-{:.2} s on {kind} rest, {tracker} (figurine synth rest --seed {} \
                 --seconds {} --kind {kind} --tracker {tracker} --out r.csv && figurine \
                 simulate r.csv)",
                a.action,
                a.span.0,
                a.span.1,
                c.seed,
                args.minutes * 60.0,
            );
        }
        for (&n, seed) in c.learnt.iter().zip(&seeds).filter(|(&n, _)| n > 0) {
            println!(
                "  library of train seed {seed}: {n} on {kind} rest, {tracker} (figurine synth \
                 rest --seed {} --seconds {} --kind {kind} --tracker {tracker} --out r.csv && \
                 figurine eval --train-seed {seed} --examples {} --scale {} --save-library \
                 l.json && figurine simulate --library l.json r.csv)",
                c.seed,
                args.minutes * 60.0,
                args.examples,
                args.learn_knobs().scale,
            );
        }
    }
    println!(
        "{} samples through {} libraries: {:.1} s ({:.1} s of it learning)",
        samples,
        1 + learnt.len(),
        clock.elapsed().as_secs_f64(),
        learn_s
    );
    if let Some(p) = &args.plot {
        save_png(
            &bar_chart(&chart(&rows, &total, learnt.len(), args.minutes)),
            p,
        )?;
        println!("wrote {}", p.display());
    }
    println!("{}", summary(&total, learnt.len()));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tallies_count_every_event_of_every_library() {
        let log = |cell, seconds, alarms: usize, learnt: [usize; 2]| LogCount {
            cell,
            seed: 0,
            seconds,
            samples: 10,
            shipped: vec![
                Alarm {
                    action: "run".into(),
                    span: (1.0, 2.0)
                };
                alarms
            ],
            learnt: learnt.to_vec(),
        };
        let counts = [
            log(0, 1800.0, 2, [1, 3]),
            log(0, 1800.0, 0, [0, 0]),
            log(5, 3600.0, 1, [2, 0]),
        ];
        let (rows, total) = tally(&counts);
        assert_eq!(rows[0].logs, 2);
        assert!((rows[0].hours - 1.0).abs() < 1e-12);
        assert_eq!(rows[0].shipped_per_hour(), 2.0);
        assert_eq!(rows[0].learnt_per_hour(2), 2.0);
        assert_eq!(total.shipped, 3);
        assert_eq!(total.learnt_per_hour(2), 1.5);
        assert_eq!(
            summary(&total, 2),
            "rest: 2.0 h, false alarms per hour: shipped 1.50, learnt 1.50"
        );
    }

    #[test]
    fn learnt_libraries_take_the_scale_asked() {
        #[derive(clap::Parser)]
        struct Cli {
            #[command(flatten)]
            rest: RestBenchArgs,
        }
        use clap::Parser as _;
        let cli = Cli::try_parse_from(["rest", "--scale", "0.3"]).unwrap();
        assert_eq!(cli.rest.learn_knobs().scale, Range::new(0.3, 0.3));
        let cli = Cli::try_parse_from(["rest"]).unwrap();
        assert_eq!(cli.rest.learn_knobs().scale, Knobs::default().scale);
        assert!(Cli::try_parse_from(["rest", "--scale", "big"]).is_err());
    }

    #[test]
    fn the_table_has_a_row_per_kind_and_tracker_level_and_a_total() {
        assert_eq!(cells().len(), 12);
        // Three hours of five-minute logs over 12 cells: three logs each.
        assert_eq!(logs_per_cell(3.0, 5.0), 3);
        assert_eq!(logs_per_cell(2.0, 5.0), 2);
        assert_eq!(logs_per_cell(0.01, 5.0), 1);
        let rows = vec![Tally::default(); 12];
        let t = table(&rows, &Tally::default(), 3);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines.len(), 1 + 12 + 1);
        for kind in RestKind::ALL {
            for level in TRACKER_LEVELS {
                assert!(
                    lines
                        .iter()
                        .any(|l| l.split_whitespace().take(2).eq([kind.name(), level.name])),
                    "no row for {kind} {}",
                    level.name
                );
            }
        }
        assert!(lines[13].starts_with("ALL"));
        let c = chart(&rows, &Tally::default(), 3, 5.0);
        assert_eq!(c.panels.len(), 2);
        assert_eq!(c.panels[0].values.len(), TRACKER_LEVELS.len());
        assert!(c.panels[0].values.iter().all(|v| v.len() == 3));
    }
}
