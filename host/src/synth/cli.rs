//! `figurine synth …`: the command-line face of the doodle generator (and of [`super::rest`]).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};

use super::effort::Effort;
use super::gesture::Action;
use super::handling::Handling;
use super::knobs::{Knobs, Range};
use super::rest::{rest_log, RestKind, RestSpec, TrackerLevel};
use super::sampling::SignMode;
use super::sequence::{
    effort_set, examples, gesture, handled, random_state_for, render, sequence, Doodle,
};

/// Most actions in one `sequence` log (≈ 2–3 s each; 10 000 actions at 240 Hz ≈ 6 M samples,
/// ≈ 400 MB in memory).
pub const MAX_SEQUENCE_ACTIONS: usize = 10_000;
/// Most logs per effort state in `effort-set`, and most `examples`.
pub const MAX_SET_SIZE: usize = 100_000;

/// Generate synthetic spatial motion doodles (seeded, labelled pose logs).
#[derive(Args, Debug)]
pub struct SynthArgs {
    #[command(subcommand)]
    command: Box<SynthCommand>,
}

#[derive(Subcommand, Debug)]
enum SynthCommand {
    /// One performance of one action.
    Gesture {
        /// Action name (walk, run, jump, punch, throw, kick, turn, sidestep, crouch, bow, wave,
        /// spin).
        #[arg(long)]
        action: Action,
        /// Effort: sudden-strong, sudden-light, sustained-strong, sustained-light, neutral, or
        /// random (one of the four states).
        #[arg(long, default_value = "random")]
        effort: OrRandom<Effort>,
        /// Master seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Output pose log (CSV).
        #[arg(long)]
        out: PathBuf,
        /// Also write the label as a one-element JSON array here.
        #[arg(long)]
        labels: Option<PathBuf>,
        #[command(flatten)]
        knobs: KnobArgs,
    },
    /// The toy handled without playing an action: carried elsewhere, lifted, looked at and set
    /// back down, or held in a hand that talks (any event on it is a false one).
    Handling {
        /// Kind: reposition, lift or talk.
        #[arg(long)]
        kind: Handling,
        /// Master seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Output pose log (CSV; the handling's span in a `# handled` line).
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        knobs: KnobArgs,
    },
    /// A labelled sequence of random actions separated by still pauses.
    Sequence {
        /// Master seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Number of actions.
        #[arg(long, default_value_t = 8)]
        count: usize,
        /// These actions in this order (comma-separated, e.g. `jump,jump,walk`) instead of
        /// `--count` random ones; no turn is put in.
        #[arg(long, value_delimiter = ',')]
        actions: Vec<Action>,
        /// Effort of every action (default: a random state per action).
        #[arg(long, default_value = "random")]
        effort: OrRandom<Effort>,
        /// Output pose log (CSV).
        #[arg(long)]
        out: PathBuf,
        /// Output labels (JSON array of {action, start, end, time_class, weight_class}).
        #[arg(long)]
        labels: PathBuf,
        #[command(flatten)]
        knobs: KnobArgs,
    },
    /// One-gesture logs in sudden-strong/, sudden-light/, sustained-strong/, sustained-light/.
    EffortSet {
        /// Master seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Logs per effort state.
        #[arg(long, default_value_t = 24)]
        per_class: usize,
        /// Output folder (created; also gets labels.json listing every file).
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        knobs: KnobArgs,
    },
    /// Learning examples of one action: NAME_1.csv … NAME_K.csv.
    Examples {
        /// Action name.
        #[arg(long)]
        action: Action,
        /// Number of examples.
        #[arg(long, default_value_t = 3)]
        count: usize,
        /// Effort of the examples (default: a random state each).
        #[arg(long, default_value = "random")]
        effort: OrRandom<Effort>,
        /// Master seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Output folder (created).
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        knobs: KnobArgs,
    },
    /// A picture of every action, or of one action in the four effort states.
    ///
    /// Without `--action`: one performance of every action (walk, run, jump, punch, throw,
    /// kick, turn, sidestep, crouch, bow, wave, spin) plotted small on a 4×3 grid. With
    /// `--action`: that action in the four effort states (same seed, so only the effort
    /// differs), 2×2.
    Gallery {
        /// Master seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Compare the four effort states of this action instead.
        #[arg(long)]
        action: Option<Action>,
        /// Effort of every performance (default: a random state each).
        #[arg(long, default_value = "random")]
        effort: OrRandom<Effort>,
        /// Output PNG.
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        knobs: KnobArgs,
    },
    /// A log of a figurine playing no action: held in a hand, on a table, or on a stand.
    ///
    /// hand: tremor (8-12 Hz, at most 3 mm and 0.5 deg per axis), sway (0.1-0.5 Hz, 1-5 mm,
    /// 0.5-2 deg) and idle fidgets every few to tens of seconds (2-8 mm, 1-5 deg, 0.2-0.8 s).
    /// table: only the tracker's noise and drift. mounted: plus a 0.05-0.2 mm stand vibration
    /// at 20-50 Hz. Prints one summary line; --labels writes everything drawn as JSON.
    Rest {
        /// Master seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Output pose log (CSV).
        #[arg(long)]
        out: PathBuf,
        /// Length of the log, seconds (at most 3600).
        #[arg(long, default_value_t = 600.0)]
        seconds: f64,
        /// hand, table, mounted, or random.
        #[arg(long, default_value = "random")]
        kind: OrRandom<RestKind>,
        /// Tracker level: lighthouse (Lighthouse/optical mocap: 0.1-0.3 mm, 0.02-0.05 deg,
        /// 120-1000 Hz), imu-fusion (IMU + optical/UWB: 0.5-1 mm, 0.1-0.2 deg, 100-400 Hz),
        /// webcam-near (tag at 0.5 m: 0.5-1 mm across, 1-2 mm in depth, 0.2-0.3 deg, 30-60 Hz),
        /// webcam-far (tag at 1 m: 1-2 mm across, 2.5-5 mm in depth, 0.3-0.5 deg, 30 Hz), or
        /// random.
        #[arg(long, default_value = "random")]
        tracker: OrRandom<TrackerLevel>,
        /// Sample rate, Hz: `V` or `LO..HI` [default: the tracker level's].
        #[arg(long, allow_hyphen_values = true)]
        rate: Option<Range>,
        /// Also write what was drawn (kind, tracker, sigmas, rate, fidget times) as JSON here.
        #[arg(long)]
        labels: Option<PathBuf>,
    },
    /// Draw a pose log as a PNG: top view, side view, speeds over time, label spans.
    Plot {
        /// The pose log (CSV).
        log: PathBuf,
        /// Labels JSON to shade (optional).
        #[arg(long)]
        labels: Option<PathBuf>,
        /// Output PNG.
        #[arg(long)]
        out: PathBuf,
    },
}

