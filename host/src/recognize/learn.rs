//! `figurine learn`: an action's pattern from a few example logs (seed 000 §4.3).
//!
//! | step | what | where |
//! |---|---|---|
//! | 1 | each example is tokenized by the device front end (through the wire quantisation); its gesture is the span from the first to the last non-STILL run | `Example` |
//! | 2 | the examples are DTW-averaged and the average doodle is tokenized too | [`super::dtw`] |
//! | 3 | each run becomes a pattern symbol: the stroke it meant, its wobbles written as such | [`super::intent`] |
//! | 4 | the mandatory runs are aligned into columns, the optional ones go between them | [`super::columns`] |
//! | 5 | the pattern accepts the action done to either side | [`super::sides`] |
//! | 6 | the edit bound defaults to the most the device allows (one less than the shortest match, at most `MAX_EDITS`); each example is checked against the pattern whole, and once the library is written, read back through the device: what a user acts on | [`learn_action`], [`read_back`] |
//! | 7 | a pattern that accepts another action's example exactly is narrowed until it does not; when it cannot be without losing its own examples, the other action is made as tolerant of the shared strokes' rotations | [`super::separate`] |
//!
//! Besides its pattern, an action keeps what its examples say of how it moves: its motion
//! shape and how much that varied ([`mean_shape`], [`shape_tolerance`]), how far the least of
//! them went ([`least_extent`]), the longest stillness inside one ([`longest_hold`]), the
//! fewest sub-movements one made ([`fewest_sweeps`]) and how briefly the quickest moved
//! ([`briefest`]).
//!
//! The pattern and every bound take the examples' lower quartile, the quantile the least of
//! three estimates: a variation is kept when a [`super::columns::quorum`] of the strings
//! shows it (any one, up to six examples), a bound is the [`lower_quartile`] of the examples'
//! measures (of three, the least). A user who teaches more examples so gets a pattern no
//! looser than three would give: taken as a union of all, every odd performance widened it,
//! and twelve examples read carried toys as actions nearly twice as often as three did.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use figurine_recognizer::extent::{Extent, ExtentSums};
use figurine_recognizer::features::{Shape, ShapeSums};
use figurine_recognizer::history::{Run, Sweeps};
use figurine_recognizer::shape::SHAPE_SCALE;
use figurine_recognizer::token::STILL;

use super::columns::{learn_regex, quorum};
use super::dtw;
use super::feed::{
    gesture_runs, log_gesture, log_runs, log_runs_and_noise, log_samples, nothing_moved_words,
};
use super::intent::{intent_of, intent_symbols, mirror_seq, run_seconds, tokens_only, Tokenized};
use super::library::{full_match, parse_tokens, tokens_to_string, ActionEntry, LibraryFile};
use super::regex::default_edits;
use super::sides::{learn_regex_mirrored, to_one_side};
use crate::poselog::PoseLog;

/// Arguments of `figurine learn`.
#[derive(Args, Debug)]
pub struct LearnArgs {
    /// The library file to update (created if missing).
    #[arg(long)]
    pub library: PathBuf,
    /// Name of the action to learn or replace.
    #[arg(long)]
    pub name: String,
    /// Edit bound (default: one per three tokens of the shortest match, at most 3).
    #[arg(long)]
    pub max_edits: Option<u8>,
    /// Do not also accept the mirror image (left ↔ right) of the examples.
    #[arg(long)]
    pub no_mirror: bool,
    /// Example logs, one performance each (three are usually enough; of more, the pattern keeps
    /// what a quarter of them show alike, so an odd one is left out).
    #[arg(required = true)]
    pub examples: Vec<PathBuf>,
}

/// One example log, read once through the device front end: its gesture's runs (STILL
/// included), the still run before them, and the span (seconds, log clock) from its first to
/// its last motion.
struct Example {
    runs: Vec<Run>,
    rest: Option<Run>,
    span: Option<(f64, f64)>,
}

impl Example {
    fn read(log: &PoseLog) -> Self {
        let (samples, _) = log_samples(log);
        let runs = log_runs(&samples);
        let g = gesture_runs(&runs);
        let clock = super::feed::Clock::new(log, &samples);
        let span = g
            .first()
            .zip(g.last())
            .map(|(a, b)| (clock.time_of(a.start.0), clock.time_of(b.end.0)));
        let first = runs.iter().position(|r| r.token != STILL);
        let rest = first
            .and_then(|i| i.checked_sub(1))
            .and_then(|i| runs.get(i))
            .copied();
        Example {
            runs: g.to_vec(),
            rest,
            span,
        }
    }
}

