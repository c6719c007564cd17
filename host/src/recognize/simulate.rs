//! `figurine simulate`: the device recognizer run in-process on a recorded pose log.
//!
//! Output: with `--jsonl`, one `figurine_host::events::ActionRecord` JSON object per action
//! (start/end in seconds of the log's clock, time/weight = the device's i8 values / 127, so
//! host and device agree bit for bit); otherwise a readable table and a summary of skipped
//! input, and with `--why` the matches the decision stage dropped or read as another action,
//! each with the rule that decided it ([`figurine_recognizer::note`]). Without `--effort`,
//! the shipped default effort model is used.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use figurine_recognizer::history::Run;
use figurine_recognizer::intake::MAX_GAP_US;
use figurine_recognizer::segment::{BRIEF_TURN_RAD, CONTINUE_US, MIN_ACTION_US};
use figurine_recognizer::sweep::MANY_SWEEPS;
use figurine_recognizer::token::{Token, STILL};
use figurine_recognizer::{
    ActionEvent, EffortModel, Library, Note, Recognizer, Sample, Stats, Why,
};

use super::columns::edit_distance;
use super::effort_model::EffortFile;
use super::feed::{
    log_runs_and_noise, log_samples, nothing_moved_words, recognize_log_noted, Clock,
};
use super::library::{parse_tokens, tokens_to_string, LibraryFile};
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
    /// Also print why: every match the decision stage dropped (too brief, not as far as its
    /// action's examples went, the settling of the event before it) or reported as another
    /// action, with the rule that decided it.
    #[arg(long, conflicts_with = "jsonl")]
    pub why: bool,
    /// Read the log as if the figurine had rested this many seconds after its last sample (its
    /// last pose repeated at its last step): what a live figurine reports. Without it the log's
    /// end decides what is still pending, and a phrase no pattern matched or could go on from
    /// is then given its nearest action, which a resting figurine does not do.
    #[arg(long, value_name = "SECONDS")]
    pub rest: Option<f64>,
    /// The pose log (CSV).
    pub log: PathBuf,
}

/// Longest stillness `simulate --rest` appends, s: an hour, far past every wait of the
/// decision stage, bounding the samples it adds (3.6 M at 1 kHz).
pub const MAX_REST_S: f64 = 3600.0;

/// Result of simulating one log.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// Events as the host records them (names, seconds, efforts as q/127).
    pub records: Vec<ActionRecord>,
    /// The raw device events.
    pub events: Vec<ActionEvent>,
    /// The decision stage's notes: matches dropped or read as another action, in order.
    pub notes: Vec<Note>,
    /// The log's clock, for the notes' sequence numbers.
    pub clock: Clock,
    /// Recognizer statistics.
    pub stats: Stats,
    /// Log samples the wire could not carry.
    pub unsendable: u64,
    /// The samples as the device received them, each with its index in the log.
    pub samples: Vec<(usize, Sample)>,
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
        action: name_of(names, e.action),
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
    let (events, notes) = recognize_log_noted(&mut rec, &samples);
    let clock = Clock::new(log, &samples);
    Ok(Simulation {
        records: events.iter().map(|e| to_record(e, names, &clock)).collect(),
        events,
        notes,
        clock,
        stats: rec.stats(),
        unsendable,
        samples,
    })
}

/// `figurine simulate`.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let (lib, blob) = load_library(args.library.as_deref())?;
    let effort = load_effort(args.effort.as_deref())?;
    let mut log = PoseLog::read_path(&args.log)?;
    if let Some(rest) = args.rest {
        if !(0.0..=MAX_REST_S).contains(&rest) {
            bail!("--rest {rest}: give seconds of stillness from 0 to {MAX_REST_S}");
        }
        log = log.rested(rest);
    }
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
        if args.why {
            let mut lines = note_lines(&sim.notes, &lib.names(), &sim.clock);
            lines.extend(unread_lines(&sim, &lib)?);
            lines.extend(lost_lines(&log, &sim));
            lines.sort_by(|a, b| a.start.total_cmp(&b.start));
            write_note_lines(&mut out, &lines)?;
        }
    }
    out.flush()?;
    Ok(())
}

/// A note in a reader's terms: its action's name, its span in seconds on the log's clock,
/// and what was decided ([`why_words`]).
#[derive(Debug, Clone, PartialEq)]
pub struct NoteLine {
    /// The action the match was, or became.
    pub action: String,
    /// Start of its first run, s.
    pub start: f64,
    /// End of its last run, s.
    pub end: f64,
    /// What was decided, in words.
    pub words: String,
}

