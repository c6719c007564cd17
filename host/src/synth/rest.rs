//! Rest logs: a figurine that is *not* playing any action, for false-positive checks.
//!
//! Three kinds of rest ([`RestKind`]), each laid under a tracker level ([`TRACKER_LEVELS`]):
//! * **hand** — held still in a child's hand: physiological tremor (8–12 Hz, at most 3 mm and
//!   0.5° per axis with a slow swell), sway of hand and arm (0.1–0.5 Hz, 1–5 mm, 0.5–2°) and
//!   occasional idle fidgets (every few to tens of seconds, a smooth 0.2–0.8 s bump of 2–8 mm and
//!   1–5° in a random direction that returns or settles where it went);
//! * **table** — set down: nothing moves; only the tracker's noise and slow drift;
//! * **mounted** — on a stand: like table plus a structure vibration of 0.05–0.2 mm at 20–50 Hz.
//!
//! Every hand motion is millimetres and a few degrees: gestures move decimetres and turn tens of
//! degrees, so none of this is an action. The tracker adds white noise (anisotropic for a webcam:
//! worse along its viewing axis, a random horizontal direction), slow drift in position and
//! heading, the jittered sample clock of [`sample_times`] and the quaternion sign conventions of
//! [`SignPolicy`]. Where the figurine stands, faces and how crooked it sits come from the usual
//! [`Knobs`] ranges. Everything is deterministic per seed; the motion is a continuous function
//! of time drawn from its own streams, so changing the rate or the tracker keeps the motion.

use std::f64::consts::{PI, TAU};
use std::fmt;
use std::path::Path;
use std::str::FromStr;

use glam::{DQuat, DVec3};
use serde::Serialize;

use super::knobs::{Knobs, Range};
use super::noise::{eval3, partials, peak, Partial};
use super::rng::{Stream, SynthRng};
use super::sampling::{sample_times, SignPolicy, MAX_RATE_HZ, MIN_RATE_HZ};
use super::sequence::to_micros;
use super::tracker::TrackerNoise;
pub use super::tracker::{TrackerLevel, TRACKER_LEVELS};
use crate::poselog::{PoseLog, PoseSample};

/// Longest rest log accepted, seconds (an hour at 1 kHz ≈ 3.6 M samples, ≈ 230 MB in memory).
pub const MAX_REST_SECONDS: f64 = 3600.0;

/// What the figurine rests on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RestKind {
    /// Held still in a child's hand: tremor, sway, idle fidgets.
    Hand,
    /// Set down on a table: only the tracker's noise and drift.
    Table,
    /// Fixed on a stand: like a table plus a tiny structure vibration.
    Mounted,
}

impl RestKind {
    /// All kinds.
    pub const ALL: [RestKind; 3] = [RestKind::Hand, RestKind::Table, RestKind::Mounted];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RestKind::Hand => "hand",
            RestKind::Table => "table",
            RestKind::Mounted => "mounted",
        }
    }
}

impl fmt::Display for RestKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RestKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim().to_ascii_lowercase();
        RestKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| format!("unknown rest kind `{s}`: expected hand, table or mounted"))
    }
}

/// What [`rest_log`] generates. `Default`: ten minutes, random kind and tracker level, the
/// level's rate, the default [`Knobs`].
#[derive(Debug, Clone, PartialEq)]
pub struct RestSpec {
    /// Length of the log, seconds (> 0, at most [`MAX_REST_SECONDS`]).
    pub seconds: f64,
    /// Kind of rest; `None` draws one per seed.
    pub kind: Option<RestKind>,
    /// Tracker level (normally an entry of [`TRACKER_LEVELS`]); `None` draws one per seed.
    pub tracker: Option<TrackerLevel>,
    /// Sample rate, Hz; `None` draws from the tracker level's range.
    pub rate_hz: Option<Range>,
    /// Placement and clock: `room_m`, `height_m`, `heading_deg`, `tilt_deg`, `t0`, `jitter`,
    /// `drop` and `sign` are used; the others (scale, speed, noise …) do not apply to rest.
    pub knobs: Knobs,
}