/// Tokenizes the gesture of a one-performance log.
pub fn tokenize_gesture(log: &PoseLog) -> Tokenized {
    tokens_of(&log_gesture(log))
}

/// The moving runs of a gesture as (token, duration).
fn tokens_of(g: &[Run]) -> Tokenized {
    g.iter()
        .filter(|r| r.token != STILL)
        .map(|r| (r.token, run_seconds(r)))
        .collect()
}

/// The motion shape of a one-performance log's gesture, from its first to its last motion
/// (`figurine_recognizer::features::Shape`) — what the device measures over a match
/// (`figurine_recognizer::shape::shape_penalty`). None without motion.
pub fn motion_shape(log: &PoseLog) -> Option<Shape> {
    shape_of_runs(&log_gesture(log))
}

/// [`motion_shape`] of a gesture's runs.
fn shape_of_runs(g: &[Run]) -> Option<Shape> {
    if g.is_empty() {
        return None;
    }
    let mut sums = ShapeSums::new();
    for r in g {
        sums.add(&r.acc, r.token == STILL);
    }
    Some(sums.shape())
}

/// How far a gesture's runs went from where it began, its rotation from where it rested
/// before (`rest`, the still run before them: [`ExtentSums::add_rest`]), as the device
/// measures a performance ([`figurine_recognizer::extent`]).
fn extent_of_runs(rest: Option<&Run>, g: &[Run]) -> Extent {
    let mut sums = ExtentSums::new();
    if let Some(r) = rest {
        sums.add_rest(&r.acc);
    }
    for r in g {
        sums.add(&r.acc);
    }
    sums.extent()
}

/// How many of `n` examples a learnt count leaves beyond it, and how many alike the pattern
/// keeps: the [`quorum`] of the examples and their average (one, up to six examples).
pub fn examples_quorum(n: usize) -> usize {
    quorum(n + 1)
}

/// The lower quartile of the examples' `values`: the (n + 1) / 4-th least of n (1-based, the
/// quantile the least of three examples estimates), interpolated between the two it falls
/// between — the least of three exactly, a quarter of the way from the third least to the
/// fourth of twelve. None when empty. What a learnt bound takes, so that one odd example
/// among many does not set it for all.
pub fn lower_quartile(mut values: Vec<f32>) -> Option<f32> {
    values.sort_by(f32::total_cmp);
    let n = values.len();
    let at = ((n as f32 + 1.0) / 4.0).clamp(1.0, n.max(1) as f32);
    let below = at as usize;
    let a = *values.get(below.checked_sub(1)?)?;
    let share = at - below as f32;
    Some(match values.get(below) {
        Some(&b) if share > 0.0 => a + share * (b - a),
        _ => a,
    })
}

/// The longest stillness inside the gestures (each from its first to its last motion),
/// seconds: the upper quartile ([`lower_quartile`] turned round) of each gesture's longest,
/// of three examples the longest of all; None when none held still inside.
pub fn longest_hold<'a>(gestures: impl IntoIterator<Item = &'a [Run]>) -> Option<f32> {
    let each: Vec<f32> = gestures
        .into_iter()
        .filter(|g| !g.is_empty())
        .map(|g| {
            g.iter()
                .filter(|r| r.token == STILL)
                .map(|r| run_seconds(r) as f32)
                .fold(0.0, f32::max)
        })
        .collect();
    lower_quartile(each.iter().map(|h| -h).collect())
        .map(|h| -h)
        .filter(|&h| h > 0.0)
}

/// How long the briefest gesture moved, from its first motion to its last, seconds: the
/// examples' [`lower_quartile`] (of three, the briefest); None without one. A performance
/// half as long that goes as far as the least of them is a quick one, not a flicker
/// (`figurine_recognizer::recognizer`'s floor, [`figurine_recognizer::segment::MIN_ACTION_US`]).
pub fn briefest<'a>(gestures: impl IntoIterator<Item = &'a [Run]>) -> Option<f32> {
    let each: Vec<f32> = gestures
        .into_iter()
        .filter_map(|g| Some((g.first()?.start.1, g.last()?.end.1)))
        .map(|(a, b)| b.saturating_sub(a) as f32 * 1e-6)
        .collect();
    lower_quartile(each)
}