/// `random` (None) or a named value: an effort, a rest kind, a tracker level.
#[derive(Debug, Clone, Copy)]
struct OrRandom<T>(Option<T>);

impl<T: std::str::FromStr<Err = String>> std::str::FromStr for OrRandom<T> {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.trim().eq_ignore_ascii_case("random") {
            Ok(Self(None))
        } else {
            s.parse()
                .map(|v| Self(Some(v)))
                .map_err(|e| format!("{e}, or random"))
        }
    }
}

/// Nuisance-parameter ranges; each takes `V` or `LO..HI`. Defaults are wide.
#[derive(Args, Debug, Clone)]
struct KnobArgs {
    /// Nominal sample rate, Hz [default: 30..240; up to 2000].
    #[arg(long, allow_hyphen_values = true)]
    rate: Option<Range>,
    /// Timestamp jitter, fraction of a period [default: 0..0.25; at most 0.45].
    #[arg(long, allow_hyphen_values = true)]
    jitter: Option<Range>,
    /// Probability of a dropped sample [default: 0..0.01].
    #[arg(long, allow_hyphen_values = true)]
    drop: Option<Range>,
    /// Spatial scale of the doodle [default: 0.5..2].
    #[arg(long, allow_hyphen_values = true)]
    scale: Option<Range>,
    /// Tempo multiplier (durations divided by it) [default: 0.8..1.25].
    #[arg(long, allow_hyphen_values = true)]
    speed: Option<Range>,
    /// Heading of the doodle, degrees about +Y [default: -180..180].
    #[arg(long, allow_hyphen_values = true)]
    heading: Option<Range>,
    /// Tilt of the toy in the hand, degrees [default: 0..10].
    #[arg(long, allow_hyphen_values = true)]
    tilt: Option<Range>,
    /// Start x and z in the room, metres [default: -2..2].
    #[arg(long, allow_hyphen_values = true)]
    room: Option<Range>,
    /// Start height, metres [default: 0.4..1.5].
    #[arg(long, allow_hyphen_values = true)]
    height: Option<Range>,
    /// Multiplier of sensor noise, tremor and drift; 0 = clean [default: 0.5..1.5].
    #[arg(long, allow_hyphen_values = true)]
    noise: Option<Range>,
    /// Log clock at the first sample, seconds [default: 0..10].
    #[arg(long, allow_hyphen_values = true)]
    t0: Option<Range>,
    /// Still time before the first action, seconds [default: 0.4..1.2].
    #[arg(long, allow_hyphen_values = true)]
    lead: Option<Range>,
    /// Still time between actions and after the last, seconds [default: 0.3..1.5].
    #[arg(long, allow_hyphen_values = true)]
    pause: Option<Range>,
    /// Quaternion sign convention: continuous, canonical, flips [default: random per doodle].
    #[arg(long)]
    quat_sign: Option<SignMode>,
    /// Probability per sample of a tracker glitch: spike, NaN row, zero quaternion, repeated or
    /// backward timestamp [default: 0].
    #[arg(long)]
    glitch: Option<Range>,
    /// Probability that a sequence also holds one handling of the toy that plays no action:
    /// carried elsewhere, or lifted and set down [default: 0.333].
    #[arg(long)]
    handling: Option<f64>,
    /// A perfect tracker: no noise, tremor, drift, jitter, drops or glitches (overrides those).
    #[arg(long)]
    clean: bool,
}