impl Default for RestSpec {
    fn default() -> Self {
        Self {
            seconds: 600.0,
            kind: None,
            tracker: None,
            rate_hz: None,
            knobs: Knobs::default(),
        }
    }
}

impl RestSpec {
    /// Checks the spec; the message names the offending option.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.seconds > 0.0 && self.seconds <= MAX_REST_SECONDS) {
            return Err(format!(
                "--seconds {}: must be above 0 and at most {MAX_REST_SECONDS}",
                self.seconds
            ));
        }
        if let Some(r) = self.rate_hz {
            if r.lo < MIN_RATE_HZ || r.hi > MAX_RATE_HZ {
                return Err(format!(
                    "--rate {r}: must lie within {MIN_RATE_HZ}..{MAX_RATE_HZ}"
                ));
            }
        }
        self.knobs.validate()
    }
}

/// One idle fidget as drawn: when, how far and whether the hand came back.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FidgetInfo {
    /// Start, seconds on the log's clock.
    pub start: f64,
    /// End, seconds on the log's clock.
    pub end: f64,
    /// Size of the displacement, millimetres.
    pub mm: f64,
    /// Size of the rotation, degrees.
    pub deg: f64,
    /// `true` when the hand returned to where it was, `false` when it settled there.
    pub returns: bool,
}

/// Everything a rest log's seed drew (the `--labels` JSON). Motion figures are peaks per axis
/// and 0 where the kind has no such motion.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RestInfo {
    /// Master seed.
    pub seed: u64,
    /// Kind of rest.
    pub kind: RestKind,
    /// Requested length, seconds.
    pub seconds: f64,
    /// Tracker level name.
    pub tracker: &'static str,
    /// The real trackers the level stands for.
    pub stands_for: &'static str,
    /// Nominal sample rate, Hz.
    pub rate_hz: f64,
    /// Timestamp jitter, fraction of a period.
    pub jitter: f64,
    /// Probability of a dropped sample.
    pub drop: f64,
    /// White position noise σ across the viewing axis, millimetres.
    pub pos_sigma_mm: f64,
    /// White position noise σ along the viewing axis, millimetres.
    pub depth_sigma_mm: f64,
    /// The tracker's viewing axis (unit, horizontal, world); matters when depth σ > σ.
    pub view_dir: [f64; 3],
    /// White orientation noise σ per axis, degrees.
    pub rot_sigma_deg: f64,
    /// Slow position drift, peak per axis, millimetres.
    pub drift_mm: f64,
    /// Slow heading drift, peak, degrees.
    pub yaw_drift_deg: f64,
    /// Hand tremor (8–12 Hz), peak per axis including its swell, millimetres.
    pub tremor_mm: f64,
    /// Hand tremor, peak per axis including its swell, degrees.
    pub tremor_deg: f64,
    /// Hand/arm sway (0.1–0.5 Hz), peak per axis, millimetres.
    pub sway_mm: f64,
    /// Hand/arm sway, peak per axis, degrees.
    pub sway_deg: f64,
    /// Stand vibration, peak per axis, millimetres.
    pub vibration_mm: f64,
    /// Stand vibration frequency, Hz (0 without a stand).
    pub vibration_hz: f64,
    /// The idle fidgets, in time order.
    pub fidgets: Vec<FidgetInfo>,
    /// Resting position, metres (world).
    pub start: [f64; 3],
    /// Heading, degrees about +Y.
    pub heading_deg: f64,
    /// How crooked it sits or is held, degrees.
    pub tilt_deg: f64,
    /// Log clock at the first sample, seconds.
    pub t0: f64,
    /// Quaternion sign convention.
    pub quat_sign: String,
}

impl fmt::Display for RestInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "kind={} tracker={} rate={:.1}Hz sigma={:.2}mm depth-sigma={:.2}mm \
             rot-sigma={:.3}deg drift={:.2}mm tremor={:.2}mm sway={:.2}mm vibration={:.3}mm \
             fidgets={} start=({:.3},{:.3},{:.3}) heading={:.1}deg t0={:.3}s sign={}",
            self.kind,
            self.tracker,
            self.rate_hz,
            self.pos_sigma_mm,
            self.depth_sigma_mm,
            self.rot_sigma_deg,
            self.drift_mm,
            self.tremor_mm,
            self.sway_mm,
            self.vibration_mm,
            self.fidgets.len(),
            self.start[0],
            self.start[1],
            self.start[2],
            self.heading_deg,
            self.t0,
            self.quat_sign
        )
    }
}