/// The fewest sub-movements ([`Sweeps::count`]) the gestures that moved made, as the
/// [`examples_quorum`]-th fewest (of three: the fewest any made); None without one.
pub fn fewest_sweeps<'a>(gestures: impl IntoIterator<Item = &'a [Run]>) -> Option<u8> {
    let mut made: Vec<u8> = gestures
        .into_iter()
        .filter(|g| !g.is_empty())
        .map(|g| {
            let mut made = Sweeps::NONE;
            g.iter().for_each(|r| made.merge(r.sweeps));
            made.count()
        })
        .collect();
    made.sort_unstable();
    let q = examples_quorum(made.len()).min(made.len());
    made.get(q.checked_sub(1)?).copied()
}

/// The least extent among gestures that moved, dimension by dimension (and the least share of
/// its own reach that one travelled), each as the examples' [`lower_quartile`] (of three: the
/// least): how far the least of an action's examples went, what the device holds a
/// performance to ([`figurine_recognizer::extent::far_enough`]). None without a gesture.
pub fn least_extent<'a>(
    gestures: impl IntoIterator<Item = (Option<&'a Run>, &'a [Run])>,
) -> Option<Extent> {
    let each: Vec<Extent> = gestures
        .into_iter()
        .filter(|(_, g)| !g.is_empty())
        .map(|(rest, g)| {
            let e = extent_of_runs(rest, g);
            Extent {
                travel_share: if e.moved_m > 0.0 {
                    (e.travel_m / e.moved_m).clamp(0.0, 1.0)
                } else {
                    0.0
                },
                ..e
            }
        })
        .collect();
    let least = |f: fn(&Extent) -> f32| lower_quartile(each.iter().map(f).collect());
    Some(Extent {
        moved_m: least(|e| e.moved_m)?,
        turned_rad: least(|e| e.turned_rad)?,
        travel_m: least(|e| e.travel_m)?,
        travel_share: least(|e| e.travel_share)?,
    })
}

/// The motion shapes of the examples that moved ([`motion_shape`]), read once for
/// [`mean_shape`] and [`shape_tolerance`].
pub fn example_shapes(logs: &[PoseLog]) -> Vec<Shape> {
    logs.iter().filter_map(motion_shape).collect()
}

/// Least tolerance of a shape dimension ([`shape_tolerance`]), in its weighted units (a share
/// of speed): a few examples that happened to agree closely in a dimension still leave some
/// room for the next performance.
pub const SHAPE_TOLERANCE_FLOOR: f32 = 0.06;

/// How far the shapes lie from their mean ([`mean_shape`]) in each dimension: the upper
/// quartile ([`lower_quartile`] turned round) of |shape − mean|, of three the largest, weighted by
/// `SHAPE_SCALE` as the device weighs it (`figurine_recognizer::shape::shape_penalty`), at
/// least [`SHAPE_TOLERANCE_FLOOR`]. None without shapes.
pub fn shape_tolerance(shapes: &[Shape]) -> Option<Shape> {
    let mean = mean_shape(shapes)?;
    Some(core::array::from_fn(|k| {
        let negated = shapes.iter().map(|s| -(s[k] - mean[k]).abs()).collect();
        let far = lower_quartile(negated).map_or(0.0, |f| -f);
        (SHAPE_SCALE[k] * far).max(SHAPE_TOLERANCE_FLOOR)
    }))
}

/// The mean of motion shapes ([`example_shapes`]); None without shapes.
pub fn mean_shape(shapes: &[Shape]) -> Option<Shape> {
    if shapes.is_empty() {
        return None;
    }
    let n = shapes.len() as f32;
    Some(core::array::from_fn(|k| {
        shapes.iter().map(|s| s[k]).sum::<f32>() / n
    }))
}