impl KnobArgs {
    fn knobs(&self) -> Result<Knobs> {
        let d = Knobs::default();
        let mut k = Knobs {
            rate_hz: self.rate.unwrap_or(d.rate_hz),
            jitter: self.jitter.unwrap_or(d.jitter),
            drop: self.drop.unwrap_or(d.drop),
            scale: self.scale.unwrap_or(d.scale),
            speed: self.speed.unwrap_or(d.speed),
            heading_deg: self.heading.unwrap_or(d.heading_deg),
            tilt_deg: self.tilt.unwrap_or(d.tilt_deg),
            room_m: self.room.unwrap_or(d.room_m),
            height_m: self.height.unwrap_or(d.height_m),
            noise: self.noise.unwrap_or(d.noise),
            t0: self.t0.unwrap_or(d.t0),
            lead_s: self.lead.unwrap_or(d.lead_s),
            pause_s: self.pause.unwrap_or(d.pause_s),
            sign: self.quat_sign,
            glitch: self.glitch.unwrap_or(d.glitch),
            handling: self.handling.unwrap_or(d.handling),
        };
        if self.clean {
            k.noise = Range::fixed(0.0);
            k.jitter = Range::fixed(0.0);
            k.drop = Range::fixed(0.0);
            k.glitch = Range::fixed(0.0);
        }
        k.validate().map_err(anyhow::Error::msg)?;
        Ok(k)
    }
}

/// Creates the folder `out` goes in, if it has one.
fn make_parent(out: &Path) -> Result<()> {
    if let Some(dir) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    Ok(())
}

fn write_doodle(d: &Doodle, out: &Path) -> Result<()> {
    make_parent(out)?;
    d.write_csv(out)
        .with_context(|| format!("writing {}", out.display()))
}

