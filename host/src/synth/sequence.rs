//! Labelled doodles: one or more performances with pauses, sampled through the tracker model.
//!
//! [`render`] is the one place a doodle is assembled: draw the nuisance [`Variation`], plan the
//! strokes of each `(action, effort)` item with a still pause before, between and after, then
//! sample the clean [`Trajectory`] at the tracker's jittered instants and lay the sensor model
//! over it. Labels give each action's first and last instant of motion on the log's clock.

use std::path::Path;

use glam::DVec3;

use serde::{Deserialize, Serialize};

use super::effort::{Effort, TimeClass, WeightClass};
use super::gesture::{plan, Action};
use super::handling::{self, Handling};
use super::knobs::{Knobs, Variation};
use super::noise::{Glitcher, SensorModel};
use super::rng::{Stream, SynthRng};
use super::sampling::{sample_times, SignPolicy};
use super::trajectory::{BodyState, Stroke, Trajectory};
use crate::poselog::{PoseLog, PoseSample};

/// Ground truth of one performed action.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Label {
    /// Action name, e.g. `jump`.
    pub action: String,
    /// First instant of motion, seconds on the log's clock.
    pub start: f64,
    /// Last instant of motion, seconds on the log's clock.
    pub end: f64,
    /// Laban Time class: `sudden`, `sustained` (or `neutral` for unlabelled examples).
    pub time_class: TimeClass,
    /// Laban Weight class: `strong`, `light` (or `neutral`).
    pub weight_class: WeightClass,
}

/// A generated doodle: the log, its labels and the nuisance parameters used.
#[derive(Debug, Clone)]
pub struct Doodle {
    /// The pose samples.
    pub log: PoseLog,
    /// One label per performed action, in time order.
    pub labels: Vec<Label>,
    /// Spans of handling that plays no action ([`Performer::handle`]), named by its kind, in
    /// time order: any event over one is a false one.
    pub handled: Vec<Label>,
    /// The drawn nuisance parameters.
    pub variation: Variation,
    /// The master seed.
    pub seed: u64,
}

impl Doodle {
    /// Writes the log as CSV with `#` comment lines recording seed, variation and labels
    /// (readers skip comments).
    pub fn write_csv(&self, path: &Path) -> std::io::Result<()> {
        use std::io::Write;
        let file = std::fs::File::create(path)?;
        let mut w = std::io::BufWriter::new(file);
        writeln!(w, "# figurine synth seed={}", self.seed)?;
        writeln!(w, "# {}", self.variation)?;
        for l in &self.labels {
            writeln!(
                w,
                "# label {} {:.6}..{:.6} {:?}/{:?}",
                l.action, l.start, l.end, l.time_class, l.weight_class
            )?;
        }
        for h in &self.handled {
            writeln!(w, "# handled {} {:.6}..{:.6}", h.action, h.start, h.end)?;
        }
        self.log.write(&mut w)?;
        w.flush()
    }

    /// Writes the labels as a pretty JSON array.
    pub fn write_labels(&self, path: &Path) -> std::io::Result<()> {
        let text = serde_json::to_string_pretty(&self.labels).map_err(std::io::Error::other)?;
        std::fs::write(path, text + "\n")
    }
}

/// Rounds a time to whole microseconds: the resolution of the CSV clock and of the wire, so
/// in-process doodles, written logs and labels all carry the same instants.
pub(super) fn to_micros(t: f64) -> f64 {
    (t * 1e6).round() / 1e6
}

/// Assembles a doodle performance by performance, then samples it.
pub struct Performer<'k> {
    knobs: &'k Knobs,
    seed: u64,
    var: Variation,
    rng: SynthRng,
    traj: Trajectory,
    labels: Vec<Label>,
    handled: Vec<Label>,
}

impl<'k> Performer<'k> {
    /// Draws the nuisance parameters of master `seed` and opens with the still lead-in.
    pub fn new(seed: u64, knobs: &'k Knobs) -> Self {
        let var = knobs.draw(&mut SynthRng::new(seed, Stream::Knobs));
        let mut rng = SynthRng::new(seed, Stream::Plan);
        let initial = BodyState {
            pos: var.start,
            yaw: var.heading,
            pitch: 0.0,
            roll: 0.0,
        };
        let mut traj = Trajectory::new(var.t0, initial);
        traj.push(Stroke::hold(knobs.lead_s.draw(&mut rng).max(0.05)));
        Self {
            knobs,
            seed,
            var,
            rng,
            traj,
            labels: Vec::new(),
            handled: Vec::new(),
        }
    }