/// The notes of a simulation in a reader's terms, each once (a phrase weighed again at a
/// later pause or at the end of the log, and decided alike, is one line).
pub fn note_lines(notes: &[Note], names: &[String], clock: &Clock) -> Vec<NoteLine> {
    let mut seen = std::collections::HashSet::new();
    notes
        .iter()
        .filter(|n| seen.insert(**n))
        .map(|n| NoteLine {
            action: name_of(names, n.action),
            start: clock.time_of(n.start_seq),
            end: clock.time_of(n.end_seq),
            words: why_words(n, names),
        })
        .collect()
}

/// The lines `simulate --why` prints ([`note_lines`], [`unread_lines`], [`lost_lines`]; it
/// sorts them by start first).
pub fn write_note_lines(mut out: impl Write, lines: &[NoteLine]) -> Result<()> {
    if lines.is_empty() {
        writeln!(
            out,
            "why: every match committed was reported as its pattern's action"
        )?;
        return Ok(());
    }
    writeln!(
        out,
        "why (matches dropped or read as another action; motion read as nothing; samples lost):"
    )?;
    for l in lines {
        writeln!(
            out,
            "{:<12} {:>9.3} {:>9.3}  {}",
            l.action, l.start, l.end, l.words
        )?;
    }
    Ok(())
}

/// Motion no event and no note of `sim` accounts for: each phrase of moving token runs
/// (split at a stillness of `segment::CONTINUE_US`, as long as an event waits for its next
/// piece) that was read as nothing, with the library example nearest it in tokens (by
/// Levenshtein distance; the device's automata weigh edits more finely); or, when nothing in
/// the log stood out of the tracker's noise, one line that says so.
pub fn unread_lines(sim: &Simulation, lib: &LibraryFile) -> Result<Vec<NoteLine>> {
    let (runs, (lin_rms, rot_rms)) = log_runs_and_noise(&sim.samples);
    let (Some(first), Some(last)) = (runs.first(), runs.last()) else {
        return Ok(Vec::new());
    };
    let time = |seq: u32| sim.clock.time_of(seq);
    if runs.iter().all(|r| r.token == STILL) {
        return Ok(vec![NoteLine {
            action: "(none)".into(),
            start: time(first.start.0),
            end: time(last.end.0),
            words: nothing_moved_words(lin_rms, rot_rms),
        }]);
    }
    let mut phrases: Vec<Vec<&Run>> = vec![Vec::new()];
    for r in &runs {
        let long_still = r.token == STILL && r.end.1.saturating_sub(r.start.1) >= CONTINUE_US;
        match phrases.last_mut() {
            Some(p) if long_still && !p.is_empty() => phrases.push(Vec::new()),
            Some(p) if r.token != STILL => p.push(r),
            _ => {}
        }
    }
    let told: Vec<(u32, u32)> = sim
        .events
        .iter()
        .map(|e| (e.start_seq, e.end_seq))
        .chain(sim.notes.iter().map(|n| (n.start_seq, n.end_seq)))
        .collect();
    let mut examples: Vec<(&str, Vec<Token>)> = Vec::new();
    for a in &lib.actions {
        for e in &a.examples {
            examples.push((&a.name, parse_tokens(e)?));
        }
    }
    let mut out = Vec::new();
    for p in &phrases {
        let (Some(a), Some(b)) = (p.first(), p.last()) else {
            continue;
        };
        let (a, b) = (a.start.0, b.end.0);
        if told.iter().any(|&(s, e)| s <= b && a <= e) {
            continue;
        }
        let tokens: Vec<Token> = p.iter().map(|r| r.token).collect();
        let moved = tokens_to_string(&tokens);
        let words = match examples
            .iter()
            .map(|(name, ex)| (edit_distance(&tokens, ex), name, ex))
            .min_by_key(|(d, ..)| *d)
        {
            Some((d, name, ex)) => format!(
                "moved (`{moved}`), but no action read it; the nearest example is `{name}`'s \
                 `{}`, {d} edit{} away",
                tokens_to_string(ex),
                if d == 1 { "" } else { "s" }
            ),
            None => format!("moved (`{moved}`), but no action read it"),
        };
        out.push(NoteLine {
            action: "(none)".into(),
            start: time(a),
            end: time(b),
            words,
        });
    }
    Ok(out)
}