/// A generated rest log and what was drawn for it.
#[derive(Debug, Clone)]
pub struct RestLog {
    /// The pose samples.
    pub log: PoseLog,
    /// The drawn parameters.
    pub info: RestInfo,
}

impl RestLog {
    /// Writes the log as CSV with `#` comment lines recording seed and drawn parameters.
    pub fn write_csv(&self, path: &Path) -> std::io::Result<()> {
        use std::io::Write;
        let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(w, "# figurine synth rest seed={}", self.info.seed)?;
        writeln!(w, "# {}", self.info)?;
        self.log.write(&mut w)?;
        w.flush()
    }

    /// Writes [`RestInfo`] as pretty JSON.
    pub fn write_info(&self, path: &Path) -> std::io::Result<()> {
        let text = serde_json::to_string_pretty(&self.info).map_err(std::io::Error::other)?;
        std::fs::write(path, text + "\n")
    }
}

/// Unit vector in a uniformly random direction.
fn random_dir(rng: &mut SynthRng) -> DVec3 {
    let v = DVec3::new(rng.normal(), rng.normal(), rng.normal());
    // A zero draw has probability ~0; fall back to up rather than NaN.
    v.try_normalize().unwrap_or(DVec3::Y)
}

/// Number of sinusoidal partials of tremor and sway per axis.
const HAND_PARTIALS: usize = 2;
/// Tremor swell: the envelope `1 + SWELL·sin(…)`; tremor amplitudes are drawn ≤ peak/(1+SWELL).
const SWELL: f64 = 0.5;
/// Largest tremor per axis including the swell, metres and radians.
const TREMOR_PEAK_M: f64 = 3e-3;
const TREMOR_PEAK_RAD: f64 = 0.5 * PI / 180.0;
/// Farthest a hand settles from home after non-returning fidgets, metres and radians: a hand
/// holding still keeps a comfortable spot instead of random-walking away.
const SETTLE_M: f64 = 8e-3;
const SETTLE_RAD: f64 = 5.0 * PI / 180.0;
/// Quietest spell between fidgets, seconds.
const MIN_FIDGET_GAP_S: f64 = 0.5;

/// One idle fidget: a smooth excursion from the current resting offset.
#[derive(Debug, Clone, Copy)]
struct Fidget {
    start: f64,
    duration: f64,
    from_pos: DVec3,
    from_rot: DVec3,
    dpos: DVec3,
    drot: DVec3,
    returns: bool,
}

impl Fidget {
    /// Offset (position m, rotation vector rad) at progress `s` ∈ [0, 1].
    fn at(&self, s: f64) -> (DVec3, DVec3) {
        let s = s.clamp(0.0, 1.0);
        // Both shapes start and end at rest (zero velocity): a bump there and back, or a
        // minimum-jerk move to a new resting spot.
        let k = if self.returns {
            (PI * s).sin().powi(2)
        } else {
            s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
        };
        (self.from_pos + self.dpos * k, self.from_rot + self.drot * k)
    }

    fn end(&self) -> f64 {
        self.start + self.duration
    }
}

/// A step of size `m` (direction `dir`) from `from`, turned straight back home when it would
/// leave the ball of radius `limit`; keeps |from + step| ≤ max(limit, m).
fn settle_step(from: DVec3, dir: DVec3, m: f64, limit: f64) -> DVec3 {
    let step = dir * m;
    if (from + step).length() > limit {
        -from.normalize_or_zero() * m
    } else {
        step
    }
}