    /// Where the figurine stands and faces now (after the last pause).
    pub fn state(&self) -> BodyState {
        self.traj.last_state()
    }

    /// Plays `strokes` at the player's tempo; returns their first and last instant on the
    /// log's clock (whole microseconds).
    fn play(&mut self, strokes: Vec<Stroke>) -> (f64, f64) {
        let start = self.traj.end();
        let speed = self.var.speed;
        self.traj.extend(strokes.into_iter().map(|mut s| {
            s.duration /= speed;
            s
        }));
        (to_micros(start), to_micros(self.traj.end()))
    }

    /// Performs `action` with `effort`, labels it, and pauses.
    pub fn perform(&mut self, action: Action, effort: Effort) {
        let shape = effort.shape(&mut self.rng);
        let strokes = plan(action, &shape, self.var.scale, &mut self.rng);
        let (start, end) = self.play(strokes);
        self.labels.push(Label {
            action: action.name().to_string(),
            start,
            end,
            time_class: effort.time,
            weight_class: effort.weight,
        });
        let pause = self.knobs.pause_s.draw(&mut self.rng).max(0.05);
        self.traj.push(Stroke::hold(pause));
    }

    /// Handles the toy without playing an action ([`Handling`]), records its span, and pauses;
    /// its strokes and pause are drawn from `rng`, so the actions around it are drawn as they
    /// would be without it.
    pub fn handle(&mut self, kind: Handling, rng: &mut SynthRng) {
        let strokes = handling::plan(kind, self.var.scale, rng);
        let (start, end) = self.play(strokes);
        self.handled.push(Label {
            action: kind.name().to_string(),
            start,
            end,
            time_class: TimeClass::Neutral,
            weight_class: WeightClass::Neutral,
        });
        let pause = self.knobs.pause_s.draw(rng).max(0.05);
        self.traj.push(Stroke::hold(pause));
    }

    /// Samples the performed trajectory through the tracker model.
    pub fn finish(self) -> Doodle {
        let Self {
            seed,
            var,
            traj,
            labels,
            handled,
            ..
        } = self;
        let mut sensor_rng = SynthRng::new(seed, Stream::Sensor);
        let sensor = SensorModel::draw(&mut sensor_rng, var.noise, var.t0);
        let mut sign = SignPolicy::new(var.sign, var.t0, &mut sensor_rng);
        let mut clock = SynthRng::new(seed, Stream::Clock);
        let times = sample_times(
            traj.start(),
            traj.end(),
            var.rate_hz,
            var.jitter,
            var.drop,
            &mut clock,
        );
        let mut glitcher = Glitcher::new(var.glitch, SynthRng::child(seed, Stream::Sensor, 0x611));
        let mut samples: Vec<PoseSample> = Vec::with_capacity(times.len());
        for t in times {
            let st = traj.state_at(t);
            let (p, q) = sensor.measure(t, st.pos, st.quat(var.tilt), &mut sensor_rng);
            let q = sign.apply(t, q, &mut sensor_rng);
            let mut s = PoseSample {
                t: to_micros(t),
                pos: p.to_array(),
                quat: [q.w, q.x, q.y, q.z],
            };
            glitcher.apply(
                samples.last().map(|p| p.t),
                &mut s.t,
                &mut s.pos,
                &mut s.quat,
            );
            s.t = to_micros(s.t);
            samples.push(s);
        }
        Doodle {
            log: PoseLog { samples },
            labels,
            handled,
            variation: var,
            seed,
        }
    }
}

/// Renders the doodle of master `seed` performing `items` in order, with `knobs` ranges.
pub fn render(seed: u64, knobs: &Knobs, items: &[(Action, Effort)]) -> Doodle {
    let mut p = Performer::new(seed, knobs);
    for &(action, effort) in items {
        p.perform(action, effort);
    }
    p.finish()
}

/// One performance of `action` with `effort`.
pub fn gesture(seed: u64, knobs: &Knobs, action: Action, effort: Effort) -> Doodle {
    render(seed, knobs, &[(action, effort)])
}

/// One handling of `kind` ([`Handling`]) alone, between still pauses: a log with no action.
pub fn handled(seed: u64, knobs: &Knobs, kind: Handling) -> Doodle {
    let mut p = Performer::new(seed, knobs);
    p.handle(
        kind,
        &mut SynthRng::child(seed, Stream::Plan, HANDLING_STREAM),
    );
    p.finish()
}

/// Horizontal distance (metres) beyond the room's half-size at which a figurine facing away
/// from the room's centre is turned back before travelling further.
const ROOM_MARGIN_M: f64 = 0.3;