/// Learns action `name` from example logs (one performance each); `mirror` also accepts the
/// left–right mirror images.
pub fn learn_action(
    name: &str,
    logs: &[PoseLog],
    max_edits: Option<u8>,
    mirror: bool,
) -> Result<ActionEntry> {
    let read: Vec<Example> = logs.iter().map(Example::read).collect();
    let mut spans: Vec<_> = logs
        .iter()
        .zip(&read)
        .map(|(log, e)| {
            e.span
                .map(|(t0, t1)| dtw::normalised_span(log, t0 - 0.05, t1 + 0.05))
                .unwrap_or_default()
        })
        .collect();
    let mut seqs: Vec<Tokenized> = read.iter().map(|e| intent_of(&e.runs)).collect();
    if mirror {
        // Bring every example to one side, so a left and a right performance average and
        // align as the same gesture (the mirror is added back below).
        for (i, flip) in to_one_side(&seqs).into_iter().enumerate() {
            if flip {
                seqs[i] = mirror_seq(&seqs[i]);
                dtw::mirror_span(&mut spans[i]);
            }
        }
    }
    let avg = dtw::average(&spans);
    let mut all = vec![intent_symbols(&avg)];
    all.extend(seqs.iter().cloned());
    let re = if mirror {
        learn_regex_mirrored(&all)?
    } else {
        learn_regex(&all)?
    };
    let c = re.compile()?;
    let shapes: Vec<Shape> = read.iter().filter_map(|e| shape_of_runs(&e.runs)).collect();
    let examples: Vec<String> = read
        .iter()
        .map(|e| tokens_to_string(&tokens_only(&tokens_of(&e.runs))))
        .collect();
    let entry = ActionEntry::new(
        name,
        &re.to_source(),
        Some(max_edits.unwrap_or_else(|| default_edits(c.min_len()))),
        examples,
    )?
    .with_shape(mean_shape(&shapes))
    .with_shape_tolerance(shape_tolerance(&shapes))
    .with_extent(least_extent(
        read.iter().map(|e| (e.rest.as_ref(), &e.runs[..])),
    ))
    .with_hold(longest_hold(read.iter().map(|e| &e.runs[..])))
    .with_sweeps(fewest_sweeps(read.iter().map(|e| &e.runs[..])))
    .with_briefest(briefest(read.iter().map(|e| &e.runs[..])));
    Ok(entry)
}

/// Collision warnings between `entry` and the other actions of `lib`.
pub fn collisions(lib: &LibraryFile, entry: &ActionEntry) -> Result<Vec<String>> {
    let mut out = Vec::new();
    for other in lib.actions.iter().filter(|a| a.name != entry.name) {
        for ex in &entry.examples {
            let t = parse_tokens(ex)?;
            if let Some(d) = full_match(other, &t)? {
                out.push(format!(
                    "an example of `{}` ({ex}) is also matched by existing action `{}` \
                     (pattern `{}`, {} edits)",
                    entry.name,
                    other.name,
                    other.regex,
                    f32::from(d) / 2.0
                ));
                break;
            }
        }
        for ex in &other.examples {
            let t = parse_tokens(ex)?;
            if let Some(d) = full_match(entry, &t)? {
                out.push(format!(
                    "the new pattern of `{}` also matches an example of existing action `{}` \
                     ({ex}, {} edits)",
                    entry.name,
                    other.name,
                    f32::from(d) / 2.0
                ));
                break;
            }
        }
    }
    Ok(out)
}

/// Why example `log` read as no motion: the least stroke and twist that would have stood out
/// of its tracker's noise ([`nothing_moved_words`]).
fn still_words(log: &PoseLog) -> String {
    let (samples, _) = log_samples(log);
    let (_, (lin, rot)) = log_runs_and_noise(&samples);
    nothing_moved_words(lin, rot)
}