/// The figurine's true motion about its resting pose: hand tremor, sway and fidgets, or a stand's
/// vibration, or nothing. A continuous function of time.
#[derive(Debug, Clone)]
struct RestMotion {
    tremor_pos: [[Partial; HAND_PARTIALS]; 3],
    tremor_rot: [[Partial; HAND_PARTIALS]; 3],
    swell: Partial,
    sway_pos: [[Partial; HAND_PARTIALS]; 3],
    sway_rot: [[Partial; HAND_PARTIALS]; 3],
    vib_pos: [[Partial; 1]; 3],
    vib_rot: [[Partial; 1]; 3],
    fidgets: Vec<Fidget>,
    /// Peaks for [`RestInfo`]: tremor m, tremor rad, sway m, sway rad, vibration m, vibration Hz.
    peaks: [f64; 6],
}

impl RestMotion {
    /// Draws the motion of `kind` over `[t0, t0 + seconds]`. Hand and stand parameters are
    /// always drawn (then zeroed where the kind has none), so a seed's draws do not depend on
    /// the kind; fidgets come from their own stream.
    fn draw(seed: u64, kind: RestKind, t0: f64, seconds: f64) -> Self {
        let mut rng = SynthRng::child(seed, Stream::Rest, 1);
        let hand = if kind == RestKind::Hand { 1.0 } else { 0.0 };
        let stand = if kind == RestKind::Mounted { 1.0 } else { 0.0 };
        let top = 1.0 + SWELL;
        let tremor_m = hand * rng.uniform(0.2e-3, TREMOR_PEAK_M / top);
        let tremor_rad = hand * rng.uniform(0.1f64.to_radians(), TREMOR_PEAK_RAD / top);
        let tremor_pos = partials(&mut rng, tremor_m, 8.0, 12.0);
        let tremor_rot = partials(&mut rng, tremor_rad, 8.0, 12.0);
        let swell = Partial {
            amp: SWELL,
            freq: rng.uniform(0.15, 0.6),
            phase: rng.uniform(0.0, TAU),
        };
        // `partials` gives each axis 0.4–1 of the amplitude, so drawing it in [top/2.5, top]
        // puts every axis within 1–5 mm and 0.5–2°.
        let sway_m = hand * rng.uniform(2.5e-3, 5e-3);
        let sway_rad = hand * rng.uniform(1.25f64.to_radians(), 2f64.to_radians());
        let sway_pos = partials(&mut rng, sway_m, 0.1, 0.5);
        let sway_rot = partials(&mut rng, sway_rad, 0.1, 0.5);
        // A stand rings at one mode: one frequency on every axis, 0.05–0.2 mm per axis.
        let vib_m = stand * rng.uniform(0.125e-3, 0.2e-3);
        let vib_rad = stand * rng.uniform(0.005f64.to_radians(), 0.02f64.to_radians());
        let vib_hz = rng.uniform(20.0, 50.0);
        let mut vib_pos = partials::<1>(&mut rng, vib_m, vib_hz, vib_hz);
        let mut vib_rot = partials::<1>(&mut rng, vib_rad, vib_hz, vib_hz);
        for p in vib_pos.iter_mut().chain(vib_rot.iter_mut()) {
            p[0].freq = vib_hz;
        }
        let fidgets = if kind == RestKind::Hand {
            draw_fidgets(seed, t0, seconds)
        } else {
            Vec::new()
        };
        let peaks = [
            peak(&tremor_pos) * top,
            peak(&tremor_rot) * top,
            peak(&sway_pos),
            peak(&sway_rot),
            peak(&vib_pos),
            if stand > 0.0 { vib_hz } else { 0.0 },
        ];
        Self {
            tremor_pos,
            tremor_rot,
            swell,
            sway_pos,
            sway_rot,
            vib_pos,
            vib_rot,
            fidgets,
            peaks,
        }
    }

    /// Offset from the resting pose at `t` seconds: position (metres, world) and rotation
    /// vector (radians, figurine frame).
    fn at(&self, t: f64) -> (DVec3, DVec3) {
        let swell = 1.0 + self.swell.at(t);
        let mut pos =
            eval3(&self.tremor_pos, t) * swell + eval3(&self.sway_pos, t) + eval3(&self.vib_pos, t);
        let mut rot =
            eval3(&self.tremor_rot, t) * swell + eval3(&self.sway_rot, t) + eval3(&self.vib_rot, t);
        let i = self.fidgets.partition_point(|f| f.start <= t);
        if let Some(f) = i.checked_sub(1).map(|i| &self.fidgets[i]) {
            let (p, r) = f.at((t - f.start) / f.duration);
            pos += p;
            rot += r;
        }
        (pos, rot)
    }
}