/// Index of the child stream handling is drawn from, apart from the actions'.
const HANDLING_STREAM: u64 = 0x4a4d;

/// A sequence of `count` random actions, each with a random one of the four effort states
/// (or `effort` for all), separated by still pauses. Like a child keeping the toy on the table,
/// a figurine that has wandered out of the room (see [`Knobs::room_m`]) and faces away from its
/// centre turns (a labelled `turn`) instead of travelling further. With probability
/// [`Knobs::handling`] the child also handles the toy once, at a random place in the sequence,
/// without playing an action ([`Handling`], recorded in [`Doodle::handled`]); the actions are
/// drawn from their own streams, the same either way (unless a carry took the toy past the
/// room's edge, where a travelling action becomes a turn).
pub fn sequence(seed: u64, knobs: &Knobs, count: usize, effort: Option<Effort>) -> Doodle {
    let mut pick = SynthRng::child(seed, Stream::Plan, 0x5e9);
    let mut aside = SynthRng::child(seed, Stream::Plan, HANDLING_STREAM);
    let handle_at = aside.chance(knobs.handling).then(|| {
        (
            aside.index(count + 1),
            Handling::BETWEEN_PLAYS[aside.index(Handling::BETWEEN_PLAYS.len())],
        )
    });
    let mut p = Performer::new(seed, knobs);
    let mut handle = |p: &mut Performer<'_>, i: usize| {
        if let Some((_, kind)) = handle_at.filter(|&(at, _)| at == i) {
            p.handle(kind, &mut aside);
        }
    };
    let mid = (knobs.room_m.lo + knobs.room_m.hi) / 2.0;
    let centre = DVec3::new(mid, 0.0, mid);
    let limit = ((knobs.room_m.hi - knobs.room_m.lo) / 2.0).max(0.5) + ROOM_MARGIN_M;
    for i in 0..count {
        handle(&mut p, i);
        let mut action = Action::ALL[pick.index(Action::ALL.len())];
        let e = effort.unwrap_or(Effort::random_state(&mut pick));
        let st = p.state();
        let out = DVec3::new(st.pos.x - centre.x, 0.0, st.pos.z - centre.z);
        let forward = DVec3::new(st.yaw.sin(), 0.0, st.yaw.cos());
        if action.travels() && out.length() > limit && forward.dot(out) > 0.0 {
            action = Action::Turn;
        }
        p.perform(action, e);
    }
    handle(&mut p, count);
    p.finish()
}

/// The seed of the `index`-th doodle of a set generated from master `seed`.
pub fn item_seed(seed: u64, index: u64) -> u64 {
    SynthRng::child(seed, Stream::Plan, index).next_u64()
}

/// `per_class` one-gesture doodles for each of the four effort states, actions cycling through
/// all of [`Action::ALL`] in a shuffled order. Returns `(state, doodle)` pairs, states in
/// [`Effort::STATES`] order.
pub fn effort_set(seed: u64, knobs: &Knobs, per_class: usize) -> Vec<(Effort, Doodle)> {
    let mut order: Vec<Action> = Action::ALL.to_vec();
    let mut shuffle = SynthRng::child(seed, Stream::Plan, u64::MAX);
    for i in (1..order.len()).rev() {
        let j = shuffle.index(i + 1);
        order.swap(i, j);
    }
    let mut out = Vec::with_capacity(4 * per_class);
    for (c, state) in Effort::STATES.into_iter().enumerate() {
        for i in 0..per_class {
            let action = order[(i + 3 * c) % order.len()];
            let s = item_seed(seed, (c * per_class + i) as u64);
            out.push((state, gesture(s, knobs, action, state)));
        }
    }
    out
}

/// `count` learning examples of `action`, each a separate doodle with its own nuisance
/// parameters; effort `None` draws one of the four states per example.
pub fn examples(
    seed: u64,
    knobs: &Knobs,
    action: Action,
    count: usize,
    effort: Option<Effort>,
) -> Vec<Doodle> {
    (0..count)
        .map(|i| {
            let s = item_seed(seed, i as u64);
            let mut pick = SynthRng::child(s, Stream::Plan, 0xeff);
            let e = effort.unwrap_or_else(|| Effort::random_state(&mut pick));
            gesture(s, knobs, action, e)
        })
        .collect()
}

/// The effort state `figurine synth gesture --effort random` uses for master `seed`.
pub fn random_state_for(seed: u64) -> Effort {
    Effort::random_state(&mut SynthRng::child(seed, Stream::Plan, 0xeff))
}