/// `figurine learn`.
pub fn run(args: &LearnArgs) -> Result<()> {
    let mut lib = if args.library.exists() {
        LibraryFile::read(&args.library)?
    } else {
        LibraryFile::default()
    };
    let logs = args
        .examples
        .iter()
        .map(|p| PoseLog::read_path(p).map_err(anyhow::Error::from))
        .collect::<Result<Vec<_>>>()?;
    let entry = match learn_action(&args.name, &logs, args.max_edits, !args.no_mirror) {
        Ok(entry) => entry,
        Err(e) if logs.iter().all(|l| log_gesture(l).is_empty()) => {
            let why: Vec<String> = args
                .examples
                .iter()
                .zip(&logs)
                .map(|(p, l)| format!("{}: {}", p.display(), still_words(l)))
                .collect();
            return Err(e.context(format!(
                "learning `{}`: no example moved enough to read\n  {}",
                args.name,
                why.join("\n  ")
            )));
        }
        Err(e) => return Err(e.context(format!("learning `{}`", args.name))),
    };
    for ((p, ex), log) in args.examples.iter().zip(&entry.examples).zip(&logs) {
        if ex.is_empty() {
            eprintln!("  {}: left out, {}", p.display(), still_words(log));
            continue;
        }
        let t = parse_tokens(ex)?;
        let ok = full_match(&entry, &t)?;
        eprintln!(
            "  {}: {ex}  [{}]",
            p.display(),
            match ok {
                Some(d) => format!("matched, {} edits", f32::from(d) / 2.0),
                None => "not matched whole".into(),
            }
        );
    }
    for w in collisions(&lib, &entry)? {
        eprintln!("warning: {w}");
    }
    let shape = entry.shape.map_or(String::new(), |[l, u, f]| {
        format!(", moves left/up/front {l:.2}/{u:.2}/{f:.2} of its speed")
    });
    // What one sweep of a hand is measured against (`figurine_recognizer::sweep`).
    let pushes = entry.sweeps.map_or(String::new(), |n| {
        format!(", each example {n} or more sub-movements")
    });
    // How quick a performance may be and still be one (`figurine_recognizer::recognizer`).
    let quick = entry.briefest_s.map_or(String::new(), |s| {
        format!(", the briefest moved for {s:.2} s")
    });
    println!(
        "{}: {}  (max {} edits{shape}{pushes}{quick})",
        entry.name, entry.regex, entry.max_edits
    );
    lib.upsert(entry);
    for step in super::separate::separate(&mut lib)? {
        eprintln!("{step}");
    }
    lib.write(&args.library)?;
    for line in read_back(&mut lib, &args.name, &args.examples, &logs)? {
        eprintln!("{line}");
    }
    Ok(())
}