/// Draws idle fidgets over `[t0, t0 + seconds]`: exponential gaps (mean 3–30 s per log), each a
/// 0.2–0.8 s excursion of 2–8 mm and 1–5° that returns or settles (even odds).
fn draw_fidgets(seed: u64, t0: f64, seconds: f64) -> Vec<Fidget> {
    let mut rng = SynthRng::child(seed, Stream::Rest, 2);
    let mean_gap = rng.uniform(3.0, 30.0);
    let end = t0 + seconds;
    let (mut at_pos, mut at_rot) = (DVec3::ZERO, DVec3::ZERO);
    let mut t = t0;
    let mut out = Vec::new();
    loop {
        let gap = -mean_gap * (1.0 - rng.unit()).ln();
        let start = t + gap.max(MIN_FIDGET_GAP_S);
        let duration = rng.uniform(0.2, 0.8);
        let mm = rng.uniform(2e-3, 8e-3);
        let rad = rng.uniform(1f64.to_radians(), 5f64.to_radians());
        let dir = random_dir(&mut rng);
        let axis = random_dir(&mut rng);
        let returns = rng.chance(0.5);
        if start + duration > end {
            return out;
        }
        let f = Fidget {
            start,
            duration,
            from_pos: at_pos,
            from_rot: at_rot,
            dpos: settle_step(at_pos, dir, mm, SETTLE_M),
            drot: settle_step(at_rot, axis, rad, SETTLE_RAD),
            returns,
        };
        (at_pos, at_rot) = f.at(1.0);
        t = f.end();
        out.push(f);
    }
}