/// Stretches where the tracker gave no sample for at least [`LOST_INTERVALS`] of its usual
/// intervals (the median), with how far the figurine turned (the short way) and moved across
/// each: the recognizer only guesses what happened there from both ends, and after a stretch
/// longer than `intake::MAX_GAP_US` it starts afresh.
pub fn lost_lines(log: &PoseLog, sim: &Simulation) -> Vec<NoteLine> {
    let samples = &sim.samples;
    let mut steps: Vec<u64> = samples
        .windows(2)
        .map(|w| w[1].1.t_us.saturating_sub(w[0].1.t_us))
        .filter(|&d| d > 0)
        .collect();
    steps.sort_unstable();
    let Some(&usual) = steps.get(steps.len() / 2) else {
        return Vec::new();
    };
    let time = |i: usize| log.samples.get(i).map_or(0.0, |s| s.t);
    samples
        .windows(2)
        .filter_map(|w| {
            let ((i, a), (j, b)) = (w[0], w[1]);
            let dt = b.t_us.saturating_sub(a.t_us);
            if dt < LOST_INTERVALS * usual.max(1) {
                return None;
            }
            let dot: f32 = a.quat.iter().zip(b.quat).map(|(x, y)| x * y).sum();
            let norms = (a.quat.iter().map(|x| x * x).sum::<f32>()
                * b.quat.iter().map(|x| x * x).sum::<f32>())
            .sqrt();
            let turned = (2.0 * (dot.abs() / norms).min(1.0).acos()).to_degrees();
            let moved: f32 = a
                .pos
                .iter()
                .zip(b.pos)
                .map(|(x, y)| (y - x) * (y - x))
                .sum::<f32>()
                .sqrt();
            let words = if dt > MAX_GAP_US {
                format!(
                    "the tracker gave no sample for {:.2} s: the recognizer starts afresh \
                     after it, and a gesture across it is not read whole",
                    dt as f64 * 1e-6
                )
            } else {
                format!(
                    "the tracker gave no sample for {:.2} s ({} of its {:.0} Hz samples); \
                     across it the figurine turned {turned:.0}° (or {:.0}° the other way \
                     round) and moved {:.1} cm: the recognizer bridges it from both ends, \
                     the long way round only when the turn before it was heading there \
                     that fast",
                    dt as f64 * 1e-6,
                    dt / usual.max(1) - 1,
                    1e6 / usual as f64,
                    360.0 - turned,
                    100.0 * moved,
                )
            };
            Some(NoteLine {
                action: "(lost)".into(),
                start: time(i),
                end: time(j),
                words,
            })
        })
        .collect()
}

/// Missing samples, in the tracker's usual intervals, that [`lost_lines`] names: two or more
/// in a row (one lost now and then is common and harmless).
pub const LOST_INTERVALS: u64 = 3;

fn name_of(names: &[String], a: u8) -> String {
    names
        .get(usize::from(a))
        .cloned()
        .unwrap_or_else(|| format!("#{a}"))
}

/// What a note says, in words.
pub fn why_words(n: &Note, names: &[String]) -> String {
    let action = name_of(names, n.action);
    match n.why {
        Why::TooBrief => format!(
            "dropped: briefer than {:.2} s, turned less than {:.0}°, and not a whole gesture \
             as quick as `{action}`'s examples and as far as the least of them (a flicker)",
            MIN_ACTION_US as f64 * 1e-6,
            f64::from(BRIEF_TURN_RAD).to_degrees()
        ),
        Why::NotFarEnough => format!(
            "dropped: a new event that went (or travelled) less far than `{action}`'s \
             examples allow (a fidget)"
        ),
        Why::OneSweep => format!(
            "dropped: a new event whose motion, from rest to rest, was one sweep of the hand, \
             where each of `{action}`'s examples made {MANY_SWEEPS} or more (a toy carried)"
        ),
        Why::Settles => "dropped: the settling of the event before it".into(),
        Why::WindUp { into } => format!(
            "taken into the `{}` after it as its wind-up: one stroke the other way, under a \
             fifth of its motion",
            name_of(names, into)
        ),
        Why::Lost => "dropped: its motion had left the recognizer's history".into(),
        Why::Reread { matched } => format!(
            "read as `{action}`: `{}`'s pattern matched, but it moved unlike its \
             examples and like `{action}`'s",
            name_of(names, matched)
        ),
        Why::NotThatFar { matched } => format!(
            "read as `{action}`: `{}`'s pattern matched, but it went less far than its \
             examples (a fidget, for it); `{action}`'s reads it within an edit, and it moved \
             like `{action}`'s examples and went as far",
            name_of(names, matched)
        ),
        Why::Nearest => format!(
            "offered to `{action}`, its nearest action: no event took this stand-alone phrase"
        ),
    }
}

/// "sudden-strong" style words for a (Lt, Lw) pair.
pub fn effort_words(time: f64, weight: f64) -> String {
    format!(
        "{}-{}",
        if time >= 0.0 { "sudden" } else { "sustained" },
        if weight >= 0.0 { "strong" } else { "light" }
    )
}