/// Labels listed in full by the summary; longer sequences are elided.
const SUMMARY_LABELS: usize = 24;

/// Prints what was written. Write errors (e.g. a closed pipe) are ignored: the files are done.
fn summary(d: &Doodle, out: &Path) {
    use std::io::Write;
    let mut w = std::io::stdout().lock();
    let n = d.log.samples.len();
    let (t0, t1) = match (d.log.samples.first(), d.log.samples.last()) {
        (Some(a), Some(b)) => (a.t, b.t),
        _ => (0.0, 0.0),
    };
    let _ = writeln!(
        w,
        "{}: {n} samples, {t0:.3}..{t1:.3} s, {}",
        out.display(),
        d.variation
    );
    for l in d.labels.iter().take(SUMMARY_LABELS) {
        let _ = writeln!(
            w,
            "  {:<9} {:>9.3} .. {:>9.3} s  {:?}/{:?}",
            l.action, l.start, l.end, l.time_class, l.weight_class
        );
    }
    if d.labels.len() > SUMMARY_LABELS {
        let _ = writeln!(w, "  … {} more", d.labels.len() - SUMMARY_LABELS);
    }
    for h in &d.handled {
        let _ = writeln!(
            w,
            "  {:<9} {:>9.3} .. {:>9.3} s  (handled, no action)",
            h.action, h.start, h.end
        );
    }
}

/// Prints one line, ignoring a closed pipe.
fn say(line: std::fmt::Arguments<'_>) {
    use std::io::Write;
    let _ = writeln!(std::io::stdout().lock(), "{line}");
}