/// A rest log of master `seed`: the figurine resting as `spec` says, sampled through the
/// tracker. Out-of-range specs are clamped by the samplers; call [`RestSpec::validate`] first to
/// reject them instead.
pub fn rest_log(seed: u64, spec: &RestSpec) -> RestLog {
    let var = spec.knobs.draw(&mut SynthRng::new(seed, Stream::Knobs));
    let mut pick = SynthRng::child(seed, Stream::Rest, 0);
    // Always draw both picks and the rate, so pinning one leaves the others unchanged.
    let kind_i = pick.index(RestKind::ALL.len());
    let level_i = pick.index(TRACKER_LEVELS.len());
    let kind = spec.kind.unwrap_or(RestKind::ALL[kind_i]);
    let level = spec.tracker.unwrap_or(TRACKER_LEVELS[level_i]);
    let rate_hz = spec.rate_hz.unwrap_or(level.rate_hz).draw(&mut pick);
    let seconds = if spec.seconds.is_finite() {
        spec.seconds.clamp(0.0, MAX_REST_SECONDS)
    } else {
        0.0
    };

    let motion = RestMotion::draw(seed, kind, var.t0, seconds);
    let mut sensor_rng = SynthRng::new(seed, Stream::Sensor);
    let tracker = TrackerNoise::draw(&level, &mut sensor_rng, var.t0);
    let mut sign = SignPolicy::new(var.sign, var.t0, &mut sensor_rng);
    let mut clock = SynthRng::new(seed, Stream::Clock);
    let times = sample_times(
        var.t0,
        var.t0 + seconds,
        rate_hz,
        var.jitter,
        var.drop,
        &mut clock,
    );
    // Upright with a random heading, crooked by the hold/base tilt.
    let base = DQuat::from_rotation_y(var.heading) * var.tilt;
    let samples = times
        .into_iter()
        .map(|t| {
            let (dp, dr) = motion.at(t);
            let truth = base * DQuat::from_scaled_axis(dr);
            let (p, q) = tracker.measure(t, var.start + dp, truth, &mut sensor_rng);
            let q = sign.apply(t, q, &mut sensor_rng);
            PoseSample {
                t: to_micros(t),
                pos: p.to_array(),
                quat: [q.w, q.x, q.y, q.z],
            }
        })
        .collect();

    let [tremor_m, tremor_rad, sway_m, sway_rad, vib_m, vib_hz] = motion.peaks;
    let info = RestInfo {
        seed,
        kind,
        seconds,
        tracker: level.name,
        stands_for: level.stands_for,
        rate_hz,
        jitter: var.jitter,
        drop: var.drop,
        pos_sigma_mm: tracker.across * 1e3,
        depth_sigma_mm: tracker.depth * 1e3,
        view_dir: tracker.view.to_array(),
        rot_sigma_deg: tracker.rot.to_degrees(),
        drift_mm: tracker.drift_peak() * 1e3,
        yaw_drift_deg: tracker.yaw_drift.amp.to_degrees(),
        tremor_mm: tremor_m * 1e3,
        tremor_deg: tremor_rad.to_degrees(),
        sway_mm: sway_m * 1e3,
        sway_deg: sway_rad.to_degrees(),
        vibration_mm: vib_m * 1e3,
        vibration_hz: vib_hz,
        fidgets: motion
            .fidgets
            .iter()
            .map(|f| FidgetInfo {
                start: to_micros(f.start),
                end: to_micros(f.end()),
                mm: f.dpos.length() * 1e3,
                deg: f.drot.length().to_degrees(),
                returns: f.returns,
            })
            .collect(),
        start: var.start.to_array(),
        heading_deg: var.heading.to_degrees(),
        tilt_deg: var.tilt.to_axis_angle().1.to_degrees(),
        t0: var.t0,
        quat_sign: var.sign.to_string(),
    };
    RestLog {
        log: PoseLog { samples },
        info,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(kind: RestKind, level: &str, seconds: f64) -> RestSpec {
        RestSpec {
            seconds,
            kind: Some(kind),
            tracker: TrackerLevel::by_name(level),
            ..RestSpec::default()
        }
    }

    fn positions(r: &RestLog) -> Vec<DVec3> {
        r.log
            .samples
            .iter()
            .map(|s| DVec3::from_array(s.pos))
            .collect()
    }

    fn mean(ps: &[DVec3]) -> DVec3 {
        ps.iter().copied().sum::<DVec3>() / ps.len() as f64
    }

    /// σ of white noise along `axis`, from successive differences (blind to slow motion).
    fn diff_sigma(ps: &[DVec3], axis: DVec3) -> f64 {
        let v: f64 = ps.windows(2).map(|w| (w[1] - w[0]).dot(axis).powi(2)).sum();
        (v / (ps.len() - 1) as f64 / 2.0).sqrt()
    }

    #[test]
    fn same_seed_same_log_other_seed_other_log() {
        let s = RestSpec {
            seconds: 20.0,
            ..RestSpec::default()
        };
        let a = rest_log(5, &s);
        let b = rest_log(5, &s);
        let c = rest_log(6, &s);
        assert_eq!(a.log, b.log);
        assert_eq!(a.info, b.info);
        assert_ne!(a.log, c.log);
        // Pinning the rate keeps the kind, the tracker and the fidgets.
        let d = rest_log(
            5,
            &RestSpec {
                rate_hz: Some(Range::fixed(500.0)),
                ..s
            },
        );
        assert_eq!((d.info.kind, d.info.tracker), (a.info.kind, a.info.tracker));
        assert_eq!(d.info.fidgets, a.info.fidgets);
    }

    #[test]
    fn duration_and_rate_are_respected() {
        let mut s = spec(RestKind::Table, "lighthouse", 20.0);
        s.rate_hz = Some(Range::fixed(200.0));
        s.knobs.jitter = Range::fixed(0.0);
        s.knobs.drop = Range::fixed(0.0);
        let r = rest_log(3, &s);
        let ts: Vec<f64> = r.log.samples.iter().map(|s| s.t).collect();
        assert_eq!(ts.len(), 20 * 200 + 1);
        assert!(((ts[ts.len() - 1] - ts[0]) - 20.0).abs() < 1e-6);
        assert_eq!(r.info.rate_hz, 200.0);
        // Defaults: the level's rate, jittered instants, a few drops.
        for level in TRACKER_LEVELS {
            let r = rest_log(4, &spec(RestKind::Hand, level.name, 30.0));
            let ts: Vec<f64> = r.log.samples.iter().map(|s| s.t).collect();
            let rate = r.info.rate_hz;
            assert!(
                rate >= level.rate_hz.lo && rate <= level.rate_hz.hi,
                "{rate}"
            );
            assert!(ts.windows(2).all(|w| w[1] > w[0]));
            assert!(ts[ts.len() - 1] - ts[0] > 30.0 - 1.5 / rate);
            assert!(ts[ts.len() - 1] - ts[0] <= 30.0 + 1e-6);
            let expect = 30.0 * rate * (1.0 - r.info.drop);
            assert!((ts.len() as f64 - expect).abs() < 0.01 * expect + 3.0);
            let norm = |q: [f64; 4]| q.iter().map(|c| c * c).sum::<f64>().sqrt();
            assert!(r
                .log
                .samples
                .iter()
                .all(|s| (norm(s.quat) - 1.0).abs() < 1e-9));
        }
        assert!(RestSpec {
            seconds: 0.0,
            ..RestSpec::default()
        }
        .validate()
        .unwrap_err()
        .contains("--seconds"));
        assert!(RestSpec {
            rate_hz: Some(Range::fixed(1e5)),
            ..RestSpec::default()
        }
        .validate()
        .unwrap_err()
        .contains("--rate"));
        assert!(RestSpec::default().validate().is_ok());
    }

    #[test]
    fn true_motion_stays_within_each_kinds_bounds() {
        for seed in 0..16 {
            for kind in RestKind::ALL {
                let m = RestMotion::draw(seed, kind, 2.0, 120.0);
                let (mut pos, mut rot): (f64, f64) = (0.0, 0.0);
                for i in 0..120_000 {
                    let (p, r) = m.at(2.0 + i as f64 * 1e-3);
                    pos = pos.max(p.abs().max_element());
                    rot = rot.max(r.abs().max_element());
                }
                let (pos_mm, rot_deg) = (pos * 1e3, rot.to_degrees());
                match kind {
                    RestKind::Table => assert_eq!((pos, rot), (0.0, 0.0)),
                    RestKind::Mounted => {
                        assert!(pos_mm > 0.02 && pos_mm <= 0.2, "{pos_mm}");
                        assert!(rot_deg <= 0.02, "{rot_deg}");
                    }
                    // Tremor 3 + sway 5 + a fidget settled 8 and bumping 8 more, per axis at
                    // worst; in practice far less. Gestures move ≥ 10 cm.
                    RestKind::Hand => {
                        assert!(pos_mm > 1.0 && pos_mm < 20.0, "{pos_mm}");
                        assert!(rot_deg > 0.3 && rot_deg < 12.0, "{rot_deg}");
                    }
                }
                let i = &m.peaks;
                assert!(i[0] <= TREMOR_PEAK_M + 1e-12 && i[1] <= TREMOR_PEAK_RAD + 1e-12);
                assert!(i[2] <= 5e-3 && i[3] <= 2f64.to_radians());
            }
        }
    }

    #[test]
    fn hand_rest_stays_near_its_mean_and_fidgets_are_small() {
        let mut fidgets = 0;
        for seed in 0..12 {
            // The best tracker, so what is measured is the hand.
            let r = rest_log(seed, &spec(RestKind::Hand, "lighthouse", 60.0));
            let ps = positions(&r);
            let m = mean(&ps);
            let worst = ps.iter().map(|p| (*p - m).length()).fold(0.0, f64::max);
            assert!(worst < 0.02, "seed {seed}: {worst} m");
            assert!(worst > 1e-3, "seed {seed}: {worst} m");
            for f in &r.info.fidgets {
                assert!((0.2..=0.8).contains(&(f.end - f.start)), "{f:?}");
                assert!(f.mm <= 8.0 + 1e-9 && f.deg <= 5.0 + 1e-9, "{f:?}");
                assert!(f.mm >= 2.0 - 1e-9 && f.deg >= 1.0 - 1e-9, "{f:?}");
            }
            assert!(r.info.tremor_mm <= 3.0 + 1e-9 && r.info.tremor_deg <= 0.5 + 1e-9);
            fidgets += r.info.fidgets.len();
        }
        // Every few to tens of seconds: 12 minutes hold a handful to a few hundred.
        assert!((6..300).contains(&fidgets), "{fidgets}");
    }

    #[test]
    fn table_rest_spreads_like_the_tracker_noise() {
        for (seed, level) in TRACKER_LEVELS.iter().enumerate() {
            let r = rest_log(seed as u64, &spec(RestKind::Table, level.name, 60.0));
            let i = &r.info;
            let ps = positions(&r);
            let est = diff_sigma(&ps, DVec3::Y) * 1e3;
            assert!((est / i.pos_sigma_mm - 1.0).abs() < 0.1, "{est} vs {i:?}");
            let m = mean(&ps);
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                let sd = (ps.iter().map(|p| (*p - m).dot(axis).powi(2)).sum::<f64>()
                    / ps.len() as f64)
                    .sqrt()
                    * 1e3;
                assert!(
                    sd > 0.8 * i.pos_sigma_mm && sd < 1.2 * i.depth_sigma_mm + i.drift_mm,
                    "{} axis {axis}: {sd} mm vs {i:?}",
                    level.name
                );
            }
            assert!(i.fidgets.is_empty() && i.tremor_mm == 0.0 && i.sway_mm == 0.0);
        }
    }

    #[test]
    fn tracker_levels_span_the_documented_ranges() {
        let lo = |f: fn(&TrackerLevel) -> Range| {
            TRACKER_LEVELS
                .iter()
                .map(|l| f(l).lo)
                .fold(f64::MAX, f64::min)
        };
        let hi = |f: fn(&TrackerLevel) -> Range| {
            TRACKER_LEVELS.iter().map(|l| f(l).hi).fold(0.0, f64::max)
        };
        assert_eq!(lo(|l| l.pos_sigma_mm), 0.1);
        assert_eq!(hi(|l| l.depth_sigma_mm), 5.0);
        assert_eq!(lo(|l| l.rot_sigma_deg), 0.02);
        assert_eq!(hi(|l| l.rot_sigma_deg), 0.5);
        assert_eq!(lo(|l| l.rate_hz), 30.0);
        assert_eq!(hi(|l| l.rate_hz), 1000.0);
        for l in TRACKER_LEVELS {
            assert_eq!(TrackerLevel::by_name(&l.name.to_uppercase()), Some(l));
            assert!(l.depth_sigma_mm.lo >= l.pos_sigma_mm.lo);
            assert!(l.depth_sigma_mm.hi >= l.pos_sigma_mm.hi);
        }
        assert!(TrackerLevel::by_name("kinect").is_none());
        assert_eq!("Mounted".parse::<RestKind>(), Ok(RestKind::Mounted));
        assert!("sofa".parse::<RestKind>().is_err());
    }

    #[test]
    fn webcam_noise_is_larger_along_the_viewing_axis() {
        for (seed, name) in [(1, "webcam-near"), (2, "webcam-far")] {
            let r = rest_log(seed, &spec(RestKind::Table, name, 120.0));
            let ps = positions(&r);
            let view = DVec3::from_array(r.info.view_dir);
            let side = DVec3::Y.cross(view);
            let along = diff_sigma(&ps, view);
            let across = diff_sigma(&ps, side);
            assert!(along > 1.5 * across, "{name}: {along} vs {across}");
            assert!((along * 1e3 / r.info.depth_sigma_mm - 1.0).abs() < 0.15);
        }
        let r = rest_log(3, &spec(RestKind::Table, "lighthouse", 60.0));
        let ps = positions(&r);
        let view = DVec3::from_array(r.info.view_dir);
        let ratio = diff_sigma(&ps, view) / diff_sigma(&ps, DVec3::Y.cross(view));
        assert!((ratio - 1.0).abs() < 0.1, "{ratio}");
    }
}
