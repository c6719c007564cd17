//! `figurine simulate`: the device recognizer run in-process on a recorded pose log.
//!
//! Output: with `--jsonl`, one `figurine_host::events::ActionRecord` JSON object per action
//! (start/end in seconds of the log's clock, time/weight = the device's i8 values / 127, so
//! host and device agree bit for bit); otherwise a readable table and a summary of skipped
//! input. Without `--effort`, the shipped default effort model is used.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use figurine_recognizer::{ActionEvent, EffortModel, Library, Recognizer, Stats};

use super::effort_model::EffortFile;
use super::feed::{log_samples, recognize_log, Clock};
use super::library::LibraryFile;
use crate::events::{write_event, ActionRecord};
use crate::poselog::PoseLog;

/// Arguments of `figurine simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Action library (LIB.json from `figurine learn`); default: the shipped library.
    #[arg(long)]
    pub library: Option<PathBuf>,
    /// Effort model (EFFORT.json from `figurine train-effort`); default: the shipped model.
    #[arg(long)]
    pub effort: Option<PathBuf>,
    /// Print one JSON object per recognised action instead of a table.
    #[arg(long)]
    pub jsonl: bool,
    /// The pose log (CSV).
    pub log: PathBuf,
}

/// Result of simulating one log.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// Events as the host records them (names, seconds, efforts as q/127).
    pub records: Vec<ActionRecord>,
    /// The raw device events.
    pub events: Vec<ActionEvent>,
    /// Recognizer statistics.
    pub stats: Stats,
    /// Log samples the wire could not carry.
    pub unsendable: u64,
}

/// Loads the library (or the default) and its device blob.
pub fn load_library(path: Option<&Path>) -> Result<(LibraryFile, Vec<u8>)> {
    let mut lib = match path {
        Some(p) => LibraryFile::read(p)?,
        None => LibraryFile::default_library()?,
    };
    let blob = lib.blob()?;
    Ok((lib, blob))
}

/// Loads the effort model (or the default).
pub fn load_effort(path: Option<&Path>) -> Result<EffortModel> {
    match path {
        Some(p) => EffortFile::read(p)?.model(),
        None => EffortFile::default_model()?.model(),
    }
}

/// Converts a device event to the host record.
pub fn to_record(e: &ActionEvent, names: &[String], clock: &Clock) -> ActionRecord {
    ActionRecord {
        action: names
            .get(usize::from(e.action))
            .cloned()
            .unwrap_or_else(|| format!("#{}", e.action)),
        start: clock.time_of(e.start_seq),
        end: clock.time_of(e.end_seq),
        time: f64::from(e.time_q) / 127.0,
        weight: f64::from(e.weight_q) / 127.0,
        distance: u32::from(e.distance),
    }
}

/// Runs the recognizer over `log`.
pub fn simulate_log(
    log: &PoseLog,
    names: &[String],
    blob: &[u8],
    effort: Option<EffortModel>,
) -> Result<Simulation> {
    let library =
        Library::from_bytes(blob).map_err(|e| anyhow::anyhow!("library blob refused: {e}"))?;
    let mut rec = Recognizer::new(library, effort);
    let (samples, unsendable) = log_samples(log);
    let events = recognize_log(&mut rec, &samples);
    let clock = Clock::new(log, &samples);
    Ok(Simulation {
        records: events.iter().map(|e| to_record(e, names, &clock)).collect(),
        events,
        stats: rec.stats(),
        unsendable,
    })
}

/// `figurine simulate`.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let (lib, blob) = load_library(args.library.as_deref())?;
    let effort = load_effort(args.effort.as_deref())?;
    let log = PoseLog::read_path(&args.log)?;
    let sim = simulate_log(&log, &lib.names(), &blob, Some(effort))
        .with_context(|| format!("simulating {}", args.log.display()))?;
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    if args.jsonl {
        for r in &sim.records {
            write_event(&mut out, r)?;
        }
    } else {
        writeln!(
            out,
            "{:<12} {:>9} {:>9} {:>7} {:>7}  {:<22} {:>4}",
            "action", "start/s", "end/s", "time", "weight", "effort", "dist"
        )?;
        for r in &sim.records {
            writeln!(
                out,
                "{:<12} {:>9.3} {:>9.3} {:>+7.3} {:>+7.3}  {:<22} {:>4}",
                r.action,
                r.start,
                r.end,
                r.time,
                r.weight,
                effort_words(r.time, r.weight),
                r.distance
            )?;
        }
        let s = sim.stats;
        writeln!(
            out,
            "{} actions; {} samples accepted, {} skipped (non-finite {}, bad quaternion {}, \
             time not increasing {}, jumps {}), {} gaps, {} not sendable on the wire",
            sim.records.len(),
            s.intake.accepted,
            s.intake.skipped(),
            s.intake.non_finite,
            s.intake.bad_quat,
            s.intake.time_not_increasing,
            s.intake.jumps,
            s.intake.gaps,
            sim.unsendable
        )?;
    }
    out.flush()?;
    Ok(())
}

/// "sudden-strong" style words for a (Lt, Lw) pair.
pub fn effort_words(time: f64, weight: f64) -> String {
    format!(
        "{}-{}",
        if time >= 0.0 { "sudden" } else { "sustained" },
        if weight >= 0.0 { "strong" } else { "light" }
    )
}