/// Runs `figurine synth …`.
pub fn run(args: SynthArgs) -> Result<()> {
    match *args.command {
        SynthCommand::Gesture {
            action,
            effort,
            seed,
            out,
            labels,
            knobs,
        } => {
            let knobs = knobs.knobs()?;
            let effort = effort
                .0
                .unwrap_or_else(|| super::sequence::random_state_for(seed));
            let d = gesture(seed, &knobs, action, effort);
            write_doodle(&d, &out)?;
            if let Some(l) = labels {
                d.write_labels(&l)
                    .with_context(|| format!("writing {}", l.display()))?;
            }
            summary(&d, &out);
        }
        SynthCommand::Handling {
            kind,
            seed,
            out,
            knobs,
        } => {
            let d = handled(seed, &knobs.knobs()?, kind);
            write_doodle(&d, &out)?;
            summary(&d, &out);
        }
        SynthCommand::Sequence {
            seed,
            count,
            actions,
            effort,
            out,
            labels,
            knobs,
        } => {
            if count == 0 || count > MAX_SEQUENCE_ACTIONS || actions.len() > MAX_SEQUENCE_ACTIONS {
                bail!("--count or --actions: must be within 1..={MAX_SEQUENCE_ACTIONS} actions");
            }
            let knobs = knobs.knobs()?;
            let d = if actions.is_empty() {
                sequence(seed, &knobs, count, effort.0)
            } else {
                // One effort for all when given, else each action its own random state.
                let items: Vec<(Action, Effort)> = actions
                    .iter()
                    .enumerate()
                    .map(|(i, &a)| {
                        let e = effort.0.unwrap_or_else(|| {
                            random_state_for(crate::synth::sequence::item_seed(seed, i as u64))
                        });
                        (a, e)
                    })
                    .collect();
                render(seed, &knobs, &items)
            };
            write_doodle(&d, &out)?;
            d.write_labels(&labels)
                .with_context(|| format!("writing {}", labels.display()))?;
            summary(&d, &out);
        }
        SynthCommand::EffortSet {
            seed,
            per_class,
            out,
            knobs,
        } => {
            if per_class == 0 || per_class > MAX_SET_SIZE {
                bail!("--per-class {per_class}: must be within 1..={MAX_SET_SIZE}");
            }
            let knobs = knobs.knobs()?;
            let set = effort_set(seed, &knobs, per_class);
            let mut index = Vec::with_capacity(set.len());
            let mut counter = std::collections::BTreeMap::<String, usize>::new();
            for (state, d) in &set {
                let dir = out.join(state.name());
                let k = counter.entry(state.name()).or_default();
                let action = d.labels.first().map_or("none", |l| l.action.as_str());
                let file = dir.join(format!("{:04}_{action}.csv", *k));
                *k += 1;
                write_doodle(d, &file)?;
                index.push(serde_json::json!({
                    "file": file.strip_prefix(&out).unwrap_or(&file).to_string_lossy(),
                    "seed": d.seed,
                    "labels": d.labels,
                }));
            }
            let idx = out.join("labels.json");
            std::fs::write(&idx, serde_json::to_string_pretty(&index)? + "\n")
                .with_context(|| format!("writing {}", idx.display()))?;
            say(format_args!(
                "{}: {} logs in {} effort folders (index: {})",
                out.display(),
                set.len(),
                Effort::STATES.len(),
                idx.display()
            ));
        }
        SynthCommand::Examples {
            action,
            count,
            effort,
            seed,
            out,
            knobs,
        } => {
            if count == 0 || count > MAX_SET_SIZE {
                bail!("--count {count}: must be within 1..={MAX_SET_SIZE}");
            }
            let knobs = knobs.knobs()?;
            for (i, d) in examples(seed, &knobs, action, count, effort.0)
                .iter()
                .enumerate()
            {
                let file = out.join(format!("{}_{}.csv", action.name(), i + 1));
                write_doodle(d, &file)?;
                summary(d, &file);
            }
        }
        SynthCommand::Gallery {
            seed,
            action,
            effort,
            out,
            knobs,
        } => {
            let knobs = knobs.knobs()?;
            let tile = |s: u64, a: Action, e: Effort| {
                let d = gesture(s, &knobs, a, e);
                (super::plot::plot(&d.log, &d.labels), format!("{a} {e}"))
            };
            let (pics, cols): (Vec<_>, u32) = match action {
                Some(a) => (
                    Effort::STATES.iter().map(|&e| tile(seed, a, e)).collect(),
                    2,
                ),
                None => (
                    Action::ALL
                        .iter()
                        .enumerate()
                        .map(|(i, &a)| {
                            let s = super::sequence::item_seed(seed, i as u64);
                            let e = effort
                                .0
                                .unwrap_or_else(|| super::sequence::random_state_for(s));
                            tile(s, a, e)
                        })
                        .collect(),
                    4,
                ),
            };
            super::plot::gallery(&pics, cols)
                .save(&out)
                .with_context(|| format!("writing {}", out.display()))?;
            say(format_args!("{}", out.display()));
        }
        SynthCommand::Rest {
            seed,
            out,
            seconds,
            kind,
            tracker,
            rate,
            labels,
        } => {
            let spec = RestSpec {
                seconds,
                kind: kind.0,
                tracker: tracker.0,
                rate_hz: rate,
                knobs: Knobs::default(),
            };
            spec.validate().map_err(anyhow::Error::msg)?;
            let r = rest_log(seed, &spec);
            make_parent(&out)?;
            r.write_csv(&out)
                .with_context(|| format!("writing {}", out.display()))?;
            if let Some(l) = labels {
                make_parent(&l)?;
                r.write_info(&l)
                    .with_context(|| format!("writing {}", l.display()))?;
            }
            let s = &r.log.samples;
            let (t0, t1) = match (s.first(), s.last()) {
                (Some(a), Some(b)) => (a.t, b.t),
                _ => (0.0, 0.0),
            };
            say(format_args!(
                "{}: {} samples, {t0:.3}..{t1:.3} s, {}",
                out.display(),
                s.len(),
                r.info
            ));
        }
        SynthCommand::Plot { log, labels, out } => {
            super::plot::plot_files(&log, labels.as_deref(), &out)?;
            say(format_args!("{}", out.display()));
        }
    }
    Ok(())
}