/// What the device makes of each example log with library `lib` (as written), a line each:
/// the check a user can act on. A pattern may not accept a whole example, yet the device
/// reads it right; and an example it reads as something else, or as two actions, or as
/// nothing, is one to play again (or, among a few, to add examples beside; among many, an odd
/// one the pattern left out, [`examples_quorum`]).
pub fn read_back(
    lib: &mut LibraryFile,
    name: &str,
    paths: &[PathBuf],
    logs: &[PoseLog],
) -> Result<Vec<String>> {
    let blob = lib.blob()?;
    let names = lib.names();
    let q = examples_quorum(logs.len());
    // Among many examples an odd one is left out on purpose: more of the same will not bring
    // it back.
    let advice = if q > 1 {
        format!(
            "of {} examples the pattern keeps what {q} show alike: play it again if it was \
             meant as the others",
            logs.len()
        )
    } else {
        "play it again, or add examples".to_string()
    };
    let mut lines = Vec::new();
    for (p, log) in paths.iter().zip(logs) {
        let sim = super::simulate::simulate_log(log, &names, &blob, None)?;
        let read: Vec<String> = sim
            .records
            .iter()
            .map(|r| format!("`{}`", r.action))
            .collect();
        let read = if read.is_empty() {
            "nothing".to_string()
        } else {
            read.join(", ")
        };
        let verdict = match sim.records.as_slice() {
            [r] if r.action == name => String::new(),
            _ => format!(" — not as one `{name}`: {advice}"),
        };
        lines.push(format!("  {}: read back as {read}{verdict}", p.display()));
    }
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::{self, Action, Knobs};

    /// Three generated learning examples of `action` (seed `seed`).
    fn example_logs(action: Action, seed: u64) -> Vec<PoseLog> {
        synth::examples(seed, &Knobs::default(), action, 3, None)
            .into_iter()
            .map(|d| d.log)
            .collect()
    }

    #[test]
    fn a_walk_bobs_where_a_run_skims_and_a_sidestep_goes_sideways() {
        let shape = |action: Action, seed: u64| {
            mean_shape(&example_shapes(&example_logs(action, seed))).unwrap()
        };
        for seed in [1, 2, 3] {
            let (walk, run, side) = (
                shape(Action::Walk, seed),
                shape(Action::Run, seed),
                shape(Action::Sidestep, seed),
            );
            // Shares of the speed, left / up / front of the figurine, whatever its heading.
            assert!(walk[1] > run[1] + 0.15, "walk {walk:?} run {run:?}");
            assert!(run[2] > walk[2], "walk {walk:?} run {run:?}");
            assert!(
                side[0] > side[2] && side[0] > walk[0] + 0.3,
                "sidestep {side:?}"
            );
            for s in [walk, run, side] {
                assert!(s[..5].iter().all(|x| (0.0..=1.0).contains(x)), "{s:?}");
                assert!((-1.0..=1.0).contains(&s[5]), "{s:?}");
            }
        }
        // No motion, no shape.
        assert_eq!(mean_shape(&[]), None);
        assert_eq!(shape_tolerance(&[]), None);
    }

    #[test]
    fn a_jump_is_performed_above_where_it_began_and_a_crouch_below() {
        // Both are written `d u` often enough; the height (the last dimension) tells them
        // apart, whatever the doodle's size, place and heading. A gesture hardly louder than
        // its tracker's noise (a small, slow crouch under a noisy tracker) may not move at
        // all: the learner does without that example.
        let mut read = 0;
        for seed in [1, 2, 3, 4] {
            for log in example_logs(Action::Jump, seed) {
                if let Some(s) = motion_shape(&log) {
                    assert!(s[5] > 0.0, "jump {s:?}");
                    read += 1;
                }
            }
            for log in example_logs(Action::Crouch, seed) {
                if let Some(s) = motion_shape(&log) {
                    assert!(s[5] < -0.02, "crouch {s:?}");
                    read += 1;
                }
            }
        }
        assert!(read >= 22, "only {read} of 24 examples moved");
    }

    #[test]
    fn a_jump_lands_a_share_of_its_reach_ahead_where_a_punch_comes_back() {
        // The least share of its own reach that an example ended away across the floor: what
        // tells a jump from a toy lifted and set down where it rose, whatever the size.
        let share = |action: Action, seed: u64| {
            learn_action("a", &example_logs(action, seed), None, false)
                .unwrap()
                .travel_share
                .unwrap()
        };
        for seed in [1, 2, 3] {
            let (walk, jump, punch, crouch) = (
                share(Action::Walk, seed),
                share(Action::Jump, seed),
                share(Action::Punch, seed),
                share(Action::Crouch, seed),
            );
            assert!(walk > 0.9 && jump > 0.3, "walk {walk} jump {jump}");
            assert!(punch < 0.2 && crouch < 0.2, "punch {punch} crouch {crouch}");
        }
    }

    #[test]
    fn a_walk_is_several_pushes_where_a_toy_carried_is_one_sweep() {
        // Counted as examples are, against the noise: what a library asks of a performance.
        let made = |log: &PoseLog| fewest_sweeps([&log_gesture(log)[..]]).unwrap_or(0);
        for seed in [1, 2, 3] {
            for action in [Action::Walk, Action::Sidestep, Action::Run] {
                let entry = learn_action("a", &example_logs(action, seed), None, false).unwrap();
                assert!(entry.sweeps >= Some(2), "{action:?} {:?}", entry.sweeps);
            }
            let carried = synth::handled(seed, &Knobs::default(), synth::Handling::Reposition);
            assert_eq!(made(&carried.log), 1, "a carry, seed {seed}");
        }
        assert_eq!(fewest_sweeps(std::iter::empty::<&[Run]>()), None);
    }

    #[test]
    fn the_briefest_example_is_its_first_motion_to_its_last() {
        // Each example as the device reads it, from its first moving run to its last.
        let logs = example_logs(Action::Punch, 4);
        let each: Vec<f32> = logs
            .iter()
            .map(|log| briefest([&log_gesture(log)[..]]).unwrap())
            .collect();
        let entry = learn_action("punch", &logs, None, false).unwrap();
        let least = each.iter().copied().fold(f32::INFINITY, f32::min);
        assert_eq!(entry.briefest_s, Some(least), "{each:?}");
        // A punch lasts tenths of a second, not milliseconds or seconds.
        assert!((0.1..1.5).contains(&least), "{each:?}");
        // Sudden examples are briefer than sustained ones of the same action.
        let played = |time: synth::TimeClass| {
            let effort = synth::Effort::new(time, synth::WeightClass::Neutral);
            let logs: Vec<PoseLog> =
                synth::examples(4, &Knobs::default(), Action::Punch, 3, Some(effort))
                    .into_iter()
                    .map(|d| d.log)
                    .collect();
            learn_action("punch", &logs, None, false)
                .unwrap()
                .briefest_s
                .unwrap()
        };
        let (sudden, sustained) = (
            played(synth::TimeClass::Sudden),
            played(synth::TimeClass::Sustained),
        );
        assert!(sudden < sustained, "{sudden} {sustained}");
        assert_eq!(briefest(std::iter::empty::<&[Run]>()), None);
    }

    #[test]
    fn many_examples_bound_a_performance_by_their_lower_quartile_not_their_odd_one() {
        let logs: Vec<PoseLog> = synth::examples(5, &Knobs::default(), Action::Jump, 12, None)
            .into_iter()
            .map(|d| d.log)
            .collect();
        let gestures: Vec<Vec<Run>> = logs.iter().map(log_gesture).collect();
        let moved = |g: &[Vec<Run>]| {
            least_extent(g.iter().map(|g| (None, &g[..])))
                .unwrap()
                .moved_m
        };
        let mut each: Vec<f32> = gestures
            .iter()
            .map(|g| moved(std::slice::from_ref(g)))
            .collect();
        each.sort_by(f32::total_cmp);
        // Twelve examples: a quarter of the way from the third least to the fourth; three:
        // their least.
        let quartile = each[2] + 0.25 * (each[3] - each[2]);
        assert!((moved(&gestures) - quartile).abs() < 1e-6, "{each:?}");
        let three = &gestures[..3];
        let least_of_three = three
            .iter()
            .map(|g| moved(std::slice::from_ref(g)))
            .fold(f32::INFINITY, f32::min);
        assert_eq!(moved(three), least_of_three);
        // A shape one example of twelve strays in: the tolerance is how far the others lie
        // from the mean it shifted, not how far it strayed; among three it sets it.
        assert_eq!(lower_quartile(vec![3.0, 1.0, 2.0]), Some(1.0));
        assert_eq!(lower_quartile(vec![4.0, 1.0, 2.0, 3.0, 5.0]), Some(1.5));
        assert_eq!(lower_quartile(vec![7.0]), Some(7.0));
        assert_eq!(lower_quartile(vec![]), None);
        let mut shapes = vec![[0.1, 0.5, 0.8, 1.0, 0.2, 0.0]; 11];
        shapes.push([0.1, 0.5, 0.8, 1.0, 0.2, 0.9]);
        let shifted = SHAPE_SCALE[5] * 0.9 / 12.0;
        assert!((shape_tolerance(&shapes).unwrap()[5] - shifted).abs() < 1e-5);
        let strayed = SHAPE_SCALE[5] * (0.9 - 0.3);
        assert!((shape_tolerance(&shapes[9..]).unwrap()[5] - strayed).abs() < 1e-5);
    }

    #[test]
    fn a_kick_flicked_flat_or_high_spreads_its_shape_more_than_a_walk() {
        // Up share (dimension 1), over a few example sets: a kick's flick rises 0.3–1.4× as
        // far as it goes forward, a walk's hops bob alike.
        let up = |action: Action, seed: u64| {
            shape_tolerance(&example_shapes(&example_logs(action, seed))).unwrap()[1]
        };
        let kick: f32 = (1..=4).map(|s| up(Action::Kick, s)).sum();
        let walk: f32 = (1..=4).map(|s| up(Action::Walk, s)).sum();
        assert!(kick > walk, "kick {kick} walk {walk}");
        // Each dimension on its own, weighted as the device weighs it, never below the floor.
        let shapes = [
            [0.1, 0.5, 0.8, 1.0, 0.2, 0.0],
            [0.1, 0.7, 0.6, 1.4, 0.2, 0.1],
        ];
        let tol = shape_tolerance(&shapes).unwrap();
        let want = [0.06, 0.1, 0.1, 0.1, 0.06, 0.15];
        for (got, want) in tol.iter().zip(want) {
            assert!((got - want).abs() < 1e-6, "{tol:?}");
        }
    }
}
